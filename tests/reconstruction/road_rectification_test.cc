#include "reconstruction/road_rectification.h"

#include <gtest/gtest.h>

#include <cmath>

namespace zebrageo {
namespace {

// Two 1280 x 960 cameras 1 m apart, 2.5 m over the road (body z down, the
// road at z = +1), pitched down by 20 degrees, with barrel distortion.
RigCamera MakeCamera(const std::string& name, double y) {
  RigCamera rig_camera;
  rig_camera.camera = Camera(name, 1280, 960, 1100.0, 1100.0, 640.0, 480.0,
                             {-0.15, 0.06, 4e-4, -3e-4, -0.01});
  const double pitch = 20.0 * M_PI / 180.0;
  // Camera axes in the body frame: x right, y down-forward, z forward-down.
  Eigen::Matrix3d R_body_cam;
  R_body_cam.col(0) = Eigen::Vector3d(0, 1, 0);
  R_body_cam.col(2) = Eigen::Vector3d(std::cos(pitch), 0, std::sin(pitch));
  R_body_cam.col(1) = R_body_cam.col(2).cross(R_body_cam.col(0));
  rig_camera.T_body_cam.linear() = R_body_cam;
  rig_camera.T_body_cam.translation() = Eigen::Vector3d(0.8, y, -1.5);
  return rig_camera;
}

// `camber`: the road's slope across the vehicle (along the baseline).
RoadPlane Road(double camber = 0.0) {
  RoadPlane plane;
  plane.normal_body = Eigen::Vector3d(0.0, camber, 1.0).normalized();
  plane.offset_m = 1.0;
  return plane;
}

class RoadRectificationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    left_ = MakeCamera("left", -0.5);
    right_ = MakeCamera("right", 0.5);
    std::string error;
    ASSERT_TRUE(
        rect_.Build(left_, right_, Road(), RectificationOptions(), &error))
        << error;
  }
  RigCamera left_, right_;
  RoadRectification rect_;
};

TEST(RoadRectification, CamberedRoadHasASmallDisparityGradient) {
  RoadRectification rect;
  std::string error;
  ASSERT_TRUE(rect.Build(MakeCamera("l", -0.5), MakeCamera("r", 0.5),
                         Road(0.02), RectificationOptions(), &error));
  for (double y : {-4.0, 0.0, 3.0}) {
    const Eigen::Vector3d p = Road(0.02).Project(Eigen::Vector3d(8.0, y, 0));
    EXPECT_LT(std::abs(rect.DisparityOf(p)), 3.0);
  }
}

TEST_F(RoadRectificationTest, RoadPointsHaveTheSamePixelInBothImages) {
  for (double x : {4.0, 8.0, 15.0}) {
    for (double y : {-4.0, 0.0, 3.0}) {
      Eigen::Vector3d p(x, y, 0.0);
      p = Road().Project(p);
      EXPECT_NEAR(rect_.DisparityOf(p), 0.0, 1e-9);
      // The ground sample distance holds at the road.
      Eigen::Vector2d a, b;
      ASSERT_TRUE(rect_.ProjectToRectified(0, p, &a));
      ASSERT_TRUE(
          rect_.ProjectToRectified(0, p + Eigen::Vector3d(0, 0.1, 0), &b));
      EXPECT_NEAR((b - a).norm() * 0.015, 0.1, 0.002);
    }
  }
}

TEST_F(RoadRectificationTest, TriangulationInvertsProjection) {
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(6.0, 1.0, 0.7), Eigen::Vector3d(12.0, -3.0, 1.1),
        Eigen::Vector3d(18.0, 2.0, -0.5)}) {
    Eigen::Vector2d l, r;
    ASSERT_TRUE(rect_.ProjectToRectified(0, p, &l));
    ASSERT_TRUE(rect_.ProjectToRectified(1, p, &r));
    EXPECT_NEAR(l.y(), r.y(), 1e-9);  // epipolar lines are rows
    Eigen::Vector3d q;
    ASSERT_TRUE(rect_.Triangulate(l.x(), r.x(), l.y(), &q));
    EXPECT_LT((q - p).norm(), 1e-9);
  }
}

