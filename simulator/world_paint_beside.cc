// Paint beside the crossings (issue 52): rows of bicycle squares along a
// crossing's side with a coloured bicycle lane between two rows, a column
// of squares one band period beyond the last band, give-way teeth before
// the crossing; and trucks standing on crossings. None of the paint is a
// zebra band: the matcher must neither take it for one nor let it shift the
// bands' ids. Each part draws from its own generator, every draw made for
// every crossing whatever the outcome, so the other knobs' streets do not
// change with these.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"

namespace zebrageo::sim {

bool BesideMark::Contains(const Eigen::Vector2d& xy) const {
  const size_t n = polygon.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = polygon[(i + 1) % n] - polygon[i];
    const Eigen::Vector2d r = xy - polygon[i];
    if (e.x() * r.y() - e.y() * r.x() < 0.0) return false;
  }
  return true;
}

namespace world_internal {
namespace {

constexpr float kWhiteTone = 212.0f;
// A red coat in a grey image: luminance of a brick red, lighter than the
// asphalt (82) and far darker than paint.
constexpr float kRedLaneTone = 104.0f;

// The horizontal point of crossing c at offset o across and a along (from
// its skew line), as world.h defines the crossing frame.
Eigen::Vector2d CrossingPoint(const Crossing& c, double o, double a) {
  return c.origin_xy + o * c.n + (o * c.tan_skew + a) * c.t;
}

// The parallelogram o in [o0, o1], a in [a0, a1], counter-clockwise.
std::vector<Eigen::Vector2d> CrossingQuad(const Crossing& c, double o0,
                                          double o1, double a0, double a1) {
  return {CrossingPoint(c, o0, a0), CrossingPoint(c, o0, a1),
          CrossingPoint(c, o1, a1), CrossingPoint(c, o1, a0)};
}

// Counter-clockwise whatever the frame's handedness.
void MakeCounterClockwise(std::vector<Eigen::Vector2d>* polygon) {
  double area = 0.0;
  const size_t n = polygon->size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = (*polygon)[i];
    const Eigen::Vector2d& q = (*polygon)[(i + 1) % n];
    area += p.x() * q.y() - q.x() * p.y();
  }
  if (area < 0.0) std::reverse(polygon->begin(), polygon->end());
}

void AddMark(World* world, const std::string& kind, int crossing,
             std::vector<Eigen::Vector2d> polygon, float tone, bool white,
             uint64_t salt) {
  MakeCounterClockwise(&polygon);
  BesideMark mark;
  mark.kind = kind;
  mark.crossing = crossing;
  mark.polygon = std::move(polygon);
  mark.tone = tone;
  mark.white = white;
  mark.salt = salt;
  world->beside_marks.push_back(mark);
}

// The offsets across the street the crossing's paint may use.
void OffsetRange(const World& world, double* lo, double* hi) {
  const double half = 0.5 * world.road.width_m();
  *lo = -half + kBandKerbMarginM;
  *hi = half - kBandKerbMarginM;
}

// A row of squares across the street at a in [a0, a0 + size].
void SquareRow(const Crossing& c, int ci, double a0, double size,
               const World& probe, World* world) {
  double lo = 0.0, hi = 0.0;
  OffsetRange(probe, &lo, &hi);
  // Squares in phase with the bands (their period), as painted beside them.
  const double period = 2.0 * size;
  double o =
      c.first_offset_m - period * std::floor((c.first_offset_m - lo) / period);
  for (; o + size <= hi; o += period) {
    AddMark(world, "square", ci, CrossingQuad(c, o, o + size, a0, a0 + size),
            kWhiteTone, true, c.salt + 52 + world->beside_marks.size());
  }
}

// Draws for one crossing, all of them made whatever the outcome.
struct BesideDraws {
  bool squares = false, two_rows = false, lane = false, column = false,
       teeth = false;
  double side = 1.0;   // +1: after the crossing (along t), -1: before
  double gap_m = 0.3;  // from the band ends to the first row
  double lane_m = 2.0;
  double tooth_base_m = 0.5, tooth_height_m = 0.6, tooth_gap_m = 0.25;
};

BesideDraws Draw(const SimulationOptions& options, std::mt19937_64* rng) {
  BesideDraws d;
  d.squares = Bernoulli(rng, options.bike_squares_probability);
  d.two_rows = Bernoulli(rng, options.two_square_rows_probability);
  d.lane = Bernoulli(rng, options.bike_lane_probability);
  d.column = Bernoulli(rng, options.square_column_probability);
  d.teeth = Bernoulli(rng, options.give_way_teeth_probability);
  d.side = Bernoulli(rng, 0.5) ? 1.0 : -1.0;
  d.gap_m = Uniform(rng, 0.2, 0.5);
  d.lane_m = Uniform(rng, 1.8, 2.4);
  d.tooth_base_m = Uniform(rng, 0.4, 0.6);
  d.tooth_height_m = Uniform(rng, 0.5, 0.7);
  d.tooth_gap_m = Uniform(rng, 0.15, 0.3);
  return d;
}

// Rows of squares (and a bicycle lane between two) along one side.
void PaintSquareRows(const BesideDraws& d, double size, int ci, World* world) {
  Crossing& c = world->crossings[ci];
  const double half = 0.5 * c.band_length_m;
  // a of the rows' near edge, going away from the crossing.
  const double reach = d.gap_m + size + (d.two_rows ? d.lane_m + size : 0.0);
  const double a_near = d.side > 0 ? half + d.gap_m : -half - d.gap_m - size;
  const World& probe = *world;
  SquareRow(c, ci, a_near, size, probe, world);
  std::string what = "squares";
  if (d.two_rows) {
    const double a_far = a_near + d.side * (size + d.lane_m);
    SquareRow(c, ci, a_far, size, probe, world);
    what = "squares+squares";
    if (d.lane) {
      double lo = 0.0, hi = 0.0;
      OffsetRange(probe, &lo, &hi);
      const double a0 = d.side > 0 ? a_near + size : a_far + size;
      AddMark(world, "bike_lane", ci,
              CrossingQuad(c, lo, hi, a0, a0 + d.lane_m), kRedLaneTone, false,
              c.salt + 520);
      what = "squares+lane+squares";
    }
  }
  c.beside.push_back(what + (d.side > 0 ? " after" : " before"));
  // Skewed crossings: the rows' ends reach further along the road.
  const double skew = std::abs(c.tan_skew) * world->road.width_m();
  if (d.side > 0) {
    c.beside_after_m = std::max(c.beside_after_m, reach + skew);
  } else {
    c.beside_before_m = std::max(c.beside_before_m, reach + skew);
  }
}

// A column of squares along the bands, one period beyond the last band,
// or before the first when the street has no room beyond the last.
void PaintSquareColumn(double size, int ci, World* world) {
  Crossing& c = world->crossings[ci];
  double lo = 0.0, hi = 0.0;
  OffsetRange(*world, &lo, &hi);
  const double width = std::min(size, c.band_width_m);
  double o0 = c.first_offset_m + c.num_street_bands * c.band_period_m;
  std::string where = "beyond band " + std::to_string(c.num_street_bands);
  if (o0 + width > hi) {
    o0 = c.first_offset_m - c.band_period_m;
    where = "before band 1";
  }
  const double o1 = o0 + width;
  if (c.num_street_bands < 1 || o1 > hi || o0 < lo) return;
  const double half = 0.5 * c.band_length_m;
  for (double a = -half; a + size <= half + 1e-9; a += 2.0 * size) {
    AddMark(world, "square", ci, CrossingQuad(c, o0, o1, a, a + size),
            kWhiteTone, true, c.salt + 5200 + world->beside_marks.size());
  }
  c.beside.push_back("square column " + where);
}

// Give-way teeth across the driving lane (the right half), pointing at the
// approaching vehicle, s_end their far edge.
void PaintTeeth(const BesideDraws& d, int ci, double s_end, World* world) {
  const Road& road = world->road;
  const double half = 0.5 * road.width_m();
  const double s_tip = s_end - d.tooth_height_m;
  const double pitch = d.tooth_base_m + d.tooth_gap_m;
  for (double l = -half + 0.35; l + d.tooth_base_m <= -0.15; l += pitch) {
    const Eigen::Vector2d base0 =
        road.Centre(s_end) + l * road.LeftNormal(s_end);
    const Eigen::Vector2d base1 =
        road.Centre(s_end) + (l + d.tooth_base_m) * road.LeftNormal(s_end);
    const Eigen::Vector2d tip =
        road.Centre(s_tip) +
        (l + 0.5 * d.tooth_base_m) * road.LeftNormal(s_tip);
    AddMark(world, "tooth", ci, {base0, tip, base1}, kWhiteTone, true,
            world->crossings[ci].salt + 53000 + world->beside_marks.size());
  }
  world->crossings[ci].beside.push_back("give-way teeth");
}

}  // namespace

