// The simulated world against the spec: road cross-section, band sizes,
// planarity and ring order, database faults and offsets.
#include "simulator/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "simulator/road.h"
#include "simulator/simulator.h"

namespace zebrageo::sim {
namespace {

SimulationOptions WorldOptions() {
  SimulationOptions options;
  options.seed = 7;
  options.road_length_m = 600.0;
  options.num_crossings = 10;
  options.num_stale_crossings = 2;
  options.num_missing_crossings = 2;
  options.num_missing_bands = 2;
  options.num_repainted_crossings = 1;
  options.skew_probability = 0.5;
  options.curved_share = 0.6;
  return options;
}

// Long sides: the two sides of the quad with the largest length.
struct BandSides {
  Eigen::Vector2d a0, a1, b0, b1;  // long side a: a0->a1, long side b
};

BandSides LongSides(const Band& band) {
  const auto& c = band.corners;
  const double len01 = (c[1] - c[0]).head<2>().norm();
  const double len12 = (c[2] - c[1]).head<2>().norm();
  const int s = len01 > len12 ? 0 : 1;
  return {c[s].head<2>(), c[s + 1].head<2>(), c[(s + 2) % 4].head<2>(),
          c[(s + 3) % 4].head<2>()};
}

double DistanceToLine(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                      const Eigen::Vector2d& b) {
  const Eigen::Vector2d t = (b - a).normalized();
  const Eigen::Vector2d d = p - a;
  return std::abs(t.x() * d.y() - t.y() * d.x());
}

TEST(Road, CrossfallIsTwoPercentDownFromTheCrownToBothEdges) {
  SimulationOptions options;
  const World world = BuildWorld(options);
  const Road& road = world.road;
  for (double l : {1.0, 2.0, 3.5}) {
    EXPECT_NEAR(road.CrossSectionSlope(l), -0.02, 0.002) << l;
    EXPECT_NEAR(road.CrossSectionSlope(-l), 0.02, 0.002) << l;
  }
  // Over a metre, measured on the surface itself.
  for (double s : {50.0, 200.0}) {
    const double drop = road.Height(s, 2.0) - road.Height(s, 3.0);
    EXPECT_NEAR(drop, 0.02, 0.0002);
  }
  // The crown is the highest point and is rounded (no kink).
  EXPECT_GT(road.CrossSection(0.0), road.CrossSection(0.05));
  EXPECT_NEAR(road.CrossSectionSlope(1e-4), 0.0, 1e-4);
  EXPECT_NEAR(road.CrossSection(0.0), 0.0, 1e-12);
}

TEST(Road, RoadCoordinatesRoundTripOnCurves) {
  RoadSpec spec;
  spec.length_m = 800.0;
  spec.curved_share = 1.0;
  spec.min_curve_radius_m = 80.0;
  spec.max_curve_radius_m = 150.0;
  const Road road = Road::Generate(spec, 3);
  for (double s = 5.0; s < 790.0; s += 37.3) {
    for (double l : {-12.0, -3.0, 0.0, 4.5, 14.0}) {
      const Eigen::Vector3d p = road.SurfacePoint(s, l);
      double s2 = 0.0, l2 = 0.0;
      ASSERT_TRUE(road.ToRoadCoordinates(p.head<2>(), s + 7.0, &s2, &l2));
      EXPECT_NEAR(s2, s, 1e-7);
      EXPECT_NEAR(l2, l, 1e-7);
      EXPECT_NEAR(road.SurfaceHeightAt(p.head<2>(), s), p.z(), 1e-9);
    }
  }
}

TEST(Road, CentrelineIsContinuousWithSmoothHeading) {
  RoadSpec spec;
  spec.length_m = 1000.0;
  spec.curved_share = 0.7;
  const Road road = Road::Generate(spec, 11);
  for (double s = 0.0; s + 0.01 < road.length_m(); s += 0.37) {
    const double step = (road.Centre(s + 0.01) - road.Centre(s)).norm();
    EXPECT_NEAR(step, 0.01, 1e-6) << s;
    const double turn = road.Heading(s + 0.01) - road.Heading(s);
    EXPECT_LT(std::abs(turn), 0.01 / 60.0) << s;  // radius >= 60 m
  }
}

TEST(World, BandsAreHalfMetreWideHalfMetreApartAndOfSpecifiedLength) {
  const SimulationOptions options = WorldOptions();
  const World world = BuildWorld(options);
  ASSERT_FALSE(world.bands.empty());
  std::map<int, std::vector<const Band*>> by_crossing;
  for (const Band& band : world.bands) {
    by_crossing[band.crossing].push_back(&band);
    const BandSides sides = LongSides(band);
    // Width: distance between the long sides (perpendicular).
    EXPECT_NEAR(DistanceToLine(sides.b0, sides.a0, sides.a1), 0.5, 1e-3);
    EXPECT_NEAR(DistanceToLine(sides.b1, sides.a0, sides.a1), 0.5, 1e-3);
    const double length = (sides.a1 - sides.a0).norm();
    EXPECT_GE(length, options.min_band_length_m - 1e-3);
    EXPECT_LE(length, options.max_band_length_m + 1e-3);
    // Long sides run along the road.
    const Crossing& c = world.crossings[band.crossing];
    const Eigen::Vector2d along = (sides.a1 - sides.a0).normalized();
    EXPECT_NEAR(std::abs(along.dot(c.t)), 1.0, 1e-9);
  }
  for (const auto& [crossing, bands] : by_crossing) {
    const Crossing& c = world.crossings[crossing];
    ASSERT_EQ(static_cast<int>(bands.size()), c.num_street_bands);
    for (size_t k = 0; k < bands.size(); ++k) {
      EXPECT_EQ(bands[k]->band,
                static_cast<int>(k) + 1);  // 1-based, consecutive
      if (k == 0) continue;
      // Gap: from the nearest long side of band k-1 to band k.
      const BandSides prev = LongSides(*bands[k - 1]);
      const BandSides next = LongSides(*bands[k]);
      const double d1 = DistanceToLine(next.a0, prev.a0, prev.a1);
      const double d2 = DistanceToLine(next.a0, prev.b0, prev.b1);
      const double d3 = DistanceToLine(next.b0, prev.a0, prev.a1);
      const double d4 = DistanceToLine(next.b0, prev.b0, prev.b1);
      EXPECT_NEAR(std::min({d1, d2, d3, d4}), 0.5, 1e-3);
    }
  }
}

TEST(World, BandCornersLieOnTheRoadAndArePlanarToAMillimetre) {
  const World world = BuildWorld(WorldOptions());
  for (const Band& band : world.bands) {
    const Crossing& c = world.crossings[band.crossing];
    for (const Eigen::Vector3d& corner : band.corners) {
      EXPECT_NEAR(world.road.SurfaceHeightAt(corner.head<2>(), c.s_m),
                  corner.z(), 1e-6);
      // The painted plane passes through the corners.
      EXPECT_NEAR(band.plane_normal.dot(corner) - band.plane_offset, 0.0, 1e-3);
    }
    // Counter-clockwise seen from above (positive signed area).
    double area = 0.0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& a = band.corners[k];
      const Eigen::Vector3d& b = band.corners[(k + 1) % 4];
      area += a.x() * b.y() - b.x() * a.y();
    }
    EXPECT_GT(area, 0.0);
    // Along the camber: the plane's cross slope is ~2 % (unless the band
    // straddles the crown).
    EXPECT_LT(std::abs(band.plane_normal.head<2>().norm()), 0.05);
  }
}

TEST(World, SkewedCrossingsHaveParallelogramBands) {
  const World world = BuildWorld(WorldOptions());
  int skewed = 0;
  for (const Band& band : world.bands) {
    const Crossing& c = world.crossings[band.crossing];
    if (c.skew_deg == 0.0) continue;
    ++skewed;
    const BandSides sides = LongSides(band);
    // A short side joins a0 to the nearer of b0, b1.
    const Eigen::Vector2d b =
        (sides.b0 - sides.a0).norm() < (sides.b1 - sides.a0).norm() ? sides.b0
                                                                    : sides.b1;
    const Eigen::Vector2d shorter = (b - sides.a0).normalized();
    const Eigen::Vector2d along = (sides.a1 - sides.a0).normalized();
    const double angle = std::acos(std::abs(shorter.dot(along))) * 180.0 / M_PI;
    EXPECT_NEAR(90.0 - angle, std::abs(c.skew_deg), 1e-6);
  }
  EXPECT_GT(skewed, 0);
}

TEST(World, FaultsAreWhereTheOptionsPutThem) {
  const SimulationOptions options = WorldOptions();
  const World world = BuildWorld(options);
  int stale = 0, missing = 0, repainted = 0, missing_band = 0;
  std::set<std::string> ids;
  for (const Crossing& c : world.crossings) {
    EXPECT_TRUE(ids.insert(c.id).second) << "duplicate id " << c.id;
    stale += !c.in_street;
    missing += !c.in_db;
    repainted += c.repainted;
    missing_band += !c.missing_band_kind.empty();
    const double offset = c.db_offset_enu.head<2>().norm();
    EXPECT_GE(offset, options.database_min_offset_m - 1e-12);
    EXPECT_LE(offset, options.database_max_offset_m + 1e-12);
    if (c.repainted) {
      EXPECT_GE(c.repaint_shift_xy.norm(), 0.5 * options.repaint_shift_m);
    }
    if (c.missing_band_kind == "worn_in_street") {
      EXPECT_EQ(c.num_street_bands + 1, c.num_db_bands);
    } else if (c.missing_band_kind == "missing_in_db") {
      EXPECT_EQ(c.num_street_bands, c.num_db_bands + 1);
    } else {
      EXPECT_EQ(c.num_street_bands, c.num_db_bands);
    }
  }
  EXPECT_EQ(stale, options.num_stale_crossings);
  EXPECT_EQ(missing, options.num_missing_crossings);
  EXPECT_EQ(repainted, options.num_repainted_crossings);
  EXPECT_EQ(missing_band, options.num_missing_bands);
  EXPECT_EQ(static_cast<int>(world.crossings.size()),
            options.num_crossings + options.num_stale_crossings);
}

TEST(World, DatabaseIsTruthPlusOffsetAndNoise) {
  SimulationOptions options = WorldOptions();
  options.database_sigma_xy_m = 0.0;
  options.database_sigma_z_m = 0.0;
  const World world = BuildWorld(options);
  const LocalFrame frame(Geodetic{options.origin_lat_deg,
                                  options.origin_lon_deg, options.origin_h_m});
  const RoadmarkDatabase truth = MakeTruthRoadmarks(world, frame);
  const RoadmarkDatabase db = MakeDatabaseRoadmarks(world, options, frame);
  std::map<std::pair<std::string, int>, const RoadmarkBand*> truth_bands;
  for (const RoadmarkBand& b : truth.bands) {
    truth_bands[{b.crossing_id, b.band}] = &b;
  }
  std::map<std::string, const Crossing*> crossings;
  for (const Crossing& c : world.crossings) crossings[c.id] = &c;
  int compared = 0;
  for (const RoadmarkBand& b : db.bands) {
    const Crossing& c = *crossings.at(b.crossing_id);
    EXPECT_TRUE(c.in_db);
    const auto it = truth_bands.find({b.crossing_id, b.band});
    if (it == truth_bands.end() || c.repainted) continue;
    for (int v = 0; v < 4; ++v) {
      const Eigen::Vector3d d = frame.EnuFromGeodetic(b.corners[v]) -
                                frame.EnuFromGeodetic(it->second->corners[v]);
      EXPECT_LT((d - c.db_offset_enu).norm(), 1e-6);
    }
    ++compared;
  }
  EXPECT_GT(compared, 20);
  // No truth band of a crossing that is not in the street.
  for (const RoadmarkBand& b : truth.bands) {
    EXPECT_TRUE(crossings.at(b.crossing_id)->in_street);
  }
  // Lines are there, typed.
  std::set<std::string> types;
  for (const RoadmarkLine& line : truth.lines) types.insert(line.type);
  EXPECT_TRUE(types.count("lane_solid"));
  EXPECT_TRUE(types.count("lane_dashed"));
}

// Road coordinates (s, l) of a point near the road (guess from the
// nearest centreline sample).
Eigen::Vector2d RoadCoordinatesOf(const Road& road, const Eigen::Vector3d& p) {
  double best_s = 0.0, best = 1e18;
  for (double s = 0.0; s <= road.length_m(); s += 2.0) {
    const double d = (road.SurfacePoint(s, 0.0) - p).head<2>().squaredNorm();
    if (d < best) best = d, best_s = s;
  }
  double s = 0.0, l = 0.0;
  EXPECT_TRUE(road.ToRoadCoordinates(p.head<2>(), best_s, &s, &l));
  return {s, l};
}

TEST(World, DatabaseLinesHaveGapsMovedStretchesAndRemovedStopLines) {
  SimulationOptions options = WorldOptions();
  options.database_sigma_xy_m = 0.0;
  options.database_sigma_z_m = 0.0;
  options.stop_line_probability = 0.3;
  options.database_line_gap_share = 0.15;
  options.num_moved_lines = 2;
  options.num_removed_stop_lines = 1;
  const World world = BuildWorld(options);
  const LocalFrame frame(Geodetic{options.origin_lat_deg,
                                  options.origin_lon_deg, options.origin_h_m});
  const RoadmarkDatabase db = MakeDatabaseRoadmarks(world, options, frame);
  std::map<std::string, int> kinds;
  for (const DatabaseLineFault& f : world.database_line_faults) ++kinds[f.kind];
  EXPECT_GE(kinds["gap"], 3);  // every lane line has gaps
  EXPECT_EQ(kinds["moved"], 2);
  EXPECT_EQ(kinds["removed"], 1);
  // Where the database says a lane line is, by road coordinates.
  int inside_gap = 0, on_moved = 0, on_street = 0;
  for (const RoadmarkLine& line : db.lines) {
    if (line.type == "stop_line") continue;
    for (const Geodetic& g : line.points) {
      const Eigen::Vector2d sl =
          RoadCoordinatesOf(world.road, frame.EnuFromGeodetic(g));
      const DatabaseLineFault* moved = nullptr;
      bool in_gap = false;
      for (const DatabaseLineFault& f : world.database_line_faults) {
        // Fault intervals of this line position, away from their ends.
        const bool here = sl.x() > f.s0 + 0.01 && sl.x() < f.s1 - 0.01;
        if (f.kind == "gap" && here && std::abs(sl.y() - f.l_m) < 0.01) {
          in_gap = true;
        }
        const bool near = sl.x() > f.s0 - 0.01 && sl.x() < f.s1 + 0.01;
        if (f.kind == "moved" && near &&
            std::abs(sl.y() - f.l_m - f.shift_m) < 0.01) {
          moved = &f;
        }
      }
      inside_gap += in_gap ? 1 : 0;
      if (moved != nullptr) {
        ++on_moved;
        EXPECT_GE(std::abs(moved->shift_m), 0.25);
        EXPECT_LE(std::abs(moved->shift_m), 0.45);
      } else {
        // Anywhere else the database line is where the street has it.
        bool on_a_street_line = false;
        for (const LinePiece& piece : world.lines) {
          on_a_street_line |= std::abs(sl.y() - piece.l_m) < 0.01 &&
                              sl.x() > piece.s0 - 0.01 &&
                              sl.x() < piece.s1 + 0.01;
        }
        EXPECT_TRUE(on_a_street_line) << "s " << sl.x() << " l " << sl.y();
        ++on_street;
      }
    }
  }
  EXPECT_EQ(inside_gap, 0);
  EXPECT_GT(on_moved, 10);
  EXPECT_GT(on_street, 100);
  // The removed stop line is in the database, at a crossing that has none.
  for (const DatabaseLineFault& f : world.database_line_faults) {
    if (f.kind != "removed") continue;
    const Crossing& c = world.crossings[f.crossing];
    EXPECT_FALSE(c.stop_line);
    int found = 0;
    for (const RoadmarkLine& line : db.lines) {
      found += line.type == "stop_line" && line.id == "stop-" + c.id;
    }
    EXPECT_EQ(found, 1);
  }
}

}  // namespace
}  // namespace zebrageo::sim

