#include "registration/roadmark_index.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "tests/registration/synthetic_scene.h"

namespace zebrageo {
namespace {

SyntheticScene OneCrossing(double skew_rad, std::vector<int> database_lacks) {
  SyntheticSceneOptions options;
  SyntheticCrossingSpec spec;
  spec.x_m = 10.0;
  spec.bands = 7;
  spec.band_length_m = 4.0;
  spec.skew_rad = skew_rad;
  spec.database_lacks = std::move(database_lacks);
  options.crossings = {spec};
  options.database_offset_m = 0.0;
  options.database_vertex_noise_m = 0.0;
  return MakeSyntheticScene(options);
}

TEST(RoadmarkIndex, GroupsBandsIntoCrossingsWithDirectionSpacingAndEnds) {
  const SyntheticScene scene = OneCrossing(0.0, {});
  const RoadmarkIndex index(scene.database, scene.frame);
  ASSERT_EQ(index.crossings().size(), 1u);
  const IndexedCrossing& c = index.crossings()[0];
  EXPECT_EQ(c.crossing_id, "C01");
  EXPECT_EQ(c.bands.size(), 7u);
  EXPECT_EQ(c.first_band, 1);
  EXPECT_EQ(c.last_band, 7);
  // Bands run east (along the road), numbers increase northwards.
  EXPECT_NEAR(std::abs(c.band_axis.x()), 1.0, 1e-6);
  EXPECT_NEAR(c.across_axis.y(), 1.0, 1e-6);
  EXPECT_NEAR(c.spacing_m, 1.0, 1e-6);
  EXPECT_NEAR(c.skew_rad, 0.0, 1e-6);
  EXPECT_NEAR(c.band_length_m, 4.0, 1e-6);
  EXPECT_NEAR(c.band_width_m, 0.5, 1e-6);
  EXPECT_NEAR(c.first_end_enu.y(), -3.5, 1e-6);
  EXPECT_NEAR(c.last_end_enu.y(), 2.5, 1e-6);
  EXPECT_TRUE(c.missing_band_numbers.empty());
  EXPECT_EQ(index.FindCrossing("C01"), 0);
  EXPECT_EQ(index.FindCrossing("nope"), -1);
}

TEST(RoadmarkIndex, MeasuresTheSkewOfASkewedCrossing) {
  const SyntheticScene scene = OneCrossing(0.3, {});
  const RoadmarkIndex index(scene.database, scene.frame);
  const IndexedCrossing& c = index.crossings()[0];
  EXPECT_NEAR(std::abs(c.skew_rad), 0.3, 1e-6);
  EXPECT_NEAR(c.spacing_m, 1.0, 1e-6);
}

TEST(RoadmarkIndex, ListsBandNumbersTheDatabaseLacks) {
  const SyntheticScene scene = OneCrossing(0.0, {3, 6});
  const RoadmarkIndex index(scene.database, scene.frame);
  const IndexedCrossing& c = index.crossings()[0];
  EXPECT_EQ(c.missing_band_numbers, (std::vector<int>{3, 6}));
  EXPECT_TRUE(c.island_band_numbers.empty());
  EXPECT_NEAR(c.spacing_m, 1.0, 1e-6);
}

// Two or more numbers in a row absent: a refuge island's places (issue 52),
// where no band is implied (a band seen there is no band the database
// lost).
TEST(RoadmarkIndex, ARunOfAbsentNumbersIsAnIslandWithNoImpliedBands) {
  const SyntheticScene scene = OneCrossing(0.0, {3, 4});
  const RoadmarkIndex index(scene.database, scene.frame);
  const IndexedCrossing& c = index.crossings()[0];
  EXPECT_TRUE(c.missing_band_numbers.empty());
  EXPECT_EQ(c.island_band_numbers, (std::vector<int>{3, 4}));
  for (int b : c.implied_bands) {
    EXPECT_NE(index.bands()[b].band, 3);
    EXPECT_NE(index.bands()[b].band, 4);
  }
  EXPECT_NEAR(c.spacing_m, 1.0, 1e-6);
}

TEST(RoadmarkIndex, FindsTheSameBandsAsABruteForceSearch) {
  SyntheticSceneOptions options;
  options.crossings = RandomCrossings(60, 25.0, 3);
  const SyntheticScene scene = MakeSyntheticScene(options);
  const RoadmarkIndex index(scene.database, scene.frame);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-20.0, 1500.0);
  std::uniform_real_distribution<double> y(-10.0, 10.0);
  std::vector<int> found;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector2d p(x(rng), y(rng));
    const double radius = 0.5 + (trial % 7);
    index.BandsWithin(p, radius, &found);
    std::sort(found.begin(), found.end());
    std::vector<int> expected;
    for (size_t b = 0; b < index.bands().size(); ++b) {
      Eigen::Vector2d low = Eigen::Vector2d::Constant(1e300);
      Eigen::Vector2d high = -low;
      for (const Eigen::Vector3d& corner : index.bands()[b].corners_enu) {
        low = low.cwiseMin(corner.head<2>());
        high = high.cwiseMax(corner.head<2>());
      }
      const Eigen::Vector2d nearest = p.cwiseMax(low).cwiseMin(high);
      if ((nearest - p).norm() <= radius)
        expected.push_back(static_cast<int>(b));
    }
    ASSERT_EQ(found, expected) << "trial " << trial;
  }
  const int nearest = index.NearestBand(Eigen::Vector2d(25.0, 0.0));
  ASSERT_GE(nearest, 0);
  EXPECT_EQ(index.bands()[nearest].crossing_id, "C02");
}

TEST(RoadmarkIndex, AnEmptyDatabaseAnswersNothing) {
  const RoadmarkIndex index(RoadmarkDatabase(), LocalFrame(Geodetic{}));
  std::vector<int> found = {1, 2};
  index.BandsWithin(Eigen::Vector2d::Zero(), 100.0, &found);
  EXPECT_TRUE(found.empty());
  EXPECT_EQ(index.NearestBand(Eigen::Vector2d::Zero()), -1);
  EXPECT_TRUE(index.crossings().empty());
}

TEST(BandShape, GivesLengthWidthAndAxisWhateverTheCornerOrder) {
  std::array<Eigen::Vector2d, 4> corners = {
      Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 0.5), Eigen::Vector2d(3, 0.5),
      Eigen::Vector2d(3, 0)};
  const BandShape shape = ShapeOfBand(corners);
  EXPECT_NEAR(shape.length_m, 3.0, 1e-12);
  EXPECT_NEAR(shape.width_m, 0.5, 1e-12);
  EXPECT_NEAR(std::abs(shape.axis.x()), 1.0, 1e-12);
  EXPECT_NEAR(shape.centre.x(), 1.5, 1e-12);
  EXPECT_NEAR(shape.centre.y(), 0.25, 1e-12);
}

}  // namespace
}  // namespace zebrageo
