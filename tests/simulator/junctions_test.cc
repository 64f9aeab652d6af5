// Junctions of the simulated world (issue 51): side streets within the
// spec, crossings across them whose bands' long sides lie across the
// track, set back from the kerb line, level with the side street; the
// database holds them; the street without junctions is unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "simulator/road.h"
#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

SimulationOptions JunctionOptions(uint64_t seed) {
  SimulationOptions options;
  options.seed = seed;
  options.road_length_m = 500.0;
  options.num_crossings = 4;
  options.num_stale_crossings = 0;
  options.num_junctions = 3;
  options.four_way_probability = 0.5;
  options.side_crossing_vehicle_probability = 0.5;
  return options;
}

TEST(Junctions, SideStreetsAndTheirCrossingsAreWithinTheSpec) {
  int side_crossings = 0, four_way = 0, vehicles = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const SimulationOptions options = JunctionOptions(seed);
    ASSERT_EQ(options.Check(), "");
    const World world = BuildWorld(options);
    const Road& road = world.road;
    const double half = 0.5 * road.width_m();
    std::set<int> junctions;
    std::map<int, int> arms;
    for (const SideStreet& street : world.side_streets) {
      EXPECT_GE(street.width_m, 6.0);
      EXPECT_LE(street.width_m, 12.0);
      EXPECT_LE(std::abs(RadToDeg(street.angle_rad)), 30.0 + 1e-9);
      EXPECT_GT(street.s_m, world.s_drive_start);
      EXPECT_LT(street.s_m, world.s_drive_end);
      ++arms[street.junction];
    }
    for (const auto& [j, n] : arms) four_way += n == 2;
    EXPECT_GE(arms.size(), 1u) << seed;
    for (const Crossing& c : world.crossings) {
      if (c.side_street < 0) continue;
      ++side_crossings;
      vehicles += c.occluded_by_vehicle;
      const SideStreet& street = world.side_streets[c.side_street];
      // Long sides along the side street: at 60-90 degrees to the road.
      const double cos_road = std::abs(c.t.dot(road.Tangent(street.s_m)));
      EXPECT_LT(cos_road, std::sin(DegToRad(30.0)) + 1e-9) << c.id;
      int painted = 0;
      for (const Band& band : world.bands) {
        if (&world.crossings[band.crossing] != &c) continue;
        ++painted;
        for (const Eigen::Vector3d& p : band.corners) {
          double s = 0.0, l = 0.0;
          ASSERT_TRUE(road.ToRoadCoordinates(p.head<2>(), c.s_m, &s, &l));
          // Beyond the road's kerb line, on its side, inside the street.
          EXPECT_GT(street.side * l, half) << c.id;
          EXPECT_EQ(SideStreetAt(world, p.head<2>(), l), c.side_street);
          // On the ground the renderer draws.
          EXPECT_NEAR(p.z(), GroundHeight(world, p.head<2>(), s, l), 1e-9);
          // Within 1-10 m of setback plus the band length and the skew's
          // lean: no farther than 17 m from the road's kerb line.
          EXPECT_LT(street.side * l - half, 17.0 + 6.0) << c.id;
        }
        // Planar (the renderer paints the quad through its corners).
        const auto& q = band.corners;
        const Eigen::Vector3d n = (q[2] - q[0]).cross(q[3] - q[1]).normalized();
        EXPECT_LT(std::abs(n.dot(q[1] - q[0])), 5e-4);  // the grade twists it
      }
      EXPECT_EQ(painted, c.num_street_bands);
      EXPECT_GE(c.num_street_bands, 1);
    }
  }
  EXPECT_GE(side_crossings, 40);
  EXPECT_GE(four_way, 5);
  EXPECT_GE(vehicles, 5);
}

TEST(Junctions, NoJunctionLeavesTheStreetAsItWas) {
  SimulationOptions with = JunctionOptions(5);
  SimulationOptions without = with;
  without.num_junctions = 0;
  const World a = BuildWorld(with);
  const World b = BuildWorld(without);
  ASSERT_TRUE(b.side_streets.empty());
  // The road's crossings are the same, band for band.
  int road_bands = 0;
  for (const Band& band : a.bands) {
    if (a.crossings[band.crossing].side_street >= 0) continue;
    ASSERT_LT(road_bands, static_cast<int>(b.bands.size()));
    const Band& other = b.bands[road_bands++];
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(band.corners[k], other.corners[k]);
    }
  }
  EXPECT_EQ(road_bands, static_cast<int>(b.bands.size()));
}

