// The paint beside the crossings and the trucks on them (issue 52,
// simulator/world_paint_beside.cc) against their spec: squares of the set
// size in rows beside the band ends or in a column one period beyond the
// last band, never over a band; teeth across the driving lane before the
// crossing; stop lines 1-5 m before its paint; a truck over the bands it
// lists, clear of the survey vehicle's lane; none of it in the truth or the
// database; and every knob at 0 leaves the street as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/geodesy.h"

namespace zebrageo::sim {
namespace {

SimulationOptions BesideOptions() {
  SimulationOptions options;
  options.seed = 11;
  options.road_length_m = 400.0;
  options.num_crossings = 8;
  options.max_bands_per_crossing = 6;
  options.bike_squares_probability = 1.0;
  options.two_square_rows_probability = 0.5;
  options.bike_lane_probability = 1.0;
  options.square_column_probability = 1.0;
  options.give_way_teeth_probability = 1.0;
  options.min_stop_line_distance_m = 1.0;
  options.max_stop_line_distance_m = 5.0;
  options.stop_line_probability = 1.0;
  options.truck_probability = 0.5;
  return options;
}

// The offset across and the position along crossing c of xy.
Eigen::Vector2d InCrossing(const Crossing& c, const Eigen::Vector2d& xy) {
  const Eigen::Vector2d rel = xy - c.origin_xy;
  const double o = rel.dot(c.n);
  return {rel.dot(c.t) - o * c.tan_skew, o};
}

TEST(PaintBesideWorld, SquaresLanesTeethAndStopLinesWhereTheSpecPutsThem) {
  const SimulationOptions options = BesideOptions();
  ASSERT_EQ(options.Check(), "");
  const World world = BuildWorld(options);
  int squares = 0, lanes = 0, teeth = 0;
  for (const BesideMark& mark : world.beside_marks) {
    const Crossing& c = world.crossings[mark.crossing];
    ASSERT_TRUE(c.in_street);
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : mark.polygon) centre += p;
    centre /= static_cast<double>(mark.polygon.size());
    EXPECT_TRUE(mark.Contains(centre)) << mark.kind;
    // Never on a band of its crossing.
    for (const Band& band : world.bands) {
      if (band.crossing != mark.crossing) continue;
      for (const Eigen::Vector2d& p : mark.polygon) {
        const Eigen::Vector2d ao = InCrossing(c, p);
        const bool inside = ao.y() > band.o0 + 0.01 &&
                            ao.y() < band.o1 - 0.01 &&
                            std::abs(ao.x()) < 0.5 * c.band_length_m - 0.01;
        EXPECT_FALSE(inside)
            << mark.kind << " over band " << band.band << " of " << c.id;
      }
    }
    if (mark.kind == "square") {
      ++squares;
      EXPECT_TRUE(mark.white);
      const double side = (mark.polygon[1] - mark.polygon[0]).norm();
      EXPECT_LT(side, options.square_size_m / std::cos(0.5) + 1e-6);
    } else if (mark.kind == "bike_lane") {
      ++lanes;
      EXPECT_FALSE(mark.white);
      EXPECT_GT(mark.tone, 82.0f);   // lighter than asphalt
      EXPECT_LT(mark.tone, 150.0f);  // far darker than paint
    } else {
      ASSERT_EQ(mark.kind, "tooth");
      ++teeth;
      // Before the crossing, across the driving lane (the right half).
      double s = 0.0, l = 0.0;
      world.road.ToRoadCoordinates(centre, c.s_m, &s, &l);
      EXPECT_LT(s, c.s_min);
      EXPECT_LT(l, 0.0);
    }
  }
  EXPECT_GT(squares, 50);
  EXPECT_GT(lanes, 0);
  EXPECT_GT(teeth, 0);
  for (const StopLine& line : world.stop_lines) {
    const Crossing& c = world.crossings[line.crossing];
    const double distance =
        c.s_min - c.beside_before_m - (line.s_m + 0.5 * line.width_m);
    EXPECT_GE(distance, 1.0 - 1e-6);
    EXPECT_LE(distance, 5.0 + 1e-6);
  }
}

TEST(PaintBesideWorld, ATruckStandsOverTheBandsItListsClearOfTheDrivenLane) {
  const SimulationOptions options = BesideOptions();
  const World world = BuildWorld(options);
  int trucks = 0;
  for (const ParkedVehicle& v : world.vehicles) {
    if (!v.truck) continue;
    ++trucks;
    double s = 0.0, l = 0.0;
    world.road.ToRoadCoordinates(v.box.centre, 0.5 * (v.s0 + v.s1), &s, &l);
    // Its right side left of the survey vehicle's lane (1.8 m wide there).
    EXPECT_GT(l - v.box.half_v, world.lane_offset_m + 0.9);
    EXPECT_GT(v.box.z1 - v.box.z0, 3.0);
  }
  EXPECT_GT(trucks, 0);
  for (const Crossing& c : world.crossings) {
    if (!c.truck) continue;
    EXPECT_FALSE(c.truck_bands.empty()) << c.id;
    for (int k : c.truck_bands) {
      const Band* band = nullptr;
      for (const Band& b : world.bands) {
        if (&world.crossings[b.crossing] == &c && b.band == k) band = &b;
      }
      ASSERT_NE(band, nullptr);
      // The band's middle lies under a truck.
      Eigen::Vector3d mid = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& q : band->corners) mid += 0.25 * q;
      bool under = false;
      for (const ParkedVehicle& v : world.vehicles) {
        if (!v.truck) continue;
        const Eigen::Vector2d rel = mid.head<2>() - v.box.centre;
        under |= std::abs(rel.dot(v.box.axis_u)) < v.box.half_u &&
                 std::abs(rel.dot(v.box.axis_v())) < v.box.half_v;
      }
      EXPECT_TRUE(under) << c.id << " band " << k;
    }
  }
}

