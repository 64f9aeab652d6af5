// Avenues (issue 52): a median down the road's middle whose refuge island
// splits every crossing, in either database form of SURVEY_FORMAT.md (two
// crossing_ids, one per half, the far half possibly staggered along the
// road; or one crossing whose band numbers skip the island's places), the
// lines of the median and of the lanes, and a vehicle driving in any lane
// and changing lanes. Everything here draws from its own generator, so a
// street without a median or extra lanes is the same as before.
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

// Purpose of this file's generators (SubSeed); the others are 1-9.
constexpr uint64_t kAvenueSeed = 52;
// A band closer than this to the island's edge is not painted.
constexpr double kIslandMarginM = 0.15;

bool IsAvenue(const SimulationOptions& options) {
  return options.median_width_m > 0.0;
}

// Width of one lane, and the centre of lane `j` (0: the innermost) of the
// right carriageway.
double LaneWidth(const SimulationOptions& options) {
  return 0.5 * (options.road_width_m - options.median_width_m) /
         options.lanes_per_direction;
}

double LaneCentre(const SimulationOptions& options, int j) {
  return -(0.5 * options.median_width_m + (j + 0.5) * LaneWidth(options));
}

// Smooth step 0 -> 1 over u in [0, 1] (a lane change's lateral profile).
double Ease(double u) { return 0.5 * (1.0 - std::cos(kPi * u)); }

// The road span of crossing c's painted area (skew included).
void SetRoadSpan(Crossing* c) {
  const double o0 = c->first_offset_m;
  const double o1 = c->first_offset_m +
                    (c->num_design_bands - 1) * c->band_period_m +
                    c->band_width_m;
  const double lo = std::min(o0, o1) * c->tan_skew;
  const double hi = std::max(o0, o1) * c->tan_skew;
  c->s_min = c->s_m + std::min(lo, hi) - 0.5 * c->band_length_m;
  c->s_max = c->s_m + std::max(lo, hi) + 0.5 * c->band_length_m;
}

// The fault label of a database gap at band k of a crossing of n bands.
const char* GapKind(int k, int n) {
  return (k == 1 || k == n) ? "end_missing_in_db" : "interior_missing_in_db";
}

// Crossing c laid kerb to kerb, centred, keeping its faults (the last band
// worn or missing from the database, a database gap) on the new row; the
// ring draws of added bands come from `rng`.
void RelayKerbToKerb(const SimulationOptions& options, double width,
                     std::mt19937_64* rng, Crossing* c) {
  const int fit = static_cast<int>(std::floor(
      (width - 2.0 * world_internal::kBandKerbMarginM + options.band_gap_m) /
      c->band_period_m));
  const int street_deficit = c->num_design_bands - c->num_street_bands;
  const int db_deficit = c->num_design_bands - c->num_db_bands;
  const int old_n = c->num_design_bands;
  c->num_design_bands = fit;
  c->first_offset_m = -0.5 * (fit * c->band_period_m - options.band_gap_m);
  while (static_cast<int>(c->ring_start.size()) < fit) {
    c->ring_start.push_back(UniformInt(rng, 0, 3));
  }
  c->ring_start.resize(fit);
  c->num_street_bands = fit - street_deficit;
  c->num_db_bands = fit - db_deficit;
  for (int& k : c->db_missing_bands) {
    if (k == old_n) k = fit;
  }
}

// The island's band places of crossing c: [first, last], or first > last
// when the row does not reach it.
std::pair<int, int> IslandPlaces(const SimulationOptions& options,
                                 const Crossing& c) {
  const double half = 0.5 * options.median_width_m + kIslandMarginM;
  int first = c.num_design_bands + 1, last = 0;
  for (int k = 1; k <= c.num_design_bands; ++k) {
    const double o0 = c.first_offset_m + (k - 1) * c.band_period_m;
    const double o1 = o0 + c.band_width_m;
    if (o1 > -half && o0 < half) {
      first = std::min(first, k);
      last = std::max(last, k);
    }
  }
  return {first, last};
}

