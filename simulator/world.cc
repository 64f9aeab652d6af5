#include "simulator/world.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <random>

#include "simulator/noise.h"
#include "simulator/world_internal.h"
#include "survey/math_util.h"

namespace zebrageo::sim {

using world_internal::BuildFacades;
using world_internal::CastShadows;
using world_internal::CrossingDesignDraw;
using world_internal::DrawBandRow;
using world_internal::DrawCrossingDesign;
using world_internal::kBandKerbMarginM;
using world_internal::kCrossingSeed;
using world_internal::kDatabaseSeed;
using world_internal::kMarksSeed;
using world_internal::kRoadSeed;
using world_internal::kTextureSeed;
using world_internal::NearCrossing;
using world_internal::OpenFacadesAtJunctions;
using world_internal::PaintAvenueLines;
using world_internal::ParkAtSideCrossings;
using world_internal::ParkOverEndBands;
using world_internal::ParkVehicles;
using world_internal::PlaceJunctions;
using world_internal::PlanLanes;
using world_internal::SplitCrossingsAtIsland;
using world_internal::StopLineBefore;
using world_internal::Subtract;

namespace {

// The centreline starts kLeadIn before the driven part and ends kLookAhead
// after it, so the cameras see road at the end of the drive.
constexpr double kLeadInM = 20.0;
constexpr double kLookAheadM = 150.0;
// Offset of the edge lines from the kerbs.
constexpr double kEdgeLineInsetM = 0.3;

std::string CrossingId(int number) {
  char text[32];
  std::snprintf(text, sizeof(text), "zc-%04d", number);
  return text;
}

// Stratified positions: slot i holds one crossing, at least
// min_crossing_spacing_m from its neighbours. The first is seen from 25 m
// before it, the last up to 3 m after the end of the drive.
std::vector<double> CrossingPositions(const SimulationOptions& options,
                                      const World& world, int total,
                                      std::mt19937_64* rng) {
  const double a = world.s_drive_start + 25.0;
  const double b = world.s_drive_end + 3.0;
  const double slot = (b - a) / total;
  const double spacing = std::min(options.min_crossing_spacing_m, slot);
  std::vector<double> positions;
  for (int i = 0; i < total; ++i) {
    positions.push_back(a + i * slot + 0.5 * spacing +
                        Uniform(rng, 0.0, slot - spacing));
  }
  return positions;
}

// Which slots are stale (database only), and the faults of street ones.
std::vector<std::string> CrossingRoles(const SimulationOptions& options,
                                       int total, std::mt19937_64* rng) {
  std::vector<int> order(total);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), *rng);
  std::vector<std::string> role(total, "ok");
  int next = 0;
  auto assign = [&](int count, const char* name) {
    for (int i = 0; i < count && next < total; ++i) role[order[next++]] = name;
  };
  assign(options.num_stale_crossings, "stale");
  assign(options.num_missing_crossings, "missing");
  assign(options.num_repainted_crossings, "repainted");
  assign(options.num_missing_bands, "missing_band");
  assign(options.num_missing_end_bands, "missing_end_band");
  assign(options.num_missing_interior_bands, "missing_interior_band");
  return role;
}

// The design of a crossing at s_design: skew, band length and count, the
// bands' place across the road, and the database's offset. `fit` bands of
// `period` fit between the kerbs.
Crossing DesignCrossing(const SimulationOptions& options, const Road& road,
                        double s_design, const CrossingDesignDraw& design,
                        int fit, std::mt19937_64* rng) {
  Crossing c;
  c.t = road.Tangent(s_design);
  c.n = road.LeftNormal(s_design);
  if (Bernoulli(rng, options.skew_probability) && options.max_skew_deg > 0.0) {
    const double lo = std::min(8.0, options.max_skew_deg);
    c.skew_deg = Uniform(rng, lo, options.max_skew_deg) *
                 (Bernoulli(rng, 0.5) ? 1.0 : -1.0);
  }
  c.tan_skew = std::tan(DegToRad(c.skew_deg));
  c.band_length_m =
      Uniform(rng, options.min_band_length_m, options.max_band_length_m);
  c.band_width_m = design.band_width_m;
  c.band_period_m = design.band_width_m + design.band_gap_m;
  c.ladder_bar_width_m = design.ladder_bar_width_m;
  const int most = std::min(options.max_bands_per_crossing, fit);
  DrawBandRow(options, road.width_m(), most, rng, &c);
  return c;
}