TEST(Junctions, EdgeLinesStopAtTheMouthsAndNothingParksAcrossThem) {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const World world = BuildWorld(JunctionOptions(seed));
    for (const SideStreet& street : world.side_streets) {
      const double l = street.side * (0.5 * world.road.width_m() - 0.3);
      for (const LinePiece& line : world.lines) {
        if (std::abs(line.l_m - l) > 1e-6) continue;
        EXPECT_TRUE(line.s1 <= street.mouth_s0 || line.s0 >= street.mouth_s1)
            << "seed " << seed;
      }
      for (const ParkedVehicle& v : world.vehicles) {
        // Those at the road's kerbs (not the ones in the side streets).
        double sc = 0.0, lc = 0.0;
        world.road.ToRoadCoordinates(v.box.centre, 0.5 * (v.s0 + v.s1), &sc,
                                     &lc);
        if (std::abs(lc) > 0.5 * world.road.width_m() + 1.5) continue;
        for (const Eigen::Vector2d& p : v.box.Footprint()) {
          double s = 0.0, l2 = 0.0;
          world.road.ToRoadCoordinates(p, 0.5 * (v.s0 + v.s1), &s, &l2);
          const bool at_road_kerb =
              std::abs(std::abs(l2) - 0.5 * world.road.width_m()) < 0.5;
          EXPECT_FALSE(at_road_kerb && l2 * street.side > 0 &&
                       s > street.mouth_s0 && s < street.mouth_s1)
              << "seed " << seed;
        }
      }
    }
  }
}

TEST(Junctions, RandomPresetDrawsThemInHalfTheSurveysOnly) {
  int with = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    SimulationOptions o;
    ASSERT_EQ(DrawRandomOptions(seed, RandomPresetLimits(), &o), "");
    with += o.num_junctions > 0;
    RandomPresetLimits none;
    none.junctions = 0;
    SimulationOptions p;
    ASSERT_EQ(DrawRandomOptions(seed, none, &p), "");
    EXPECT_EQ(p.num_junctions, 0);
    // The other draws do not depend on the junctions.
    EXPECT_EQ(o.road_length_m, p.road_length_m);
    EXPECT_EQ(o.num_crossings, p.num_crossings);
    EXPECT_EQ(o.drift_along_track_m, p.drift_along_track_m);
    if (o.num_junctions == 0) {
      EXPECT_EQ(o.four_way_probability, p.four_way_probability);
      EXPECT_EQ(o.focal_px, p.focal_px);
      EXPECT_EQ(o.k1, p.k1);
    }
  }
  EXPECT_GT(with, 15);
  EXPECT_LT(with, 45);
}

// With junctions the rig is wide-angle (70-100 degrees across), its
// distortion the same function of the pixel radius as the one drawn, and
// the options valid.
TEST(Junctions, RandomPresetWithJunctionsGivenHasAWideAngleRig) {
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    RandomPresetLimits two;
    two.junctions = 2;
    SimulationOptions o;
    ASSERT_EQ(DrawRandomOptions(seed, two, &o), "");
    ASSERT_EQ(o.Check(), "") << seed;
    RandomPresetLimits none;
    none.junctions = 0;
    SimulationOptions p;
    ASSERT_EQ(DrawRandomOptions(seed, none, &p), "");
    const double fov_deg =
        RadToDeg(2.0 * std::atan(0.5 * o.image_width / o.focal_px));
    EXPECT_GE(fov_deg, 70.0 - 1e-9) << seed;
    EXPECT_LE(fov_deg, 100.0 + 1e-9) << seed;
    // The distortion at a pixel radius (here the image's half width).
    const auto factor = [](const SimulationOptions& x, double r_px) {
      const double r2 = (r_px / x.focal_px) * (r_px / x.focal_px);
      return 1.0 + r2 * (x.k1 + r2 * (x.k2 + r2 * x.k3));
    };
    EXPECT_NEAR(factor(o, 0.5 * o.image_width), factor(p, 0.5 * p.image_width),
                1e-12)
        << seed;
  }
}

}  // namespace
}  // namespace zebrageo::sim
