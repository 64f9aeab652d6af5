#include "adjustment/cost_functions.h"

#include <ceres/gradient_checker.h>
#include <ceres/numeric_diff_cost_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "adjustment/trajectory_correction.h"

namespace zebrageo {
namespace {

// A camera 1.5 m above the body origin looking forward and 20 degrees down,
// the vehicle heading north-east, a point 10 m ahead on the road.
struct Scene {
  Pose ins_pose;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
  std::array<double, kNumIntrinsics> intrinsics = {
      1100.0, 1101.0, 640.0, 480.0, -0.15, 0.06, 4e-4, -3e-4, -0.01};
  Eigen::Vector3d point_enu;
};

Scene MakeScene() {
  Scene scene;
  scene.ins_pose.p_enu = Eigen::Vector3d(120.0, -40.0, 61.0);
  // Body FRD heading 45 degrees from north: x = NE, z = down.
  Eigen::Matrix3d R;
  const double s = std::sqrt(0.5);
  R.col(0) = Eigen::Vector3d(s, s, 0.0);
  R.col(1) = Eigen::Vector3d(s, -s, 0.0);
  R.col(2) = Eigen::Vector3d(0.0, 0.0, -1.0);
  scene.ins_pose.q_enu_body = Eigen::Quaterniond(R);
  Eigen::Matrix3d base;
  base.col(0) = Eigen::Vector3d::UnitY();
  base.col(1) = Eigen::Vector3d::UnitZ();
  base.col(2) = Eigen::Vector3d::UnitX();
  scene.T_body_cam.linear() =
      Eigen::AngleAxisd(-20.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) * base;
  scene.T_body_cam.translation() = Eigen::Vector3d(0.8, -0.5, -1.5);
  scene.point_enu = scene.ins_pose.p_enu + R * Eigen::Vector3d(10.0, 1.0, 1.0);
  return scene;
}

TEST(SplineReprojectionCost, JacobiansPassGradientCheckerWithAndWithoutRig) {
  const Scene scene = MakeScene();
  const double weights[4] = {1.0 / 6.0, 0.5, 0.3, 1.0 / 30.0};
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::array<Knot, 4> knots;
  for (Knot& k : knots) {
    for (int i = 0; i < 3; ++i) k[i] = 1e-3 * n(rng);
    for (int i = 3; i < 6; ++i) k[i] = 0.5 * n(rng);
  }
  std::array<double, kRigCorrectionSize> rig = {2e-3, -1e-3, 5e-4,
                                                0.01, -0.02, 0.005};
  Eigen::Matrix2d S;
  S << 2.0, 0.3, 0.0, 1.5;
  for (bool self_calibrating : {false, true}) {
    std::unique_ptr<ceres::CostFunction> cost(SplineReprojectionCost::Create(
        Eigen::Vector2d(600.0, 700.0), S, weights, scene.ins_pose,
        TrackFrame(scene.ins_pose), scene.T_body_cam, scene.intrinsics.data(),
        self_calibrating));
    std::vector<const double*> parameters = {knots[0].data(), knots[1].data(),
                                             knots[2].data(), knots[3].data(),
                                             scene.point_enu.data()};
    if (self_calibrating) parameters.push_back(rig.data());
    double r[2];
    ASSERT_TRUE(cost->Evaluate(parameters.data(), r, nullptr));
    // Ridders' first step is 1 % of each value: 1.2 m on ENU coordinates of
    // 120 m would probe far from the point; 1e-4 stays local.
    ceres::NumericDiffOptions numeric;
    numeric.ridders_relative_initial_step_size = 1e-4;
    const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
    ceres::GradientChecker checker(cost.get(), no_manifolds, numeric);
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(parameters.data(), 1e-6, &results))
        << results.error_log;
  }
}

TEST(SplineReprojectionCost, ZeroCorrectionReprojectsExactly) {
  const Scene scene = MakeScene();
  // The observation is the projection through the INS pose itself.
  const Eigen::Isometry3d T_cam_enu =
      (scene.ins_pose.T_enu_body() * scene.T_body_cam).inverse();
  const Eigen::Vector3d p_cam = T_cam_enu * scene.point_enu;
  Eigen::Vector2d uv;
  ASSERT_TRUE(ProjectToPixel(scene.intrinsics.data(), p_cam.data(), uv.data()));
  const double weights[4] = {1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0};
  std::unique_ptr<ceres::CostFunction> cost(SplineReprojectionCost::Create(
      uv, Eigen::Matrix2d::Identity(), weights, scene.ins_pose,
      TrackFrame(scene.ins_pose), scene.T_body_cam, scene.intrinsics.data(),
      false));
  Knot zero{};
  const double* parameters[5] = {zero.data(), zero.data(), zero.data(),
                                 zero.data(), scene.point_enu.data()};
  double residuals[2];
  ASSERT_TRUE(cost->Evaluate(parameters, residuals, nullptr));
  EXPECT_NEAR(residuals[0], 0.0, 1e-9);
  EXPECT_NEAR(residuals[1], 0.0, 1e-9);
}

TEST(SplineReprojectionCost,
     CorrectionMovesTheCameraAsTrajectoryCorrectionApply) {
  // A correction applied through the cost function and through
  // TrajectoryCorrection::Apply must describe the same camera.
  const Scene scene = MakeScene();
  TrajectoryCorrection correction(0.0, 10.0, 1.0);
  for (Knot& k : correction.knots()) {
    k = {1e-3, -2e-3, 3e-3, 0.4, -0.3, 0.1};
  }
  const double t = 4.3;
  const Pose corrected = correction.Apply(t, scene.ins_pose);
  const Eigen::Isometry3d T_cam_enu =
      (corrected.T_enu_body() * scene.T_body_cam).inverse();
  Eigen::Vector2d uv;
  const Eigen::Vector3d p_cam = T_cam_enu * scene.point_enu;
  ASSERT_TRUE(ProjectToPixel(scene.intrinsics.data(), p_cam.data(), uv.data()));
  int first = 0;
  double w[4];
  correction.Basis(t, &first, w);
  std::unique_ptr<ceres::CostFunction> cost(SplineReprojectionCost::Create(
      uv, Eigen::Matrix2d::Identity(), w, scene.ins_pose,
      correction.Frame(scene.ins_pose), scene.T_body_cam,
      scene.intrinsics.data(), false));
  const auto& k = correction.knots();
  const double* parameters[5] = {k[first].data(), k[first + 1].data(),
                                 k[first + 2].data(), k[first + 3].data(),
                                 scene.point_enu.data()};
  double residuals[2];
  ASSERT_TRUE(cost->Evaluate(parameters, residuals, nullptr));
  EXPECT_NEAR(residuals[0], 0.0, 1e-7);
  EXPECT_NEAR(residuals[1], 0.0, 1e-7);
}

TEST(LinearPrior, SecondDifferenceJacobiansPassGradientChecker) {
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Identity() * 3.0;
  LinearPrior<3, 6> prior(S, {1.0, -2.0, 1.0});
  Knot a = {1, 2, 3, 4, 5, 6}, b = {0.5, 0, 1, 2, 2, 2}, c = {3, 1, 0, 0, 1, 2};
  const double* parameters[3] = {a.data(), b.data(), c.data()};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&prior, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-8, &results)) << results.error_log;
  double r[6];
  prior.Evaluate(parameters, r, nullptr);
  EXPECT_DOUBLE_EQ(r[0], 3.0 * (1 - 1 + 3));
}