// Keeps the bands [from, to] of crossing c as a crossing of its own
// (numbered from 1), with the database gaps and last-band faults that fall
// in it.
Crossing HalfOf(const Crossing& c, int from, int to, bool holds_last) {
  Crossing h = c;
  const int n = to - from + 1;
  h.num_design_bands = n;
  h.first_offset_m = c.first_offset_m + (from - 1) * c.band_period_m;
  h.ring_start.assign(c.ring_start.begin() + (from - 1),
                      c.ring_start.begin() + to);
  h.num_street_bands = n;
  h.num_db_bands = n;
  h.missing_band_kind.clear();
  h.db_missing_bands.clear();
  if (holds_last) {
    h.num_street_bands = n - (c.num_design_bands - c.num_street_bands);
    h.num_db_bands = n - (c.num_design_bands - c.num_db_bands);
    if (c.missing_band_kind == "worn_in_street" ||
        c.missing_band_kind == "missing_in_db") {
      h.missing_band_kind = c.missing_band_kind;
    }
  }
  for (int k : c.db_missing_bands) {
    if (k >= from && k <= to) {
      h.db_missing_bands.push_back(k - from + 1);
      h.missing_band_kind = GapKind(k - from + 1, n);
    }
  }
  return h;
}

}  // namespace

double LaneOffsetAt(const World& world, double s) {
  if (world.lane_changes.empty()) return world.lane_offset_m;
  double l = world.lane_changes.front().l_from;
  for (const LaneChange& change : world.lane_changes) {
    if (s <= change.s0) break;
    if (s >= change.s1) {
      l = change.l_to;
      continue;
    }
    const double u = (s - change.s0) / (change.s1 - change.s0);
    return change.l_from + (change.l_to - change.l_from) * Ease(u);
  }
  return l;
}

double LaneOffsetSlopeAt(const World& world, double s) {
  for (const LaneChange& change : world.lane_changes) {
    if (s > change.s0 && s < change.s1) {
      const double length = change.s1 - change.s0;
      const double u = (s - change.s0) / length;
      return (change.l_to - change.l_from) * 0.5 * kPi * std::sin(kPi * u) /
             length;
    }
  }
  return 0.0;
}

bool IsIslandBand(const Crossing& crossing, int band) {
  return std::find(crossing.island_bands.begin(), crossing.island_bands.end(),
                   band) != crossing.island_bands.end();
}

