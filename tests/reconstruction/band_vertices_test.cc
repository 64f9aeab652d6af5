#include "reconstruction/band_vertices.h"

#include <gtest/gtest.h>

#include <cmath>

namespace zebrageo {
namespace {

TEST(EndAngle, ZeroForASkewedBandLargeForAStainCutEnd) {
  // A band 0.5 m wide, 3 m long, skewed 30 degrees (x along the band).
  const double skew = 30.0 * M_PI / 180.0;
  const Eigen::Vector3d across(std::tan(skew) * 0.5, 0.5, 0.0);
  std::array<Eigen::Vector3d, 4> band = {
      Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1) + across,
      Eigen::Vector3d(3, 0, 1) + across, Eigen::Vector3d(3, 0, 1)};
  EXPECT_LT(EndAngleRad(band), 1e-12);
  // Ambiguity seed 2: a dark stain cuts the band 0.28 m further along at
  // one corner than at the other.
  band = {Eigen::Vector3d(6.735, 0.996, 1.010),
          Eigen::Vector3d(6.736, 0.494, 1.013),
          Eigen::Vector3d(4.073, 0.513, 1.011),
          Eigen::Vector3d(3.796, 1.012, 1.007)};
  EXPECT_NEAR(EndAngleRad(band), 0.51, 0.02);
  EXPECT_GT(EndAngleRad(band), BandOptions().max_end_angle_rad);
}

}  // namespace
}  // namespace zebrageo