// What a role may use, drawn for every crossing whatever its role (so that
// the draws of the next crossings do not depend on it).
struct RoleDraws {
  double shift_along = 0.0;
  double shift_across = 0.0;
  bool long_band_worn = false;
  bool stop_line = false;
};

RoleDraws DrawRoleDraws(const SimulationOptions& options,
                        std::mt19937_64* rng) {
  RoleDraws draws;
  draws.shift_along = options.repaint_shift_m * Uniform(rng, 0.6, 1.0) *
                      (Bernoulli(rng, 0.5) ? 1.0 : -1.0);
  draws.shift_across = options.repaint_shift_m * Uniform(rng, -0.4, 0.4);
  draws.long_band_worn = Bernoulli(rng, 0.5);
  draws.stop_line = Bernoulli(rng, options.stop_line_probability);
  return draws;
}

// The crossing's faults for its role; the database's band gaps draw from
// `gap_rng`.
void ApplyRole(const std::string& role, const RoleDraws& draws,
               std::mt19937_64* gap_rng, Crossing* crossing) {
  Crossing& c = *crossing;
  c.num_street_bands = c.num_design_bands;
  c.num_db_bands = c.num_design_bands;
  if (role == "stale") {
    c.in_street = false;
  } else if (role == "missing") {
    c.in_db = false;
  } else if (role == "repainted") {
    c.repainted = true;
    c.repaint_shift_xy = draws.shift_along * c.t + draws.shift_across * c.n;
  } else if (role == "missing_band") {
    // Always the last band, so both files number 1..N consecutively.
    if (draws.long_band_worn) {
      c.missing_band_kind = "worn_in_street";
      c.num_street_bands = c.num_design_bands - 1;
    } else {
      c.missing_band_kind = "missing_in_db";
      c.num_db_bands = c.num_design_bands - 1;
    }
  } else if (role == "missing_end_band" && c.num_design_bands >= 2) {
    c.missing_band_kind = "end_missing_in_db";
    c.db_missing_bands = {Bernoulli(gap_rng, 0.5) ? 1 : c.num_design_bands};
  } else if (role == "missing_interior_band" && c.num_design_bands >= 3) {
    c.missing_band_kind = "interior_missing_in_db";
    c.db_missing_bands = {UniformInt(gap_rng, 2, c.num_design_bands - 1)};
  }
}

// The crossing's origin and road position after a repaint, and the span of
// road its bands cover.
void PlaceCrossingOnRoad(const Road& road, double s_design,
                         Crossing* crossing) {
  Crossing& c = *crossing;
  c.origin_xy = road.Centre(s_design) + c.repaint_shift_xy;
  c.s_m = s_design + c.repaint_shift_xy.dot(c.t);
  const double o_end = c.first_offset_m +
                       (c.num_design_bands - 1) * c.band_period_m +
                       c.band_width_m;
  const double skew_lo = std::min(c.first_offset_m, o_end) * c.tan_skew;
  const double skew_hi = std::max(c.first_offset_m, o_end) * c.tan_skew;
  // (A ladder's bars, at most a few decimetres beyond the band ends, stay
  // within the margins the lines and small marks keep from s_min, s_max:
  // with them inside, a ladder changes nothing else in the street.)
  const double half = 0.5 * c.band_length_m;
  c.s_min = c.s_m + std::min(skew_lo, skew_hi) - half;
  c.s_max = c.s_m + std::max(skew_lo, skew_hi) + half;
}