namespace zebrageo::sim {
namespace {

TEST(World, DatabaseLackingEndAndInteriorBandsKeepsTheStreetsNumbering) {
  SimulationOptions options;
  options.seed = 11;
  options.road_length_m = 400.0;
  options.num_crossings = 6;
  options.num_stale_crossings = 0;
  options.min_bands_per_crossing = 5;
  options.num_missing_end_bands = 2;
  options.num_missing_interior_bands = 2;
  const World world = BuildWorld(options);
  const LocalFrame frame(Geodetic{options.origin_lat_deg,
                                  options.origin_lon_deg, options.origin_h_m});
  const RoadmarkDatabase database =
      MakeDatabaseRoadmarks(world, options, frame);
  const RoadmarkDatabase truth = MakeTruthRoadmarks(world, frame);
  std::map<std::string, std::set<int>> db_bands, street_bands;
  for (const RoadmarkBand& b : database.bands) {
    db_bands[b.crossing_id].insert(b.band);
  }
  for (const RoadmarkBand& b : truth.bands) {
    street_bands[b.crossing_id].insert(b.band);
  }
  int end = 0, interior = 0;
  for (const Crossing& c : world.crossings) {
    const std::set<int>& street = street_bands[c.id];
    ASSERT_EQ(static_cast<int>(street.size()), c.num_street_bands);
    EXPECT_EQ(*street.begin(), 1);
    if (c.db_missing_bands.empty()) {
      EXPECT_EQ(db_bands[c.id], street) << c.id;
      continue;
    }
    ASSERT_EQ(c.db_missing_bands.size(), 1u);
    const int gap = c.db_missing_bands[0];
    std::set<int> expected = street;
    expected.erase(gap);
    EXPECT_EQ(db_bands[c.id], expected) << c.id;
    if (c.missing_band_kind == "end_missing_in_db") {
      ++end;
      EXPECT_TRUE(gap == 1 || gap == c.num_street_bands) << gap;
    } else {
      ++interior;
      EXPECT_EQ(c.missing_band_kind, "interior_missing_in_db");
      EXPECT_GT(gap, 1);
      EXPECT_LT(gap, c.num_street_bands);
    }
  }
  EXPECT_EQ(end, 2);
  EXPECT_EQ(interior, 2);
}

TEST(World, VehiclesParkOverEndBandsAtTheKerbOutOfTheDrivingLane) {
  SimulationOptions options;
  options.seed = 12;
  options.road_length_m = 600.0;
  options.road_width_m = 12.0;
  options.num_crossings = 10;
  options.occluding_vehicle_probability = 0.0;
  options.parked_vehicles_per_100m = 0.0;
  options.end_band_vehicle_probability = 1.0;
  const World world = BuildWorld(options);
  int covered = 0;
  for (const Crossing& c : world.crossings) {
    if (c.end_band_vehicle.empty()) continue;
    const int band = c.end_band_vehicle == "first" ? 1 : c.num_street_bands;
    const Band* end_band = nullptr;
    for (const Band& b : world.bands) {
      if (world.crossings[b.crossing].id == c.id && b.band == band) {
        end_band = &b;
      }
    }
    ASSERT_NE(end_band, nullptr);
    const Eigen::Vector2d centre =
        0.25 * (end_band->corners[0] + end_band->corners[1] +
                end_band->corners[2] + end_band->corners[3])
                   .head<2>();
    bool under = false;
    for (const ParkedVehicle& v : world.vehicles) {
      const Eigen::Vector2d d = centre - v.box.centre;
      under |= std::abs(d.dot(v.box.axis_u)) < v.box.half_u &&
               std::abs(d.dot(v.box.axis_v())) < v.box.half_v;
      // Never where the survey vehicle drives.
      double s = 0.0, l = 0.0;
      ASSERT_TRUE(world.road.ToRoadCoordinates(v.box.centre, c.s_m, &s, &l));
      EXPECT_GT(std::abs(l - world.lane_offset_m), v.box.half_v + 1.7);
    }
    EXPECT_TRUE(under) << c.id << " band " << band;
    ++covered;
  }
  EXPECT_GE(covered, 5);
}

}  // namespace
}  // namespace zebrageo::sim