TEST_F(RoadRectificationTest, TriangulationJacobianMatchesNumeric) {
  const double xl = 400.3, xr = 401.1, y = 500.2, h = 1e-4;
  const Eigen::Matrix3d J = rect_.TriangulationJacobian(xl, xr, y);
  const double in[3] = {xl, xr, y};
  for (int k = 0; k < 3; ++k) {
    double plus[3] = {in[0], in[1], in[2]}, minus[3] = {in[0], in[1], in[2]};
    plus[k] += h;
    minus[k] -= h;
    Eigen::Vector3d a, b;
    ASSERT_TRUE(rect_.Triangulate(plus[0], plus[1], plus[2], &a));
    ASSERT_TRUE(rect_.Triangulate(minus[0], minus[1], minus[2], &b));
    EXPECT_LT((J.col(k) - (a - b) / (2 * h)).norm(), 1e-6);
  }
}

TEST_F(RoadRectificationTest, RemapTablesFollowTheDistortedCamera) {
  // An image whose value is its own column: the rectified value at a road
  // point is the column where the original camera sees it.
  cv::Mat columns(960, 1280, CV_32F), rows(960, 1280, CV_32F);
  for (int v = 0; v < 960; ++v) {
    for (int u = 0; u < 1280; ++u) {
      columns.at<float>(v, u) = u * 0.1f;
      rows.at<float>(v, u) = v * 0.1f;
    }
  }
  cv::Mat rect_columns, rect_rows;
  rect_.Rectify(columns, rows, &rect_columns, &rect_rows);
  for (double x : {5.0, 10.0}) {
    for (double y : {-2.0, 1.0}) {
      const Eigen::Vector3d p = Road().Project(Eigen::Vector3d(x, y, 0.0));
      Eigen::Vector2d xy, uv_left, uv_right;
      ASSERT_TRUE(rect_.ProjectToRectified(0, p, &xy));
      ASSERT_TRUE(rect_.IsValid(xy.x(), xy.y()));
      ASSERT_TRUE(
          left_.camera.Project(left_.T_body_cam.inverse() * p, &uv_left));
      ASSERT_TRUE(
          right_.camera.Project(right_.T_body_cam.inverse() * p, &uv_right));
      // Rectified pixel centres only: compare at the nearest one.
      const int xi = static_cast<int>(std::lround(xy.x()));
      const int yi = static_cast<int>(std::lround(xy.y()));
      Eigen::Vector2d uv_at;
      const Eigen::Vector3d ray = rect_.RayBody(0, Eigen::Vector2d(xi, yi));
      ASSERT_TRUE(left_.camera.Project(
          left_.T_body_cam.linear().transpose() * ray, &uv_at));
      EXPECT_NEAR(rect_columns.at<float>(yi, xi) * 10.0, uv_at.x(), 0.05);
      const Eigen::Vector3d ray_right =
          rect_.RayBody(1, Eigen::Vector2d(xi, yi));
      ASSERT_TRUE(right_.camera.Project(
          right_.T_body_cam.linear().transpose() * ray_right, &uv_at));
      EXPECT_NEAR(rect_rows.at<float>(yi, xi) * 10.0, uv_at.y(), 0.05);
    }
  }
}

TEST(RoadRectification, RefusesCamerasBelowTheRoad) {
  RoadPlane plane = Road();
  plane.offset_m = -3.0;
  RoadRectification rect;
  std::string error;
  EXPECT_FALSE(rect.Build(MakeCamera("l", -0.5), MakeCamera("r", 0.5), plane,
                          RectificationOptions(), &error));
  EXPECT_EQ(error, "the left camera is not above the road plane");
}

TEST(RoadRectification, CheckNamesTheBadField) {
  RectificationOptions options;
  options.ground_pixel_m = 0.0;
  EXPECT_EQ(options.Check(), "ground_pixel_m = 0: must be in (0, 0.2]");
}

}  // namespace
}  // namespace zebrageo
