// Avenues of the simulated world (issue 52): a median whose refuge island
// splits every crossing of the road, in both database forms of
// SURVEY_FORMAT.md (two crossing_ids, the far half staggered; one crossing
// whose band numbers skip the island's places), the truth in the same form,
// the lines of the median and the lanes, and the vehicle changing lanes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "simulator/road.h"
#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/geodesy.h"

namespace zebrageo::sim {
namespace {

SimulationOptions AvenueOptions(uint64_t seed) {
  SimulationOptions options;
  options.seed = seed;
  EXPECT_EQ(ApplyPreset("avenue", &options), "");
  return options;
}

// Road offset of a horizontal position.
double RoadOffset(const Road& road, const Eigen::Vector3d& p, double s_guess) {
  double s = 0.0, l = 0.0;
  EXPECT_TRUE(road.ToRoadCoordinates(p.head<2>(), s_guess, &s, &l));
  return l;
}

using BandKeys = std::map<std::string, std::set<int>>;

BandKeys KeysOf(const RoadmarkDatabase& db) {
  BandKeys keys;
  for (const RoadmarkBand& b : db.bands) keys[b.crossing_id].insert(b.band);
  return keys;
}

TEST(Avenue, IslandSplitsEveryCrossingInBothDatabaseForms) {
  int one_id = 0, halves = 0, staggered = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    const SimulationOptions options = AvenueOptions(seed);
    ASSERT_EQ(options.Check(), "");
    const World world = BuildWorld(options);
    const double half_median = 0.5 * options.median_width_m;
    const LocalFrame frame(Geodetic{
        options.origin_lat_deg, options.origin_lon_deg, options.origin_h_m});
    const BandKeys truth = KeysOf(MakeTruthRoadmarks(world, frame));
    const BandKeys db = KeysOf(MakeDatabaseRoadmarks(world, options, frame));
    // No paint on the island: every painted corner beside it.
    for (const Band& band : world.bands) {
      const Crossing& c = world.crossings[band.crossing];
      for (const Eigen::Vector3d& q : band.corners) {
        EXPECT_GE(std::abs(RoadOffset(world.road, q, c.s_m)), half_median + 0.1)
            << c.id << " band " << band.band;
      }
    }
    std::map<std::string, const Crossing*> by_id;
    for (const Crossing& c : world.crossings) by_id[c.id] = &c;
    for (const Crossing& c : world.crossings) {
      ASSERT_FALSE(c.island_form.empty()) << c.id;
      if (c.island_form == "one_id") {
        ++one_id;
        ASSERT_FALSE(c.island_bands.empty());
        // The island's places are neither in the truth nor the database,
        // and bands on both sides of it are.
        for (int k : c.island_bands) {
          EXPECT_EQ(truth.count(c.id) ? truth.at(c.id).count(k) : 0u, 0u);
          EXPECT_EQ(db.count(c.id) ? db.at(c.id).count(k) : 0u, 0u);
        }
        if (c.in_street && truth.count(c.id)) {
          EXPECT_LT(*truth.at(c.id).begin(), c.island_bands.front());
          EXPECT_GT(*truth.at(c.id).rbegin(), c.island_bands.back());
        }
        continue;
      }
      ASSERT_TRUE(c.island_form == "near_half" || c.island_form == "far_half");
      ASSERT_TRUE(c.island_bands.empty());
      ASSERT_EQ(by_id.count(c.other_half), 1u) << c.id;
      const Crossing& other = *by_id.at(c.other_half);
      EXPECT_EQ(other.other_half, c.id);
      if (c.island_form == "far_half") continue;
      ++halves;
      // Numbered 1..n each; the island between them; the far half
      // staggered by at most max_stagger_m.
      if (c.in_street && truth.count(c.id) && truth.count(other.id)) {
        EXPECT_EQ(*truth.at(c.id).begin(), 1);
        EXPECT_EQ(*truth.at(other.id).begin(), 1);
      }
      const double near_end = c.first_offset_m +
                              (c.num_design_bands - 1) * c.band_period_m +
                              c.band_width_m;
      EXPECT_LE(near_end, -half_median);
      EXPECT_GE(other.first_offset_m, half_median);
      const double stagger = other.s_m - c.s_m;
      EXPECT_LE(std::abs(stagger), options.max_stagger_m + 1e-9);
      staggered += std::abs(stagger) > 0.5;
    }
  }
  EXPECT_GE(one_id, 5);
  EXPECT_GE(halves, 5);
  EXPECT_GE(staggered, 3);
}

TEST(Avenue, MedianLinesReplaceTheCentreLineAndLanesAreDashed) {
  const SimulationOptions options = AvenueOptions(3);
  const World world = BuildWorld(options);
  std::set<double> solid, dashed;
  for (const LinePiece& line : world.lines) {
    (line.type == "lane_solid" ? solid : dashed).insert(line.l_m);
  }
  const double half_median = 0.5 * options.median_width_m;
  EXPECT_EQ(solid.count(half_median), 1u);
  EXPECT_EQ(solid.count(-half_median), 1u);
  EXPECT_EQ(dashed.count(0.0), 0u);
  // Two lanes each way: one dashed line between them on each side.
  EXPECT_EQ(dashed.size(), 2u);
  for (const StopLine& stop : world.stop_lines) {
    EXPECT_LE(stop.l1, -half_median);
  }
}

TEST(Avenue, VehicleChangesLanesSmoothly) {
  const SimulationOptions options = AvenueOptions(5);
  const World world = BuildWorld(options);
  ASSERT_EQ(world.lane_changes.size(), 2u);
  const double lane = 0.5 * (options.road_width_m - options.median_width_m) /
                      options.lanes_per_direction;
  double lo = 1e9, hi = -1e9;
  for (double s = world.s_drive_start; s <= world.s_drive_end; s += 0.5) {
    const double l = LaneOffsetAt(world, s);
    lo = std::min(lo, l);
    hi = std::max(hi, l);
    // The slope is the derivative of the offset (the vehicle's yaw).
    const double numeric =
        (LaneOffsetAt(world, s + 0.01) - LaneOffsetAt(world, s - 0.01)) / 0.02;
    EXPECT_NEAR(LaneOffsetSlopeAt(world, s), numeric, 1e-3) << s;
    // Always in a lane of the right carriageway.
    EXPECT_LT(l, -0.5 * options.median_width_m);
    EXPECT_GT(l, -0.5 * options.road_width_m);
  }
  EXPECT_NEAR(hi - lo, lane, 1e-6);
  // The scenery keeps the kerb clear of the outermost lane driven.
  EXPECT_NEAR(world.lane_offset_m, lo, 1e-6);
}

TEST(Avenue, RandomPresetDrawsThemInAShareOfSurveysOnly) {
  int avenues = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    SimulationOptions drawn, none, every;
    RandomPresetLimits limits;
    limits.avenues = -1;
    ASSERT_EQ(DrawRandomOptions(seed, limits, &drawn), "") << seed;
    limits.avenues = 0;
    ASSERT_EQ(DrawRandomOptions(seed, limits, &none), "") << seed;
    limits.avenues = 1;
    ASSERT_EQ(DrawRandomOptions(seed, limits, &every), "") << seed;
    EXPECT_GE(every.road_width_m, 14.0);
    EXPECT_GT(every.median_width_m, 0.0);
    EXPECT_EQ(none.median_width_m, 0.0);
    EXPECT_EQ(none.lanes_per_direction, 1);
    if (drawn.median_width_m > 0.0) {
      ++avenues;
    } else {
      // Without an avenue the survey is the one drawn without them.
      EXPECT_EQ(drawn.road_width_m, none.road_width_m);
      EXPECT_EQ(drawn.num_crossings, none.num_crossings);
    }
  }
  EXPECT_GE(avenues, 20);
  EXPECT_LE(avenues, 60);
}

}  // namespace
}  // namespace zebrageo::sim
