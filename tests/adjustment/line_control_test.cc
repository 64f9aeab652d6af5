#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "adjustment/line_costs.h"

namespace zebrageo {
namespace {

TEST(LineSqrtInformation, WhitensBothUncertainties) {
  Eigen::Matrix3d covariance_body;
  covariance_body << 4e-4, 1e-5, 2e-5, 1e-5, 1e-4, 3e-5, 2e-5, 3e-5, 2e-4;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d across(std::cos(0.3), std::sin(0.3), 0.0);
  const Eigen::Matrix2d S =
      LineSqrtInformation(covariance_body, R, across, 0.05, 0.04);
  Eigen::Matrix<double, 2, 3> J;
  J.row(0) = across.transpose();
  J.row(1) = Eigen::Vector3d::UnitZ().transpose();
  Eigen::Matrix2d C = J * R * covariance_body * R.transpose() * J.transpose();
  C(0, 0) += 0.05 * 0.05;
  C(1, 1) += 0.04 * 0.04;
  EXPECT_TRUE(
      (S * C * S.transpose()).isApprox(Eigen::Matrix2d::Identity(), 1e-9));
}

// A vehicle heading east at the origin sees a line point 8 m ahead and
// 1.7 m to the left; the database line runs east at y = 1.7 (body y is
// right, so left is -y; heading east, left is north).
class LinePointErrorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Body FRD heading east: x -> east, y -> south, z -> down.
    Eigen::Matrix3d R;
    R.col(0) = Eigen::Vector3d::UnitX();
    R.col(1) = -Eigen::Vector3d::UnitY();
    R.col(2) = -Eigen::Vector3d::UnitZ();
    pose_.q_enu_body = Eigen::Quaterniond(R);
    pose_.p_enu = Eigen::Vector3d(0, 0, 2.0);
    point_.time = 1.0;
    point_.p_body = Eigen::Vector3d(8.0, -1.7, 2.0);  // on the road, z = 0
    point_.db_point_enu = Eigen::Vector3d(8.0, 1.7, 0.0);
    point_.across_enu = Eigen::Vector3d::UnitY();
    point_.sqrt_information = Eigen::Vector2d(1 / 0.02, 1 / 0.03).asDiagonal();
  }
  Eigen::Vector2d Residual(const Eigen::Matrix<double, 6, 1>& c) const {
    const LinePointError error(point_, pose_, Eigen::Matrix3d::Identity());
    Eigen::Vector2d r;
    EXPECT_TRUE(error(c.data(), r.data()));
    return r;
  }
  Pose pose_;
  LineControlPoint point_;
};

TEST_F(LinePointErrorTest, ZeroOnTheLineAndBlindAlongIt) {
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  EXPECT_NEAR(Residual(c).norm(), 0.0, 1e-12);
  c[3] = 0.5;  // half a metre east: along the line
  EXPECT_NEAR(Residual(c).norm(), 0.0, 1e-12);
}

TEST_F(LinePointErrorTest, AcrossAndHeightInSigmas) {
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  c[4] = 0.04;   // 4 cm north: across
  c[5] = -0.03;  // 3 cm down
  const Eigen::Vector2d r = Residual(c);
  EXPECT_NEAR(r[0], 2.0, 1e-9);
  EXPECT_NEAR(r[1], -1.0, 1e-9);
  // A heading error turns the point 8 m ahead sideways: 1 mrad, 8 mm.
  c.setZero();
  c[2] = 1e-3;
  EXPECT_NEAR(Residual(c)[0], 0.008 / 0.02, 1e-3);
}

TEST_F(LinePointErrorTest, HeightFollowsTheLineGradeAlongIt) {
  // The line climbs 3 % eastwards; the INS put the point at D, the
  // correction moves it 1 m east (along the line) and 3 cm up: on the line.
  point_.along_enu = Eigen::Vector3d::UnitX();
  point_.grade = 0.03;
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  c[3] = 1.0;
  c[5] = 0.03;
  EXPECT_NEAR(Residual(c).norm(), 0.0, 1e-12);
  // Without the grade the same correction is 1 sigma too high.
  point_.grade = 0.0;
  EXPECT_NEAR(Residual(c)[1], 1.0, 1e-9);
}

TEST_F(LinePointErrorTest, SplineCostChainsToTheKnots) {
  const double w[4] = {0.1, 0.4, 0.4, 0.1};
  std::unique_ptr<ceres::CostFunction> cost(
      LinePointCost::Create(point_, pose_, Eigen::Matrix3d::Identity(), w));
  double knots[4][6] = {};
  for (int j = 0; j < 4; ++j) knots[j][4] = 0.02;  // all 2 cm north
  const double* parameters[4] = {knots[0], knots[1], knots[2], knots[3]};
  double r[2];
  double jacobian[4][12];
  double* jacobians[4] = {jacobian[0], jacobian[1], jacobian[2], jacobian[3]};
  ASSERT_TRUE(cost->Evaluate(parameters, r, jacobians));
  EXPECT_NEAR(r[0], 1.0, 1e-9);
  for (int j = 0; j < 4; ++j) {
    // d r_across / d (knot j north) = w_j / sigma.
    EXPECT_NEAR(jacobian[j][4], w[j] / 0.02, 1e-9);
    EXPECT_NEAR(jacobian[j][3], 0.0, 1e-9);  // east: along the line
  }
}

}  // namespace
}  // namespace zebrageo
