#include "reconstruction/crossing_regularity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace zebrageo {
namespace {

Eigen::Vector2d AtAngle(double angle) {
  return Eigen::Vector2d(std::cos(angle), std::sin(angle));
}

double AngleBetweenLines(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

TEST(CrossingEndDirection, NearEndsOutweighFarOnesAndAStainDoesNotPull) {
  // A crossing skewed 20 degrees: near ends (weight 1/8^4) good to 0.01
  // rad, far ones (1/14^4) to 0.05 rad, listed in both orientations; one
  // stain-cut end 0.5 rad off; and another crossing's ends.
  const double truth = (90.0 - 20.0) * M_PI / 180.0;
  std::mt19937 rng(3);
  std::normal_distribution<double> near_noise(0.0, 0.01), far_noise(0.0, 0.05);
  std::vector<EndDirectionObservation> all;
  for (int k = 0; k < 8; ++k) {
    const double flip = k % 2 == 0 ? 0.0 : M_PI;
    all.push_back({0, AtAngle(truth + flip + near_noise(rng)), 1.0 / 4096});
    all.push_back({0, AtAngle(truth + flip + far_noise(rng)), 1.0 / 38416});
  }
  all.push_back({0, AtAngle(truth + 0.5), 1.0 / 4096});
  all.push_back({1, AtAngle(0.0), 1.0});
  Eigen::Vector2d direction;
  ASSERT_TRUE(CrossingEndDirection(all, 0, 4, &direction));
  EXPECT_NEAR(direction.norm(), 1.0, 1e-12);
  EXPECT_LT(AngleBetweenLines(direction, AtAngle(truth)), 0.006);
  ASSERT_TRUE(CrossingEndDirection(all, 1, 1, &direction));
  EXPECT_LT(AngleBetweenLines(direction, AtAngle(0.0)), 1e-12);
}

TEST(CrossingEndDirection, WrapsAroundPi) {
  // Ends within a few hundredths of the direction pi/2 ~ -pi/2: their mean
  // is pi/2, not 0.
  std::vector<EndDirectionObservation> all = {
      {0, AtAngle(M_PI / 2 - 0.01), 1.0},
      {0, AtAngle(-M_PI / 2 + 0.01), 1.0},
      {0, AtAngle(M_PI / 2 + 0.02), 1.0},
      {0, AtAngle(-M_PI / 2 - 0.02), 1.0}};
  Eigen::Vector2d direction;
  ASSERT_TRUE(CrossingEndDirection(all, 0, 4, &direction));
  EXPECT_LT(AngleBetweenLines(direction, AtAngle(M_PI / 2)), 0.02);
}

TEST(CrossingEndDirection, TooFewObservationsGiveNoDirection) {
  std::vector<EndDirectionObservation> all = {
      {0, AtAngle(0.3), 1.0}, {0, AtAngle(0.3), 1.0}, {1, AtAngle(0.3), 1.0}};
  Eigen::Vector2d direction;
  EXPECT_FALSE(CrossingEndDirection(all, 0, 3, &direction));
  EXPECT_FALSE(CrossingEndDirection(all, 2, 1, &direction));
  EXPECT_TRUE(CrossingEndDirection(all, 0, 2, &direction));
}

}  // namespace
}  // namespace zebrageo