void PaintBeside(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kMarksSeed, 52));
  const double size = options.square_size_m;
  for (int ci = 0; ci < static_cast<int>(world->crossings.size()); ++ci) {
    const BesideDraws d = Draw(options, &rng);
    Crossing& c = world->crossings[ci];
    if (!c.in_street || c.side_street >= 0) continue;
    if (d.squares) PaintSquareRows(d, size, ci, world);
    if (d.column) PaintSquareColumn(size, ci, world);
    if (d.teeth) {
      // Teeth right before the crossing's paint; a stop line goes before
      // them (StopLineBefore counts them in beside_before_m).
      const double s_end = c.s_min - c.beside_before_m - 0.4;
      PaintTeeth(d, ci, s_end, world);
      c.beside_before_m += 0.4 + d.tooth_height_m;
    }
  }
}

void ParkTrucks(const SimulationOptions& options, World* world) {
  if (options.truck_probability <= 0.0) return;
  std::mt19937_64 rng(SubSeed(options.seed, kVehicleSeed, 52));
  const Road& road = world->road;
  const double half_width = 0.5 * road.width_m();
  for (Crossing& c : world->crossings) {
    const bool want = Bernoulli(&rng, options.truck_probability);
    const double length = Uniform(&rng, 7.0, 10.0);
    const double height = Uniform(&rng, 3.2, 3.8);
    const double along = Uniform(&rng, -1.0, 1.0);
    const double tone = Uniform(&rng, 120.0, 220.0);
    const uint64_t salt = rng();
    if (!want || !c.in_street || c.side_street >= 0) continue;
    if (!c.end_band_vehicle.empty()) continue;  // the oncoming kerb is taken
    // In the oncoming lane: its right side 0.3 m left of the centre line,
    // its left side short of the kerb.
    const double width = 2.5;
    const double l_right = std::max(0.3, -world->lane_offset_m - 1.5);
    const double l_centre =
        std::min(l_right + 0.5 * width, half_width - 0.15 - 0.5 * width);
    if (l_centre - 0.5 * width < 0.2) continue;  // too narrow a street
    const double o_mid = std::clamp(l_centre, -half_width, half_width);
    const double s = c.s_m + o_mid * c.tan_skew + along;
    ParkedVehicle v;
    v.box.centre = road.Centre(s) + l_centre * road.LeftNormal(s);
    v.box.axis_u = road.Tangent(s);
    v.box.half_u = 0.5 * length;
    v.box.half_v = 0.5 * width;
    v.box.z0 = road.Height(s, l_centre) - 0.05;
    v.box.z1 = v.box.z0 + height;
    v.body_tone = static_cast<float>(tone);
    v.s0 = s - 0.5 * length;
    v.s1 = s + 0.5 * length;
    v.occludes_crossing = true;
    v.truck = true;
    v.salt = salt;
    world->vehicles.push_back(v);
    c.truck = true;
    c.truck_bands.clear();
    for (int k = 1; k <= c.num_street_bands; ++k) {
      const double o0 = c.first_offset_m + (k - 1) * c.band_period_m;
      const double o1 = o0 + c.band_width_m;
      // Under it when most of the band's width is (the truck is longer
      // than any band).
      const double covered = std::min(o1, l_centre + 0.5 * width) -
                             std::max(o0, l_centre - 0.5 * width);
      if (covered > 0.5 * c.band_width_m) c.truck_bands.push_back(k);
    }
  }
}

}  // namespace world_internal
}  // namespace zebrageo::sim
