#include "adjustment/trajectory_correction.h"

#include <gtest/gtest.h>

namespace zebrageo {
namespace {

TEST(CubicBSplineBasis, WeightsArePositiveAndSumToOne) {
  for (double u = 0.0; u <= 1.0; u += 0.05) {
    double w[4];
    CubicBSplineBasis(u, w);
    double sum = 0.0;
    for (double x : w) {
      EXPECT_GE(x, 0.0);
      sum += x;
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
  }
  double w[4];
  CubicBSplineBasis(0.0, w);
  EXPECT_NEAR(w[0], 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(w[1], 4.0 / 6.0, 1e-15);
  EXPECT_NEAR(w[2], 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(w[3], 0.0, 1e-15);
}

TEST(TrajectoryCorrection, CoversTheSpanWithKnotsAtTheSpacing) {
  const TrajectoryCorrection correction(100.0, 110.0, 1.0);
  EXPECT_EQ(correction.num_knots(), 13);  // 10 segments + 3
  int first = -1;
  double w[4];
  correction.Basis(100.0, &first, w);
  EXPECT_EQ(first, 0);
  correction.Basis(110.0, &first, w);
  EXPECT_EQ(first, 9);  // the last segment, u = 1
  correction.Basis(250.0, &first, w);
  EXPECT_EQ(first, 9);  // clamped
  EXPECT_DOUBLE_EQ(correction.KnotTime(1), 100.0);
}

TEST(TrajectoryCorrection, ConstantKnotsGiveThatCorrectionEverywhere) {
  TrajectoryCorrection correction(0.0, 5.0, 0.5);
  for (Knot& k : correction.knots()) k = {0.0, 0.0, 0.01, 1.0, 2.0, 3.0};
  for (double t = 0.0; t <= 5.0; t += 0.37) {
    const Eigen::Matrix<double, 6, 1> c = correction.Evaluate(t);
    EXPECT_NEAR(c[2], 0.01, 1e-14);
    EXPECT_NEAR(c[5], 3.0, 1e-14);
  }
}

TEST(TrajectoryCorrection, ApplyWorksInTheTrackFrame) {
  TrajectoryCorrection correction(0.0, 5.0, 1.0);
  // 1 m along track, 0.01 rad about the up axis.
  for (Knot& k : correction.knots()) k = {0.0, 0.0, 0.01, 1.0, 0.0, 0.0};
  Pose ins;
  ins.p_enu = Eigen::Vector3d(5.0, 6.0, 7.0);
  // Body x (forward) pointing north, z down.
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d::UnitY();
  R.col(1) = Eigen::Vector3d::UnitX();
  R.col(2) = -Eigen::Vector3d::UnitZ();
  ins.q_enu_body = Eigen::Quaterniond(R);
  const Pose corrected = correction.Apply(2.0, ins);
  EXPECT_NEAR((corrected.p_enu - Eigen::Vector3d(5.0, 7.0, 7.0)).norm(), 0.0,
              1e-12);
  const Eigen::AngleAxisd change(corrected.q_enu_body *
                                 ins.q_enu_body.inverse());
  EXPECT_NEAR(change.angle(), 0.01, 1e-12);
  EXPECT_NEAR(change.axis().z(), 1.0, 1e-9);
}

}  // namespace
}  // namespace zebrageo
