#include "tiepoints/stereo_odometry.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace zebrageo {
namespace {

constexpr double kFocalPx = 800.0;

// A stereo rig 1 m wide: camera b to the right of camera a.
Eigen::Isometry3d RigT_cb_ca() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(-1.0, 0.0, 0.0);
  return T;
}

Eigen::Vector2d Normalised(const Eigen::Vector3d& p) {
  return p.head<2>() / p.z();
}

// The motion of a camera driving forward 1.5 m with a small turn: what the
// images must measure, and a trajectory's version of it off by `error_m`
// sideways and along (jitter).
Eigen::Isometry3d TrueMotion() {
  Eigen::Isometry3d T_ca_cb = Eigen::Isometry3d::Identity();
  T_ca_cb.linear() =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_ca_cb.translation() = Eigen::Vector3d(0.02, 0.0, 1.5);
  return T_ca_cb.inverse();  // T_cb_ca
}

Eigen::Isometry3d Jittered(const Eigen::Isometry3d& T_cb_ca, double error_m) {
  Eigen::Isometry3d T = T_cb_ca;
  T.translation() += Eigen::Vector3d(error_m, 0.0, -error_m);
  return T;
}

struct Scene {
  std::vector<Eigen::Vector3d> points_ca;
  std::vector<Eigen::Vector2d> x_b;
};

// n points 4 to 20 m ahead seen again after the true motion, with pixel
// noise; the first `outliers` of them matched to the wrong image point.
Scene MakeScene(int n, int outliers, double noise_px, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(-4.0, 4.0), y(-1.0, 1.6),
      z(4.0, 20.0), u(-0.4, 0.4);
  std::normal_distribution<double> noise(0.0, noise_px / kFocalPx);
  Scene scene;
  const Eigen::Isometry3d T_cb_ca = TrueMotion();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p(x(rng), y(rng), z(rng));
    scene.points_ca.push_back(p);
    Eigen::Vector2d seen = Normalised(T_cb_ca * p);
    seen += Eigen::Vector2d(noise(rng), noise(rng));
    if (i < outliers) seen = Eigen::Vector2d(u(rng), u(rng));
    scene.x_b.push_back(seen);
  }
  return scene;
}

TEST(TriangulateStereoPoint, RecoversThePointAndRefusesRaysThatMiss) {
  const StereoOdometryOptions options;
  const Eigen::Vector3d p(1.2, 0.8, 12.0);
  const Eigen::Isometry3d T_cb_ca = RigT_cb_ca();
  Eigen::Vector3d found;
  ASSERT_TRUE(TriangulateStereoPoint(options, T_cb_ca, Normalised(p),
                                     Normalised(T_cb_ca * p), kFocalPx,
                                     &found));
  EXPECT_LT((found - p).norm(), 1e-9);
  // Two pixels off the epipolar line: the rays do not meet.
  const Eigen::Vector2d off =
      Normalised(T_cb_ca * p) + Eigen::Vector2d(0.0, 2.0 / kFocalPx);
  EXPECT_FALSE(TriangulateStereoPoint(options, T_cb_ca, Normalised(p), off,
                                      kFocalPx, &found));
  // Beyond max_range_m.
  const Eigen::Vector3d far(0.0, 0.5, 60.0);
  EXPECT_FALSE(TriangulateStereoPoint(options, T_cb_ca, Normalised(far),
                                      Normalised(T_cb_ca * far), kFocalPx,
                                      &found));
}

TEST(CameraMotionFromStereoPoints,
     MeasuresTheMotionAJitteringTrajectoryMisses) {
  const StereoOdometryOptions options;
  // 60 points, 15 of them mismatched, 0.3 px noise; the trajectory's
  // motion is 12 cm off.
  const Scene scene = MakeScene(60, 15, 0.3, 7);
  const Eigen::Isometry3d prior = Jittered(TrueMotion(), 0.12);
  const CameraMotion motion = CameraMotionFromStereoPoints(
      options, scene.points_ca, scene.x_b, prior, kFocalPx);
  ASSERT_TRUE(motion.valid);
  EXPECT_GE(motion.inliers, 40);
  EXPECT_LE(motion.inliers, 46);  // the mismatches are not inliers
  const Eigen::Isometry3d error = TrueMotion().inverse() * motion.T_cb_ca;
  EXPECT_LT(error.translation().norm(), 0.01);  // from 12 cm to under 1 cm
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), 1e-3);
}

TEST(CameraMotionFromStereoPoints, RefusesTooFewPointsAndImplausibleMotions) {
  const StereoOdometryOptions options;
  const Scene few = MakeScene(options.min_inliers - 1, 0, 0.3, 8);
  EXPECT_FALSE(CameraMotionFromStereoPoints(options, few.points_ca, few.x_b,
                                            TrueMotion(), kFocalPx)
                   .valid);
  // Mostly mismatched (a repeated pattern): no consensus.
  const Scene junk = MakeScene(40, 32, 0.3, 9);
  EXPECT_FALSE(CameraMotionFromStereoPoints(options, junk.points_ca, junk.x_b,
                                            TrueMotion(), kFocalPx)
                   .valid);
  // A sound measurement 0.8 m from the trajectory's motion is not believed:
  // beyond max_translation_change_m the images were misread.
  const Scene scene = MakeScene(60, 0, 0.3, 10);
  EXPECT_FALSE(CameraMotionFromStereoPoints(options, scene.points_ca, scene.x_b,
                                            Jittered(TrueMotion(), 0.6),
                                            kFocalPx)
                   .valid);
}

}  // namespace
}  // namespace zebrageo
