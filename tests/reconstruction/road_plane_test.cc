#include "reconstruction/road_plane.h"

#include <gtest/gtest.h>

#include <random>

namespace zebrageo {
namespace {

TEST(RoadPlane, RansacFindsTheRoadDespiteHalfOutliers) {
  // Road 1.2 m below the body origin, tilted by the camber; half the points
  // are facades, cars and mismatches.
  const Eigen::Vector3d normal = Eigen::Vector3d(0.01, 0.03, 1.0).normalized();
  const double offset = 1.2;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> along(2.0, 20.0), across(-6.0, 6.0),
      height(-3.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 400; ++i) {
    const double x = along(rng), y = across(rng);
    if (i % 2 == 0) {
      const double z = (offset - normal.x() * x - normal.y() * y) / normal.z();
      points.emplace_back(x, y, z + noise(rng));
    } else {
      points.emplace_back(x, y, height(rng));  // anywhere above the road
    }
  }
  RoadPlaneOptions options;
  const RoadPlaneFit fit =
      FitRoadPlane(points, Eigen::Vector3d::UnitZ(), options, 42);
  ASSERT_TRUE(fit.ok);
  EXPECT_LT((fit.plane.normal_body - normal).norm(), 2e-3);
  EXPECT_NEAR(fit.plane.offset_m, offset, 0.01);
  // The kept points are the road's, and the few outliers that happen to
  // lie within 20 cm of it.
  int road = 0;
  for (int i : fit.inliers) road += i % 2 == 0;
  EXPECT_EQ(road, 200);
  EXPECT_LT(static_cast<int>(fit.inliers.size()) - road, 30);
}

TEST(RoadPlane, RejectsAFacadeEvenWhenItHoldsMostPoints) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(i * 0.1, 5.0, -i * 0.02);
  RoadPlaneOptions options;
  const RoadPlaneFit fit =
      FitRoadPlane(points, Eigen::Vector3d::UnitZ(), options, 1);
  EXPECT_FALSE(fit.ok);
}

TEST(RoadPlane, LeastSquaresOrientsTheNormalDown) {
  std::vector<Eigen::Vector3d> points = {
      {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  RoadPlane plane;
  ASSERT_TRUE(FitPlaneLeastSquares(points, Eigen::Vector3d::UnitZ(), &plane));
  EXPECT_NEAR(plane.normal_body.z(), 1.0, 1e-12);
  EXPECT_NEAR(plane.offset_m, 1.0, 1e-12);
  EXPECT_NEAR(plane.SignedDistance(Eigen::Vector3d(3, 3, 1.5)), 0.5, 1e-12);
}

TEST(RoadPlane, CheckNamesTheBadField) {
  RoadPlaneOptions options;
  options.ransac_tolerance_m = -1;
  EXPECT_EQ(options.Check(), "ransac_tolerance_m = -1: must be > 0");
}

}  // namespace
}  // namespace zebrageo