void PlaceCrossings(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kCrossingSeed));
  const Road& road = world->road;
  const int total = options.num_crossings + options.num_stale_crossings;
  if (total == 0) return;
  const std::vector<double> positions =
      CrossingPositions(options, *world, total, &rng);
  const std::vector<std::string> role = CrossingRoles(options, total, &rng);
  // The database's band gaps draw from their own generator: the crossings
  // of the other presets do not change with these knobs.
  std::mt19937_64 gap_rng(SubSeed(options.seed, kCrossingSeed, 7));
  // So do the designs (band sizes, ladder bars; issue 52).
  std::mt19937_64 design_rng(SubSeed(options.seed, kCrossingSeed, 52));

  const double width = road.width_m();
  int number = 100 + UniformInt(&rng, 1, 20);
  for (int i = 0; i < total; ++i) {
    number += UniformInt(&rng, 1, 3);  // ids are labels, with gaps
    const double s_design = positions[i];
    const CrossingDesignDraw design = DrawCrossingDesign(options, &design_rng);
    const int fit = static_cast<int>(
        std::floor((width - 2.0 * kBandKerbMarginM + design.band_gap_m) /
                   (design.band_width_m + design.band_gap_m)));
    Crossing c = DesignCrossing(options, road, s_design, design, fit, &rng);
    c.id = CrossingId(number);
    c.salt = SubSeed(options.seed, kCrossingSeed, 1000 + i);
    const RoleDraws draws = DrawRoleDraws(options, &rng);
    ApplyRole(role[i], draws, &gap_rng, &c);
    PlaceCrossingOnRoad(road, s_design, &c);
    c.stop_line = draws.stop_line && c.in_street;
    world->crossings.push_back(c);
  }
}

void PaintBands(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kMarksSeed, 1));
  for (int ci = 0; ci < static_cast<int>(world->crossings.size()); ++ci) {
    const Crossing& c = world->crossings[ci];
    if (!c.in_street) continue;
    for (int k = 1; k <= c.num_street_bands; ++k) {
      if (IsIslandBand(c, k)) continue;
      Band band;
      band.crossing = ci;
      band.band = k;
      band.corners = DesignBandCorners(*world, c, k, c.origin_xy);
      const auto& q = band.corners;
      Eigen::Vector3d normal = (q[2] - q[0]).cross(q[3] - q[1]).normalized();
      if (normal.z() < 0.0) normal = -normal;
      const Eigen::Vector3d centroid = 0.25 * (q[0] + q[1] + q[2] + q[3]);
      band.plane_normal = normal;
      band.plane_offset = normal.dot(centroid);
      band.o0 = c.first_offset_m + (k - 1) * c.band_period_m;
      band.o1 = band.o0 + c.band_width_m;
      if (Bernoulli(&rng, options.missing_paint_probability)) {
        band.patch_ao =
            Eigen::Vector2d(Uniform(&rng, -0.4, 0.4) * c.band_length_m,
                            Uniform(&rng, band.o0, band.o1));
        band.patch_radius_m = Uniform(&rng, 0.2, 0.6);
      }
      band.salt = SubSeed(options.seed, kMarksSeed, 5000 + world->bands.size());
      world->bands.push_back(band);
    }
  }
}

// The stop line across the driving lane, 1-5 m before crossing `ci`.
void PaintLines(const SimulationOptions& options, World* world) {
  const Road& road = world->road;
  const double half = 0.5 * road.width_m();
  std::vector<std::pair<double, double>> holes;
  for (const Crossing& c : world->crossings) {
    if (c.in_street && c.side_street < 0) {
      holes.push_back({c.s_min - 1.0 - c.beside_before_m,
                       c.s_max + 1.0 + c.beside_after_m});
    }
  }
  if (options.lane_lines) {
    const double end = road.length_m();
    for (double side : {-1.0, 1.0}) {
      // The edge line stops at the mouths of the side streets.
      std::vector<std::pair<double, double>> side_holes = holes;
      for (const SideStreet& street : world->side_streets) {
        if (street.side == side) {
          side_holes.push_back({street.mouth_s0 - 0.5, street.mouth_s1 + 0.5});
        }
      }
      for (const auto& [a, b] : Subtract(0.5, end - 0.5, side_holes)) {
        if (b - a < 1.0) continue;
        world->lines.push_back({"lane_solid", side * (half - kEdgeLineInsetM),
                                options.lane_line_width_m, a, b});
      }
    }
    const double period = options.dash_length_m + options.dash_gap_m;
    for (double s = 2.0; s + options.dash_length_m < end; s += period) {
      const double s1 = s + options.dash_length_m;
      bool clear = true;
      for (const auto& [a, b] : holes) clear &= (s1 <= a || s >= b);
      if (clear) {
        world->lines.push_back(
            {"lane_dashed", 0.0, options.lane_line_width_m, s, s1});
      }
    }
  }
  for (int ci = 0; ci < static_cast<int>(world->crossings.size()); ++ci) {
    if (!world->crossings[ci].stop_line) continue;
    world->stop_lines.push_back(StopLineBefore(*world, ci, options));
  }
}

