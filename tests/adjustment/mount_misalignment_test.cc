// The mount misalignment the camera's motion and the road plane observe
// (tiepoints/mount_misalignment.h), on synthetic observations: a vehicle
// driving forward with gentle turns, its camera mounted turned from the
// stated mount by a known rotation, motions and road points with noise.
#include "tiepoints/mount_misalignment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "survey/math_util.h"
#include "tiepoints/mount_observations.h"

namespace zebrageo {
namespace {

Eigen::Isometry3d StatedMount() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Camera z forward and 20 degrees down, x right, y down (FRD body).
  Eigen::Matrix3d R;
  R << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  T.linear() = Eigen::AngleAxisd(DegToRad(-20.0), Eigen::Vector3d::UnitY()) * R;
  T.translation() = Eigen::Vector3d(0.8, -0.5, -1.5);
  return T;
}

Eigen::Isometry3d Turn(const Eigen::Vector3d& w) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (w.norm() > 0.0)
    T.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  return T;
}

// Observations of a camera mounted at Turn(truth) * StatedMount().
MountObservations Observe(const Eigen::Vector3d& truth, int seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Isometry3d X = Turn(truth) * StatedMount();
  MountObservations observations;
  for (int e = 0; e < 40; ++e) {
    // Body a to body b: 2 m along the vehicle's axis (the chord of its
    // arc), turning and pitching a little.
    const Eigen::Vector3d rotation(0.002 * normal(random),
                                   0.003 * normal(random),
                                   0.03 * std::sin(0.3 * e));
    Eigen::Isometry3d T_ba_bb = Turn(rotation);
    T_ba_bb.translation() =
        2.0 * (Turn(0.5 * rotation) * Eigen::Vector3d::UnitX());
    CameraStep step;
    step.camera = 0;
    step.exposure_a = e;
    step.exposure_b = e + 1;
    // Measured: the true motion, with 0.2 degree of direction noise and
    // 0.01 degree of rotation noise.
    const Eigen::Isometry3d measured = X.inverse() * T_ba_bb.inverse() * X;
    Eigen::Isometry3d noise =
        Turn(DegToRad(0.01) *
             Eigen::Vector3d(normal(random), normal(random), normal(random)));
    noise.translation() =
        0.007 * Eigen::Vector3d(normal(random), normal(random), 0.0);
    step.T_cb_ca = noise * measured;
    // The trajectory's: its positions jitter by 2 cm between exposures
    // (1.4 cm rms sideways over 2 m: 0.4 degree), its attitude does not.
    T_ba_bb.translation() +=
        0.02 * Eigen::Vector3d(normal(random), normal(random), normal(random));
    step.T_bb_ba = T_ba_bb.inverse();
    step.inliers = 50;
    observations.steps.push_back(step);
    // The road 2 m below the body origin, in the camera's frame.
    StereoPoints points;
    points.camera = 0;
    points.exposure = e;
    for (int k = 0; k < 80; ++k) {
      const Eigen::Vector3d p_body(4.0 + 0.2 * k, -2.0 + 0.5 * (k % 9),
                                   2.0 + 0.01 * normal(random));
      points.points_cam.push_back(X.inverse() * p_body);
    }
    observations.stereo_points.push_back(points);
  }
  return observations;
}

Rig StatedRig() {
  Rig rig;
  rig.cameras.resize(1);
  rig.cameras[0].T_body_cam = StatedMount();
  rig.stereo_pairs.push_back({0, 0});
  return rig;
}

TEST(MountMisalignment, FindsTheRotationTheDataObserve) {
  const Eigen::Vector3d truth(DegToRad(0.6), DegToRad(-0.4), DegToRad(0.95));
  const MountMisalignment estimate = EstimateMountMisalignment(
      MountMisalignmentOptions(), StatedRig(), Observe(truth, 1));
  ASSERT_TRUE(estimate.estimated);
  EXPECT_EQ(estimate.steps_used, 40);
  EXPECT_EQ(estimate.planes_used, 40);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(estimate.rotation_body_rad[k], truth[k], DegToRad(0.05)) << k;
    // Its standard deviation says how well: honest, and small here.
    EXPECT_LT(std::abs(estimate.rotation_body_rad[k] - truth[k]),
              4.0 * estimate.sd_rad[k] + 1e-4)
        << k;
    EXPECT_LT(estimate.sd_rad[k], DegToRad(0.1)) << k;
  }
  // Turning the rig by the estimate leaves nothing to find.
  const Rig turned = RotateRigMount(StatedRig(), estimate.rotation_body_rad);
  const MountMisalignment again = EstimateMountMisalignment(
      MountMisalignmentOptions(), turned, Observe(truth, 1));
  EXPECT_LT(again.rotation_body_rad.norm(), DegToRad(0.01));
}

TEST(MountMisalignment, AStatedMountGivesNoRotationBeyondItsNoise) {
  for (int seed = 2; seed < 6; ++seed) {
    const MountMisalignment estimate =
        EstimateMountMisalignment(MountMisalignmentOptions(), StatedRig(),
                                  Observe(Eigen::Vector3d::Zero(), seed));
    ASSERT_TRUE(estimate.estimated);
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT(std::abs(estimate.rotation_body_rad[k]),
                std::max(4.0 * estimate.sd_rad[k], DegToRad(0.05)))
          << "seed " << seed << " axis " << k;
    }
  }
}

TEST(MountMisalignment, RefusesBadOptions) {
  MountMisalignmentOptions options;
  options.min_step_m = -1.0;
  EXPECT_THROW(
      EstimateMountMisalignment(options, StatedRig(), MountObservations()),
      std::invalid_argument);
}

// A long survey is read in runs of consecutive exposures spread over its
// whole length, never more than max_exposures of them; a short one whole.
TEST(MountObservations, SamplesLongSurveysInRunsSpreadAlongThem) {
  const std::vector<bool> all = SampledExposures(100, 120, 4);
  EXPECT_EQ(std::count(all.begin(), all.end(), true), 100);
  const std::vector<bool> every = SampledExposures(5000, 0, 4);
  EXPECT_EQ(std::count(every.begin(), every.end(), true), 5000);
  for (const int n : {121, 997, 100000}) {
    const std::vector<bool> sampled = SampledExposures(n, 120, 4);
    ASSERT_EQ(static_cast<int>(sampled.size()), n);
    EXPECT_EQ(std::count(sampled.begin(), sampled.end(), true), 120) << n;
    EXPECT_TRUE(sampled.front() && sampled.back()) << n;
    // Runs of at least 4 consecutive exposures (two may touch on a short
    // survey), with no stretch unsampled longer than the survey's share.
    int run = 0, gap = 0, longest_gap = 0;
    for (int e = 0; e < n; ++e) {
      if (sampled[e]) {
        ++run;
        gap = 0;
      } else {
        if (run > 0) {
          EXPECT_GE(run, 4) << n << " exposure " << e;
        }
        run = 0;
        longest_gap = std::max(longest_gap, ++gap);
      }
    }
    EXPECT_LE(longest_gap, n / 29) << n;  // 30 runs: 29 gaps
  }
  MountObservationOptions options;
  options.max_exposures = 1;
  EXPECT_FALSE(options.Check().empty());
}

}  // namespace
}  // namespace zebrageo