TEST(LinearPrior, EverySizeAndCentrePassesGradientChecker) {
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker::ProbeResults results;
  Eigen::Matrix<double, 6, 6> S6 = Eigen::Matrix<double, 6, 6>::Identity();
  S6(0, 1) = 0.5;
  S6(5, 5) = 20.0;
  Eigen::Matrix<double, 6, 1> b;
  b << 0.1, -0.2, 0.3, 1.0, 2.0, -3.0;
  Knot a = {1, 2, 3, 4, 5, 6}, c = {0.5, 0, 1, 2, 2, 2};
  std::unique_ptr<ceres::CostFunction> absolute(
      LinearPrior<1, 6>::Create(S6, {1.0}, b));
  const double* one[1] = {a.data()};
  ceres::GradientChecker check1(absolute.get(), no_manifolds, numeric);
  EXPECT_TRUE(check1.Probe(one, 1e-8, &results)) << results.error_log;
  double r[6];
  absolute->Evaluate(one, r, nullptr);
  EXPECT_NEAR(r[5], 20.0 * (6.0 + 3.0), 1e-12);  // S (x - b)
  EXPECT_NEAR(r[0], (1.0 - 0.1) + 0.5 * (2.0 + 0.2), 1e-12);

  std::unique_ptr<ceres::CostFunction> rate(
      LinearPrior<2, 6>::Create(S6, {-1.0, 1.0}));
  const double* two[2] = {a.data(), c.data()};
  ceres::GradientChecker check2(rate.get(), no_manifolds, numeric);
  EXPECT_TRUE(check2.Probe(two, 1e-8, &results)) << results.error_log;

  const Eigen::Matrix3d S3 = Eigen::Vector3d(10.0, 10.0, 5.0).asDiagonal();
  std::unique_ptr<ceres::CostFunction> offset(
      LinearPrior<1, 3>::Create(S3, {1.0}));
  const double x3[3] = {0.1, -0.05, 0.2};
  const double* three[1] = {x3};
  ceres::GradientChecker check3(offset.get(), no_manifolds, numeric);
  EXPECT_TRUE(check3.Probe(three, 1e-8, &results)) << results.error_log;
}

TEST(PointPriorError, JacobiansPassGradientChecker) {
  const Eigen::Vector3d prior(10.0, 20.0, 30.0);
  Eigen::Matrix3d S = Eigen::Vector3d(10.0, 10.0, 5.0).asDiagonal();
  S(0, 2) = 1.5;
  std::unique_ptr<ceres::CostFunction> cost(PointPriorError::Create(prior, S));
  const Eigen::Vector3d point(10.1, 19.9, 30.2), offset(0.05, 0.0, 0.1);
  const double* parameters[2] = {point.data(), offset.data()};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(cost.get(), no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-8, &results)) << results.error_log;
}

TEST(PointPriorError, WhitensTheDifferenceWithTheOffset) {
  const Eigen::Vector3d prior(10.0, 20.0, 30.0);
  const Eigen::Matrix3d S = Eigen::Vector3d(10.0, 10.0, 5.0).asDiagonal();
  std::unique_ptr<ceres::CostFunction> cost(PointPriorError::Create(prior, S));
  const Eigen::Vector3d point(10.1, 19.9, 30.2), offset(0.05, 0.0, 0.1);
  const double* parameters[2] = {point.data(), offset.data()};
  double r[3];
  ASSERT_TRUE(cost->Evaluate(parameters, r, nullptr));
  EXPECT_NEAR(r[0], 0.5, 1e-12);
  EXPECT_NEAR(r[1], -1.0, 1e-12);
  EXPECT_NEAR(r[2], 0.5, 1e-12);
}

}  // namespace
}  // namespace zebrageo