// The lateral positions of the lane lines (edge, centre, edge).
std::vector<double> LaneLinePositions(const World& world,
                                      const SimulationOptions& options) {
  if (!options.lane_lines) return {};
  const double edge = 0.5 * world.road.width_m() - kEdgeLineInsetM;
  return {-edge, 0.0, edge};
}

// Where the database's copy of the road lines differs from the street. Its
// own generator: the street, and the bands of the database, do not change
// with the line-fault knobs.
void PlanDatabaseLineFaults(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kDatabaseSeed, 7));
  const std::vector<double> positions = LaneLinePositions(*world, options);
  const double a = world->s_drive_start;
  const double b = world->s_drive_end;
  for (double l : positions) {
    // Gaps may overlap: the share is approximate (at most the knob).
    double missing = options.database_line_gap_share * (b - a);
    while (missing > 1.0) {
      const double gap = std::min(missing, Uniform(&rng, 10.0, 30.0));
      const double s0 = Uniform(&rng, a, std::max(a, b - gap));
      world->database_line_faults.push_back({"gap", l, s0, s0 + gap});
      missing -= gap;
    }
  }
  for (int i = 0; i < options.num_moved_lines && !positions.empty(); ++i) {
    DatabaseLineFault moved;
    moved.kind = "moved";
    moved.l_m =
        positions[UniformInt(&rng, 0, static_cast<int>(positions.size()) - 1)];
    const double length = Uniform(&rng, 30.0, 60.0);
    moved.s0 = Uniform(&rng, a, std::max(a, b - length));
    moved.s1 = moved.s0 + length;
    moved.shift_m =
        (Bernoulli(&rng, 0.5) ? 1.0 : -1.0) * Uniform(&rng, 0.25, 0.45);
    world->database_line_faults.push_back(moved);
  }
  std::vector<int> without_stop_line;
  for (int ci = 0; ci < static_cast<int>(world->crossings.size()); ++ci) {
    const Crossing& c = world->crossings[ci];
    if (c.in_street && !c.stop_line) without_stop_line.push_back(ci);
  }
  std::shuffle(without_stop_line.begin(), without_stop_line.end(), rng);
  const int removed =
      std::min<int>(options.num_removed_stop_lines, without_stop_line.size());
  for (int i = 0; i < removed; ++i) {
    const StopLine stop = StopLineBefore(*world, without_stop_line[i], options);
    DatabaseLineFault fault;
    fault.kind = "removed";
    fault.l_m = stop.l0;
    fault.s0 = fault.s1 = stop.s_m;
    fault.crossing = stop.crossing;
    world->database_line_faults.push_back(fault);
  }
}

void PlaceSmallMarks(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kMarksSeed, 2));
  const Road& road = world->road;
  const double half = 0.5 * road.width_m();
  const double length = road.length_m();
  const int manholes =
      PoissonCount(&rng, options.manholes_per_100m * length / 100.0);
  for (int i = 0; i < manholes; ++i) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const double radius = Uniform(&rng, 0.3, 0.4);
      const double s = Uniform(&rng, 1.0, length - 1.0);
      const double l = Uniform(&rng, -half + 0.6, half - 0.6);
      const bool square = Bernoulli(&rng, 0.3);
      if (NearCrossing(*world, s - radius, s + radius, 1.5)) continue;
      bool clear = true;
      for (const LinePiece& line : world->lines) {
        if (std::abs(l - line.l_m) < radius + 0.5 * line.width_m + 0.1 &&
            s + radius > line.s0 && s - radius < line.s1) {
          clear = false;
        }
      }
      if (!clear) continue;
      Manhole m;
      m.centre = road.Centre(s) + l * road.LeftNormal(s);
      m.radius_m = radius;
      m.square = square;
      m.salt = rng();
      world->manholes.push_back(m);
      break;
    }
  }
  const int stains =
      PoissonCount(&rng, options.stains_per_100m * length / 100.0);
  for (int i = 0; i < stains; ++i) {
    const double s = Uniform(&rng, 1.0, length - 1.0);
    const double l = Uniform(&rng, -half + 0.3, half - 0.3);
    Stain stain;
    stain.centre = road.Centre(s) + l * road.LeftNormal(s);
    stain.radius_m = Uniform(&rng, 0.3, 1.2);
    stain.darkness = static_cast<float>(Uniform(&rng, 0.55, 0.85));
    stain.salt = rng();
    world->stains.push_back(stain);
  }
}

}  // namespace

