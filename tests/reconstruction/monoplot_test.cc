// MonoplotSigmas (issue 51): the standard deviations of a monoplotted
// point against the closed forms of a camera at height h above a level
// road, a point D ahead of it on the road.
#include "reconstruction/monoplot.h"

#include <gtest/gtest.h>

#include <cmath>

namespace zebrageo {
namespace {

constexpr double kHeight = 2.5;    // camera above the road (metres)
constexpr double kAhead = 12.0;    // the point ahead of the camera
constexpr double kFocal = 700.0;   // pixels
constexpr double kBaseline = 1.0;  // metres

RoadPlane LevelRoad() {
  RoadPlane plane;  // body FRD: the road kHeight below the camera (z down)
  plane.normal_body = Eigen::Vector3d::UnitZ();
  plane.offset_m = kHeight;
  return plane;
}

void Sigmas(const Eigen::Vector3d& edge_direction, double line_sigma_m,
            double* across, double* height) {
  MonoplotOptions options;
  options.edge_sigma_px = 0.5;
  options.height_disparity_sigma_px = 0.2;
  MonoplotSigmas(LevelRoad(), Eigen::Vector3d::Zero(),
                 Eigen::Vector3d(kAhead, 0.0, kHeight), edge_direction,
                 kBaseline, 1.0 / kFocal, line_sigma_m, options, across,
                 height);
}

// An edge across the line of sight (a side-street band's long side seen
// from the road): moving it across is moving it along the ray, seen at the
// depression angle h / R: 0.5 px * R^2 / (f h).
TEST(MonoplotSigmas, EdgeAcrossTheLineOfSightIsPlacedAlongTheRayBadly) {
  double across = 0.0, height = 0.0;
  Sigmas(Eigen::Vector3d::UnitY(), 0.0, &across, &height);
  const double range = std::hypot(kAhead, kHeight);
  EXPECT_NEAR(across, 0.5 * range * range / (kFocal * kHeight), 1e-9);
  EXPECT_GT(across, 0.04);  // 4 cm for half a pixel at 12 m
}

// An edge along the line of sight: moving it across moves its image
// sideways, 0.5 px * R / f.
TEST(MonoplotSigmas, EdgeAlongTheLineOfSightIsPlacedAcrossTheRayWell) {
  double across = 0.0, height = 0.0;
  Sigmas(Eigen::Vector3d::UnitX(), 0.0, &across, &height);
  const double range = std::hypot(kAhead, kHeight);
  EXPECT_NEAR(across, 0.5 * range / kFocal, 1e-9);
}

// The height: the triangulated ends' depth error (R^2 / (f B) per pixel of
// disparity) along a ray descending h / R, at least the height line's own.
TEST(MonoplotSigmas, HeightGrowsWithRangeAndKeepsTheLinesSigma) {
  double across = 0.0, height = 0.0;
  Sigmas(Eigen::Vector3d::UnitY(), 0.0, &across, &height);
  const double range = std::hypot(kAhead, kHeight);
  EXPECT_NEAR(height, 0.2 * range * kHeight / (kFocal * kBaseline), 1e-9);
  Sigmas(Eigen::Vector3d::UnitY(), 0.05, &across, &height);
  EXPECT_DOUBLE_EQ(height, 0.05);
}

}  // namespace
}  // namespace zebrageo
