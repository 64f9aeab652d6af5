#include "survey/camera.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

namespace zebrageo {
namespace {

// A realistic 1280x960 road camera with strong barrel distortion.
Camera TestCamera() {
  return Camera("left", 1280, 960, 1110.5, 1108.25, 641.3, 478.9,
                {-0.17, 0.045, 0.0008, -0.0005, -0.004});
}

std::vector<Eigen::Vector3d> PointsAcrossTheImage(const Camera& camera) {
  std::vector<Eigen::Vector3d> points;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> depth(1.0, 60.0);
  for (double u = 0.0; u < camera.width(); u += 64.0) {
    for (double v = 0.0; v < camera.height(); v += 48.0) {
      // Spread points over the undistorted field of view of the image.
      const double x = (u - camera.cx()) / camera.fx();
      const double y = (v - camera.cy()) / camera.fy();
      const double z = depth(rng);
      points.emplace_back(x * z, y * z, z);
    }
  }
  return points;
}

TEST(Camera, ProjectionEqualsOpenCvProjectPoints) {
  const Camera camera = TestCamera();
  const std::vector<Eigen::Vector3d> points = PointsAcrossTheImage(camera);
  std::vector<cv::Point3d> object;
  for (const Eigen::Vector3d& p : points)
    object.emplace_back(p.x(), p.y(), p.z());
  cv::Mat K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = camera.K()(r, c);
  const std::array<double, 5> d = camera.distortion();
  const cv::Mat D = (cv::Mat_<double>(1, 5) << d[0], d[1], d[2], d[3], d[4]);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D,
                    expected);
  double worst_px = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(camera.Project(points[i], &uv));
    worst_px = std::max(
        worst_px, (uv - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
  }
  EXPECT_LT(worst_px, 1e-9);
}

TEST(Camera, UnprojectInvertsProject) {
  const Camera camera = TestCamera();
  double worst_ray = 0.0, worst_px = 0.0;
  for (const Eigen::Vector3d& p : PointsAcrossTheImage(camera)) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(camera.Project(p, &uv));
    Eigen::Vector3d ray;
    ASSERT_TRUE(camera.UnprojectToRay(uv, &ray));
    worst_ray = std::max(worst_ray, (ray - p.normalized()).norm());
    Eigen::Vector2d back;
    ASSERT_TRUE(camera.Project(ray * 7.0, &back));
    worst_px = std::max(worst_px, (back - uv).norm());
  }
  EXPECT_LT(worst_ray, 1e-12);
  EXPECT_LT(worst_px, 1e-9);
}

TEST(Camera, UnprojectCoversEveryPixelOfTheImage) {
  const Camera camera = TestCamera();
  for (double u : {-0.5, 0.0, 639.0, 1279.0, 1279.5}) {
    for (double v : {-0.5, 0.0, 480.0, 959.0, 959.5}) {
      Eigen::Vector2d xy;
      EXPECT_TRUE(camera.UnprojectToNormalized({u, v}, &xy)) << u << "," << v;
    }
  }
}

TEST(Camera, PointBehindTheCameraDoesNotProject) {
  Eigen::Vector2d uv(-1.0, -1.0);
  EXPECT_FALSE(TestCamera().Project({0.1, 0.2, -3.0}, &uv));
  EXPECT_FALSE(TestCamera().Project({0.1, 0.2, 0.0}, &uv));
  EXPECT_EQ(uv, Eigen::Vector2d(-1.0, -1.0));
}

TEST(Camera, TemplatedProjectionGivesAutodiffJacobianEqualToNumeric) {
  using Jet = ceres::Jet<double, 3>;
  const Camera camera = TestCamera();
  const Eigen::Vector3d p(1.2, -0.7, 9.0);
  Jet intrinsics[kNumIntrinsics];
  for (int i = 0; i < kNumIntrinsics; ++i)
    intrinsics[i] = Jet(camera.intrinsics()[i]);
  Jet point[3] = {Jet(p.x(), 0), Jet(p.y(), 1), Jet(p.z(), 2)};
  Jet uv[2];
  ASSERT_TRUE(ProjectToPixel(intrinsics, point, uv));
  const double h = 1e-6;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d plus = p, minus = p;
    plus[axis] += h;
    minus[axis] -= h;
    Eigen::Vector2d uv_plus, uv_minus;
    camera.Project(plus, &uv_plus);
    camera.Project(minus, &uv_minus);
    const Eigen::Vector2d numeric = (uv_plus - uv_minus) / (2 * h);
    EXPECT_NEAR(uv[0].v[axis], numeric.x(), 1e-5);
    EXPECT_NEAR(uv[1].v[axis], numeric.y(), 1e-5);
  }
}

TEST(Camera, IsInImageUsesPixelAreas) {
  const Camera camera = TestCamera();
  EXPECT_TRUE(camera.IsInImage({-0.4, 0.0}));
  EXPECT_FALSE(camera.IsInImage({-0.6, 0.0}));
  EXPECT_TRUE(camera.IsInImage({1279.4, 959.4}));
  EXPECT_FALSE(camera.IsInImage({1279.4, 959.4}, 2.0));
}

}  // namespace
}  // namespace zebrageo