namespace world_internal {

// The row of bands of crossing c across a street `width` wide: their count
// (at most `most`), the first one's offset from the street's middle, each
// band's ring of paint wear, and the database's offset of the crossing
// (c->band_width_m set). The draws' order is the random preset's contract:
// a change changes every survey after it.
void DrawBandRow(const SimulationOptions& options, double width, int most,
                 std::mt19937_64* rng, Crossing* c) {
  const int least = std::min(options.min_bands_per_crossing, most);
  c->num_design_bands =
      Bernoulli(rng, 0.6) ? most : UniformInt(rng, least, most);
  const double gap = c->band_period_m - c->band_width_m;
  const double span =
      c->num_design_bands * c->band_width_m + (c->num_design_bands - 1) * gap;
  const double free = width - 2.0 * kBandKerbMarginM - span;
  c->first_offset_m = -0.5 * width + kBandKerbMarginM +
                      (free > 0.3 ? Uniform(rng, 0.0, free) : 0.5 * free);
  for (int k = 0; k < c->num_design_bands; ++k) {
    c->ring_start.push_back(UniformInt(rng, 0, 3));
  }
  const double angle = Uniform(rng, 0.0, 2.0 * kPi);
  const double magnitude = Uniform(rng, options.database_min_offset_m,
                                   options.database_max_offset_m);
  c->db_offset_enu =
      Eigen::Vector3d(magnitude * std::cos(angle), magnitude * std::sin(angle),
                      Uniform(rng, -options.database_max_offset_m,
                              options.database_max_offset_m));
}

std::vector<std::pair<double, double>> Subtract(
    double s0, double s1, std::vector<std::pair<double, double>> holes) {
  std::sort(holes.begin(), holes.end());
  std::vector<std::pair<double, double>> out;
  double start = s0;
  for (const auto& [a, b] : holes) {
    if (b <= start) continue;
    if (a >= s1) break;
    if (a > start) out.push_back({start, a});
    start = std::max(start, b);
  }
  if (start < s1) out.push_back({start, s1});
  return out;
}

StopLine StopLineBefore(const World& world, int ci,
                        const SimulationOptions& options) {
  const Crossing& c = world.crossings[ci];
  StopLine line;
  line.width_m = 0.3;
  // Drawn per crossing from its salt (2 m when min = max = 2: as before),
  // before the paint beside it (issue 52).
  const double distance =
      options.min_stop_line_distance_m +
      (options.max_stop_line_distance_m - options.min_stop_line_distance_m) *
          HashToUnit(Mix64(c.salt + 5252));
  line.s_m = c.s_min - c.beside_before_m - distance - 0.5 * line.width_m;
  line.l0 = -0.5 * world.road.width_m() + kEdgeLineInsetM;
  line.l1 = -0.5 * options.lane_line_width_m - 0.05;
  line.crossing = ci;
  return line;
}

bool NearCrossing(const World& world, double s0, double s1, double margin) {
  for (const Crossing& c : world.crossings) {
    if (!c.in_street) continue;
    if (s1 > c.s_min - margin && s0 < c.s_max + margin) return true;
  }
  for (const SideStreet& street : world.side_streets) {
    if (s1 > street.mouth_s0 - margin && s0 < street.mouth_s1 + margin) {
      return true;
    }
  }
  return false;
}

}  // namespace world_internal

void Shadow::Finish() {
  edge_normals.clear();
  edge_offsets.clear();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d e = polygon[(i + 1) % polygon.size()] - polygon[i];
    if (e.norm() < 1e-9) continue;
    const Eigen::Vector2d normal = Eigen::Vector2d(-e.y(), e.x()).normalized();
    edge_normals.push_back(normal);
    edge_offsets.push_back(normal.dot(polygon[i]));
  }
}

