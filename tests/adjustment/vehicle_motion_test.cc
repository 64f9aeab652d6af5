#include "adjustment/vehicle_motion.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

namespace zebrageo {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// A vehicle on a circle of radius `radius_m` (counter-clockwise seen from
// above, a left turn; 0 = straight east) at `speed_mps`; the INS sits
// `axle_offset_m` ahead of the rear axle, which follows the path without
// slipping, so the INS moves sideways on a turn.
struct Drive {
  double radius_m = 0.0;
  double speed_mps = 10.0;
  double axle_offset_m = 0.0;

  Pose At(double t) const {
    Pose pose;
    double yaw = 0.0;  // ENU angle of the body x axis from east
    Eigen::Vector3d axle(speed_mps * t, 0.0, 50.0);
    if (radius_m > 0.0) {
      yaw = speed_mps * t / radius_m;
      axle = Eigen::Vector3d(radius_m * std::sin(yaw),
                             radius_m * (1.0 - std::cos(yaw)), 50.0);
    }
    const Eigen::Vector3d forward(std::cos(yaw), std::sin(yaw), 0.0);
    // Body FRD: x forward, y right, z down.
    Eigen::Matrix3d R;
    R.col(0) = forward;
    R.col(1) = Eigen::Vector3d(std::sin(yaw), -std::cos(yaw), 0.0);
    R.col(2) = -Eigen::Vector3d::UnitZ();
    pose.q_enu_body = Eigen::Quaterniond(R);
    pose.p_enu = axle + axle_offset_m * forward;
    return pose;
  }
};

std::vector<VehicleMotionSample> Samples(const Drive& drive,
                                         const TrajectoryCorrection& c,
                                         double duration_s) {
  std::vector<double> times;
  for (double t = 0.0; t <= duration_s + 1e-9; t += 0.01) times.push_back(t);
  return MakeVehicleMotionSamples(c, times, 10.0, 0.05, 2.0,
                                  Eigen::Vector2d(0.1, 0.35) * kDegToRad,
                                  [&](double t, Pose* pose) {
                                    *pose = drive.At(t);
                                    return true;
                                  });
}

TEST(VehicleMotion, ZeroWhenTheVehicleMovesAlongItsHeading) {
  const TrajectoryCorrection correction(0.0, 10.0, 1.0);
  const double vehicle[kVehicleSize] = {0.0, 0.0, 0.0};
  for (double radius : {0.0, 40.0}) {
    Drive drive;
    drive.radius_m = radius;
    const auto samples = Samples(drive, correction, 10.0);
    ASSERT_GT(samples.size(), 90u);
    for (const VehicleMotionSample& s : samples) {
      // A chord of a circle points along the tangent at its mid-time.
      EXPECT_NEAR(CrabAngleResidual(s, correction, vehicle).norm(), 0.0, 1e-9);
    }
  }
}

TEST(VehicleMotion, AHeadingErrorIsSeenAsCrabAndCorrected) {
  Drive drive;
  TrajectoryCorrection correction(0.0, 10.0, 1.0);
  const auto samples = Samples(drive, correction, 10.0);
  ASSERT_FALSE(samples.empty());
  const double vehicle[kVehicleSize] = {0.0, 0.0, 0.0};
  // A correction turning the heading 1 mrad to the left (about up): the
  // velocity is then 1 mrad to the right of the body's x axis (FRD y).
  for (Knot& k : correction.knots()) k[2] = 1e-3;
  for (const VehicleMotionSample& s : samples) {
    const Eigen::Vector2d crab = CrabAngleResidual(s, correction, vehicle);
    EXPECT_NEAR(crab.x(), 1e-3, 1e-9);
    EXPECT_NEAR(crab.y(), 0.0, 1e-9);
  }
  // A pitch-up correction (about the track frame's y, to the left): the
  // velocity points below the body's x axis (FRD z down).
  for (Knot& k : correction.knots()) k = Knot{0.0, -1e-3, 0.0, 0.0, 0.0, 0.0};
  for (const VehicleMotionSample& s : samples) {
    EXPECT_NEAR(CrabAngleResidual(s, correction, vehicle).y(), 1e-3, 1e-9);
  }
  // A cross-track drift of the correction: 1 cm/s to the left at 10 m/s
  // turns the velocity 1 mrad to the left.
  for (Knot& k : correction.knots()) k.fill(0.0);
  for (int k = 0; k < correction.num_knots(); ++k) {
    correction.knots()[k][4] = 0.01 * correction.KnotTime(k);
  }
  for (const VehicleMotionSample& s : samples) {
    EXPECT_NEAR(CrabAngleResidual(s, correction, vehicle).x(), -1e-3, 1e-6);
  }
  // The same drift with the chord stretched by a tenth (1 m/s forward):
  // the crab must not shrink by a tenth, or the adjustment buys a smaller
  // crab with metres of along-track correction (seen through GNSS outages).
  for (int k = 0; k < correction.num_knots(); ++k) {
    correction.knots()[k][3] = 1.0 * correction.KnotTime(k);
  }
  for (const VehicleMotionSample& s : samples) {
    EXPECT_NEAR(CrabAngleResidual(s, correction, vehicle).x(), -1e-3, 1e-6);
  }
}

TEST(VehicleMotion, AxleOffsetExplainsTheCrabOnATurn) {
  Drive drive;
  drive.radius_m = 40.0;
  drive.axle_offset_m = 1.5;
  const TrajectoryCorrection correction(0.0, 10.0, 1.0);
  const auto samples = Samples(drive, correction, 10.0);
  ASSERT_FALSE(samples.empty());
  const double none[kVehicleSize] = {0.0, 0.0, 0.0};
  const double offset[kVehicleSize] = {0.0, 1.5, 0.0};
  for (const VehicleMotionSample& s : samples) {
    // A point 1.5 m ahead of the axle on a 40 m left turn moves left:
    // atan(1.5 / 40) = 2.1 degrees.
    EXPECT_NEAR(CrabAngleResidual(s, correction, none).x(),
                -std::atan(1.5 / 40.0), 2e-4);
    EXPECT_NEAR(CrabAngleResidual(s, correction, offset).x(), 0.0, 2e-4);
  }
}

TEST(VehicleMotion, SlowSamplesAreSkippedAndTheRateIsKept) {
  Drive drive;
  const TrajectoryCorrection correction(0.0, 20.0, 1.0);
  EXPECT_NEAR(static_cast<double>(Samples(drive, correction, 20.0).size()),
              200.0, 2.0);
  drive.speed_mps = 1.0;  // below the 2 m/s minimum
  EXPECT_TRUE(Samples(drive, correction, 20.0).empty());
}

TEST(VehicleMotionCost, JacobiansPassGradientChecker) {
  Drive drive;
  drive.radius_m = 60.0;
  TrajectoryCorrection correction(0.0, 10.0, 0.5);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (Knot& k : correction.knots()) {
    for (int i = 0; i < 3; ++i) k[i] = 1e-3 * n(rng);
    for (int i = 3; i < 6; ++i) k[i] = 0.3 * n(rng);
  }
  const auto samples = Samples(drive, correction, 10.0);
  ASSERT_GT(samples.size(), 40u);
  std::array<double, kVehicleSize> vehicle = {1e-3, 0.4, -2e-3};
  // One sample whose three times straddle a knot boundary (4 + 1 knots).
  for (size_t i : {size_t{5}, size_t{40}}) {
    std::unique_ptr<VehicleMotionCost> cost(
        VehicleMotionCost::Create(samples[i], correction));
    std::vector<const double*> parameters;
    for (int k = 0; k < cost->num_knots(); ++k) {
      parameters.push_back(correction.knots()[cost->first_knot() + k].data());
    }
    parameters.push_back(vehicle.data());
    double r[2];
    ASSERT_TRUE(cost->Evaluate(parameters.data(), r, nullptr));
    EXPECT_TRUE(std::isfinite(r[0]) && std::isfinite(r[1]));
    ceres::NumericDiffOptions numeric;
    numeric.ridders_relative_initial_step_size = 1e-4;
    const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
    ceres::GradientChecker checker(cost.get(), no_manifolds, numeric);
    ceres::GradientChecker::ProbeResults results;
    // 1e-5: some derivatives are 1e-5 small, and the numeric differences
    // come within a few 1e-11 of them; a wrong Jacobian is off by far more.
    EXPECT_TRUE(checker.Probe(parameters.data(), 1e-5, &results))
        << results.error_log;
  }
}

}  // namespace
}  // namespace zebrageo