namespace world_internal {

void PlanLanes(const SimulationOptions& options, World* world) {
  world->median_width_m = options.median_width_m;
  const int lanes = options.lanes_per_direction;
  if (!IsAvenue(options) && lanes == 1) return;
  std::mt19937_64 rng(SubSeed(options.seed, kAvenueSeed, 1));
  int lane = UniformInt(&rng, 0, lanes - 1);
  world->lane_offset_m = LaneCentre(options, lane);
  if (lanes == 1 || options.num_lane_changes == 0) return;
  // One change per slot of the drive, each to a neighbouring lane.
  const double a = world->s_drive_start + 10.0;
  const double b = world->s_drive_end - 10.0;
  const double slot = (b - a) / options.num_lane_changes;
  double outermost = world->lane_offset_m;
  for (int i = 0; i < options.num_lane_changes; ++i) {
    const double length = std::min(Uniform(&rng, 30.0, 60.0), 0.9 * slot);
    const double s0 = a + i * slot + Uniform(&rng, 0.0, slot - length);
    const int next = lane == 0 ? 1
                     : lane == lanes - 1
                         ? lane - 1
                         : lane + (Bernoulli(&rng, 0.5) ? 1 : -1);
    LaneChange change;
    change.s0 = s0;
    change.s1 = s0 + length;
    change.l_from = LaneCentre(options, lane);
    change.l_to = LaneCentre(options, next);
    world->lane_changes.push_back(change);
    outermost = std::min(outermost, change.l_to);
    lane = next;
  }
  // The scenery keeps the kerb clear of the outermost lane driven.
  world->lane_offset_m = outermost;
}

void SplitCrossingsAtIsland(const SimulationOptions& options, World* world) {
  if (!IsAvenue(options)) return;
  std::mt19937_64 rng(SubSeed(options.seed, kAvenueSeed, 2));
  std::vector<Crossing> out;
  for (Crossing c : world->crossings) {
    // The same draws for every crossing, whatever it becomes.
    const bool split = Bernoulli(&rng, options.split_crossing_probability);
    const double stagger = Uniform(&rng, -1.0, 1.0) * options.max_stagger_m;
    if (c.side_street >= 0) {
      out.push_back(c);
      continue;
    }
    RelayKerbToKerb(options, world->road.width_m(), &rng, &c);
    const auto [first, last] = IslandPlaces(options, c);
    if (first > last || first < 3 || last > c.num_design_bands - 2) {
      SetRoadSpan(&c);
      out.push_back(c);  // too narrow to split: left whole
      continue;
    }
    if (!split) {
      c.island_form = "one_id";
      for (int k = first; k <= last; ++k) c.island_bands.push_back(k);
      // A database gap drawn on an island place moves beside it.
      for (int& k : c.db_missing_bands) {
        if (IsIslandBand(c, k)) k = first - 1;
      }
      SetRoadSpan(&c);
      out.push_back(c);
      continue;
    }
    Crossing near = HalfOf(c, 1, first - 1, false);
    Crossing far = HalfOf(c, last + 1, c.num_design_bands, true);
    near.id = c.id + "a";
    far.id = c.id + "b";
    near.island_form = "near_half";
    far.island_form = "far_half";
    near.other_half = far.id;
    far.other_half = near.id;
    far.origin_xy += stagger * c.t;
    far.s_m += stagger;
    far.salt = c.salt ^ 0x5a5a5a5aULL;
    far.stop_line = false;  // the stop line stands before the near half
    SetRoadSpan(&near);
    SetRoadSpan(&far);
    out.push_back(near);
    out.push_back(far);
  }
  world->crossings = out;
}

void PaintAvenueLines(const SimulationOptions& options, World* world) {
  if (!options.lane_lines ||
      (!IsAvenue(options) && options.lanes_per_direction == 1)) {
    return;
  }
  std::vector<std::pair<double, double>> holes;
  for (const Crossing& c : world->crossings) {
    if (c.in_street && c.side_street < 0) {
      holes.push_back({c.s_min - 1.0, c.s_max + 1.0});
    }
  }
  const double end = world->road.length_m();
  const double half_median = 0.5 * options.median_width_m;
  if (IsAvenue(options)) {
    // The median's edges replace the dashed centre line.
    world->lines.erase(std::remove_if(world->lines.begin(), world->lines.end(),
                                      [](const LinePiece& line) {
                                        return line.type == "lane_dashed" &&
                                               line.l_m == 0.0;
                                      }),
                       world->lines.end());
    for (double side : {-1.0, 1.0}) {
      for (const auto& [a, b] : Subtract(0.5, end - 0.5, holes)) {
        if (b - a < 1.0) continue;
        world->lines.push_back({"lane_solid", side * half_median,
                                options.lane_line_width_m, a, b});
      }
    }
    for (StopLine& stop : world->stop_lines) {
      stop.l1 = std::min(stop.l1, -half_median - 0.05);
    }
  }
  const double period = options.dash_length_m + options.dash_gap_m;
  for (int j = 1; j < options.lanes_per_direction; ++j) {
    const double l = half_median + j * LaneWidth(options);
    for (double side : {-1.0, 1.0}) {
      for (double s = 2.0; s + options.dash_length_m < end; s += period) {
        const double s1 = s + options.dash_length_m;
        bool clear = true;
        for (const auto& [a, b] : holes) clear &= (s1 <= a || s >= b);
        if (clear) {
          world->lines.push_back(
              {"lane_dashed", side * l, options.lane_line_width_m, s, s1});
        }
      }
    }
  }
}

}  // namespace world_internal
}  // namespace zebrageo::sim