double Shadow::InsideDistance(const Eigen::Vector2d& p) const {
  double d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < edge_normals.size(); ++i) {
    d = std::min(d, edge_normals[i].dot(p) - edge_offsets[i]);
  }
  return d;
}

std::array<Eigen::Vector2d, 4> VerticalBox::Footprint() const {
  const Eigen::Vector2d u = half_u * axis_u;
  const Eigen::Vector2d v = half_v * axis_v();
  return {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
}

std::array<Eigen::Vector3d, 4> DesignBandCorners(
    const World& world, const Crossing& crossing, int band,
    const Eigen::Vector2d& origin_xy) {
  const Road& road = world.road;
  const double o0 =
      crossing.first_offset_m + (band - 1) * crossing.band_period_m;
  const double o1 = o0 + crossing.band_width_m;
  const double half = 0.5 * crossing.band_length_m;
  // Counter-clockwise from above: along t, then left (+n), then back.
  const double ao[4][2] = {{-half, o0}, {half, o0}, {half, o1}, {-half, o1}};
  std::array<Eigen::Vector3d, 4> ring;
  const int start =
      crossing.ring_start.empty() ? 0 : crossing.ring_start[band - 1];
  for (int k = 0; k < 4; ++k) {
    const double a = ao[(k + start) % 4][0];
    const double o = ao[(k + start) % 4][1];
    const double along = o * crossing.tan_skew + a;
    const Eigen::Vector2d xy = origin_xy + o * crossing.n + along * crossing.t;
    double z = 0.0;
    if (crossing.side_street < 0) {
      z = road.SurfaceHeightAt(xy, crossing.s_m + along);
    } else {
      double s = 0.0, l = 0.0;
      road.ToRoadCoordinates(xy, crossing.s_m, &s, &l);
      z = GroundHeight(world, xy, s, l);
    }
    ring[k] = Eigen::Vector3d(xy.x(), xy.y(), z);
  }
  return ring;
}

World BuildWorld(const SimulationOptions& options) {
  RoadSpec spec;
  spec.length_m = options.road_length_m + kLeadInM + kLookAheadM;
  spec.width_m = options.road_width_m;
  spec.crossfall = options.crossfall;
  spec.crown_rounding_m = options.crown_rounding_m;
  spec.max_grade = options.max_grade;
  spec.grade_wavelength_m = options.grade_wavelength_m;
  spec.curved_share = options.curved_share;
  spec.min_curve_radius_m = options.min_curve_radius_m;
  spec.max_curve_radius_m = options.max_curve_radius_m;
  spec.transition_length_m = options.transition_length_m;
  spec.start_heading_rad = 0.5 * kPi - DegToRad(options.start_heading_deg);
  World world;
  world.road = Road::Generate(spec, SubSeed(options.seed, kRoadSeed));
  world.s_drive_start = kLeadInM;
  world.s_drive_end = kLeadInM + options.road_length_m;
  world.lane_offset_m = -0.25 * options.road_width_m;
  PlanLanes(options, &world);
  const double elevation = DegToRad(options.sun_elevation_deg);
  const double azimuth = DegToRad(options.sun_azimuth_deg);
  world.sun_enu = Eigen::Vector3d(std::sin(azimuth) * std::cos(elevation),
                                  std::cos(azimuth) * std::cos(elevation),
                                  std::sin(elevation));
  world.paint_wear = static_cast<float>(options.paint_wear);
  world.texture_salt = SubSeed(options.seed, kTextureSeed);
  PlaceCrossings(options, &world);
  SplitCrossingsAtIsland(options, &world);
  PlaceJunctions(options, &world);
  PaintBands(options, &world);
  world_internal::PaintBeside(options, &world);
  PaintLines(options, &world);
  PaintAvenueLines(options, &world);
  PlanDatabaseLineFaults(options, &world);
  PlaceSmallMarks(options, &world);
  BuildFacades(options, &world);
  OpenFacadesAtJunctions(options, &world);
  ParkVehicles(options, &world);
  ParkOverEndBands(options, &world);
  ParkAtSideCrossings(options, &world);
  world_internal::ParkTrucks(options, &world);
  CastShadows(options, &world);
  for (Shadow& shadow : world.shadows) shadow.Finish();
  return world;
}

}  // namespace zebrageo::sim