// Not bands: the truth and the database hold the same bands with and
// without the paint beside (and the trucks).
TEST(PaintBesideWorld, ThePaintBesideIsNoBandOfTheTruthOrTheDatabase) {
  SimulationOptions plain = BesideOptions();
  plain.bike_squares_probability = 0.0;
  plain.square_column_probability = 0.0;
  plain.give_way_teeth_probability = 0.0;
  plain.truck_probability = 0.0;
  const World with = BuildWorld(BesideOptions());
  const World without = BuildWorld(plain);
  ASSERT_EQ(with.bands.size(), without.bands.size());
  const LocalFrame frame(Geodetic{49.9, 2.3, 60.0});
  const RoadmarkDatabase a = MakeTruthRoadmarks(with, frame);
  const RoadmarkDatabase b = MakeTruthRoadmarks(without, frame);
  ASSERT_EQ(a.bands.size(), b.bands.size());
  for (size_t i = 0; i < a.bands.size(); ++i) {
    EXPECT_EQ(a.bands[i].crossing_id, b.bands[i].crossing_id);
    EXPECT_EQ(a.bands[i].band, b.bands[i].band);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(a.bands[i].corners[k].lat_deg, b.bands[i].corners[k].lat_deg);
    }
  }
  EXPECT_TRUE(without.beside_marks.empty());
}

// Every knob at its default: the street of before (the same crossings,
// vehicles, stop lines 2 m before the crossing).
TEST(PaintBesideWorld, DefaultsLeaveTheStreetAsItWas) {
  SimulationOptions options;
  options.seed = 5;
  options.stop_line_probability = 1.0;
  const World world = BuildWorld(options);
  EXPECT_TRUE(world.beside_marks.empty());
  for (const ParkedVehicle& v : world.vehicles) EXPECT_FALSE(v.truck);
  for (const StopLine& line : world.stop_lines) {
    const Crossing& c = world.crossings[line.crossing];
    EXPECT_NEAR(c.s_min - (line.s_m + 0.5 * line.width_m), 2.0, 1e-9);
  }
}

}  // namespace
}  // namespace zebrageo::sim
