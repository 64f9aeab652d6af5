// Junctions (issue 51): side streets meeting the road at 0-30 degrees off
// square, T (one side) or four-way (both sides), each arm with a zebra
// crossing across the side street set back from the road's kerb line, so
// that its bands' long sides lie across the track; the facades opened at
// the mouths; vehicles partly hiding some of those crossings. All from the
// junctions' own generators: a street without junctions is unchanged.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

using world_internal::DrawBandRow;
using world_internal::kBandKerbMarginM;
using world_internal::kJunctionSeed;

constexpr double kSideStreetLengthM = 60.0;
// Distance kept between a junction's mouth and the road's crossings.
constexpr double kMouthClearanceM = 4.0;

// The road s-range of the mouth of a side street at the road's kerb line.
void SetMouth(const Road& road, SideStreet* street) {
  const double half = 0.5 * road.width_m();
  const double c = std::cos(street->angle_rad);
  const double centre = street->s_m + half * std::tan(street->angle_rad);
  street->mouth_s0 = centre - 0.5 * street->width_m / c;
  street->mouth_s1 = centre + 0.5 * street->width_m / c;
}

SideStreet MakeSideStreet(const Road& road, double s, int side, double angle,
                          double width, int junction) {
  SideStreet street;
  street.s_m = s;
  street.side = side;
  street.angle_rad = angle;
  street.width_m = width;
  street.length_m = kSideStreetLengthM;
  street.junction = junction;
  street.axis_xy = road.Centre(s);
  street.direction = (std::sin(angle) * road.Tangent(s) +
                      side * std::cos(angle) * road.LeftNormal(s))
                         .normalized();
  SetMouth(road, &street);
  return street;
}

// The s-range a side street and its crossing may cover (mouth, and the
// crossing up to 17 m from the centreline, with the angle).
std::pair<double, double> Footprint(const Road& road, const SideStreet& s) {
  const double reach = 0.5 * road.width_m() + 17.0;
  const double lean = reach * std::tan(s.angle_rad);
  return {std::min(s.mouth_s0, s.mouth_s0 + lean) - kMouthClearanceM,
          std::max(s.mouth_s1, s.mouth_s1 + lean) + kMouthClearanceM};
}

bool Clear(const World& world, double s0, double s1) {
  if (world_internal::NearCrossing(world, s0, s1, 3.0)) return false;
  return true;
}

// The crossing across `street`: its bands' long sides along the street,
// set back from the road's kerb line, skewed (half of them parallel to the
// road's kerb line).
Crossing DesignSideCrossing(const SimulationOptions& options,
                            const World& world, int street_index,
                            std::mt19937_64* rng) {
  const SideStreet& street = world.side_streets[street_index];
  const Road& road = world.road;
  Crossing c;
  c.side_street = street_index;
  c.t = street.direction;
  c.n = street.across();
  if (Bernoulli(rng, 0.5)) {
    // Parallel to the road's kerb line.
    c.tan_skew = -street.side * std::tan(street.angle_rad);
  } else if (options.max_skew_deg > 0.0 && Bernoulli(rng, 0.5)) {
    c.tan_skew = std::tan(
        DegToRad(Uniform(rng, -options.max_skew_deg, options.max_skew_deg)));
  }
  c.skew_deg = RadToDeg(std::atan(c.tan_skew));
  c.band_length_m = Uniform(rng, options.min_band_length_m,
                            std::min(options.max_band_length_m, 4.5));
  c.band_width_m = options.band_width_m;
  c.band_period_m = options.band_width_m + options.band_gap_m;
  const double width = street.width_m;
  const int fit = static_cast<int>(std::floor(
      (width - 2.0 * kBandKerbMarginM + options.band_gap_m) / c.band_period_m));
  const int most = std::max(1, std::min(options.max_bands_per_crossing, fit));
  DrawBandRow(options, width, most, rng, &c);
  // The near ends of the bands `setback` or more beyond the road's kerb
  // line: at offset o across the side street the kerb line is at
  // half / cos(angle) - side o tan(angle) along it, the near end at
  // along - L / 2 + o tan_skew.
  const double setback = Uniform(rng, options.min_side_crossing_setback_m,
                                 options.max_side_crossing_setback_m);
  const double kerb = 0.5 * road.width_m() / std::cos(street.angle_rad);
  const double lean =
      0.5 * width *
      std::abs(c.tan_skew + street.side * std::tan(street.angle_rad));
  const double along = kerb + setback + lean + 0.5 * c.band_length_m;
  c.origin_xy = street.axis_xy + along * street.direction;
  c.num_street_bands = c.num_design_bands;
  c.num_db_bands = c.num_design_bands;
  double s = 0.0, l = 0.0;
  road.ToRoadCoordinates(c.origin_xy, street.s_m, &s, &l);
  c.s_m = s;
  return c;
}

// The road s-range of a crossing's painted corners.
void SetRoadSpan(const World& world, Crossing* c) {
  c->s_min = 1e300;
  c->s_max = -1e300;
  for (int k = 1; k <= c->num_design_bands; ++k) {
    for (const Eigen::Vector3d& p :
         DesignBandCorners(world, *c, k, c->origin_xy)) {
      double s = 0.0, l = 0.0;
      world.road.ToRoadCoordinates(p.head<2>(), c->s_m, &s, &l);
      c->s_min = std::min(c->s_min, s);
      c->s_max = std::max(c->s_max, s);
    }
  }
}

std::string SideCrossingId(int number) {
  char text[32];
  std::snprintf(text, sizeof(text), "zc-%04d", number);
  return text;
}

}  // namespace

int SideStreetAt(const World& world, const Eigen::Vector2d& xy, double l) {
  const double half = 0.5 * world.road.width_m();
  for (int k = 0; k < static_cast<int>(world.side_streets.size()); ++k) {
    const SideStreet& street = world.side_streets[k];
    if (street.side * l <= half) continue;
    const Eigen::Vector2d rel = xy - street.axis_xy;
    const double along = rel.dot(street.direction);
    if (along < 0.0 || along > street.length_m) continue;
    if (std::abs(rel.dot(street.across())) <= 0.5 * street.width_m) return k;
  }
  return -1;
}

double GroundHeight(const World& world, const Eigen::Vector2d& xy, double s,
                    double l) {
  const Road& road = world.road;
  const double half = 0.5 * road.width_m();
  if (std::abs(l) > half && SideStreetAt(world, xy, l) >= 0) {
    return road.CrownHeight(s) + road.CrossSection(l < 0.0 ? -half : half);
  }
  return road.Height(s, l);
}

namespace world_internal {

void PlaceJunctions(const SimulationOptions& options, World* world) {
  if (options.num_junctions <= 0) return;
  std::mt19937_64 rng(SubSeed(options.seed, kJunctionSeed));
  const Road& road = world->road;
  const double a = world->s_drive_start + 20.0;
  const double b = world->s_drive_end - 5.0;
  std::vector<std::pair<double, double>> taken;
  int junction = 0;
  for (int j = 0; j < options.num_junctions && b > a; ++j) {
    for (int attempt = 0; attempt < 60; ++attempt) {
      const double s = Uniform(&rng, a, b);
      const bool four_way = Bernoulli(&rng, options.four_way_probability);
      const int first_side = Bernoulli(&rng, 0.5) ? 1 : -1;
      const double angle =
          DegToRad(Uniform(&rng, -options.junction_max_angle_deg,
                           options.junction_max_angle_deg));
      std::vector<SideStreet> arms;
      for (int side : {first_side, -first_side}) {
        if (side != first_side && !four_way) break;
        const double width = Uniform(&rng, options.min_side_street_width_m,
                                     options.max_side_street_width_m);
        // The far arm of a four-way junction continues the near one.
        arms.push_back(MakeSideStreet(road, s, side,
                                      side == first_side ? angle : -angle,
                                      width, junction));
      }
      bool fits = true;
      for (const SideStreet& arm : arms) {
        const auto [s0, s1] = Footprint(road, arm);
        fits &= Clear(*world, s0, s1);
        for (const auto& [t0, t1] : taken) fits &= (s1 < t0 || s0 > t1);
      }
      if (!fits) continue;
      for (const SideStreet& arm : arms) {
        taken.push_back(Footprint(road, arm));
        world->side_streets.push_back(arm);
      }
      ++junction;
      break;
    }
  }
  // The crossings across them, numbered after the road's.
  int number = 900;
  for (int k = 0; k < static_cast<int>(world->side_streets.size()); ++k) {
    number += UniformInt(&rng, 1, 3);
    const bool want = Bernoulli(&rng, options.side_crossing_probability);
    Crossing c = DesignSideCrossing(options, *world, k, &rng);
    if (!want) continue;
    c.id = SideCrossingId(number);
    c.salt = SubSeed(options.seed, kJunctionSeed, 1000 + k);
    SetRoadSpan(*world, &c);
    world->crossings.push_back(c);
  }
}

void OpenFacadesAtJunctions(const SimulationOptions& options, World* world) {
  if (world->side_streets.empty()) return;
  const Road& road = world->road;
  const double front = 0.5 * road.width_m() + options.sidewalk_width_m;
  std::vector<Building> kept;
  for (const Building& building : world->buildings) {
    const int side = building.front_side > 0 ? -1 : 1;
    const double depth = 2.0 * building.box.half_v;
    std::vector<std::pair<double, double>> holes;
    for (const SideStreet& street : world->side_streets) {
      if (street.side != side) continue;
      const double lean = std::tan(street.angle_rad);
      const double half = 0.5 * street.width_m / std::cos(street.angle_rad);
      const double a =
          street.s_m + std::min(front * lean, (front + depth) * lean);
      const double b =
          street.s_m + std::max(front * lean, (front + depth) * lean);
      holes.push_back({a - half - 1.0, b + half + 1.0});
    }
    const auto pieces =
        world_internal::Subtract(building.s0, building.s1, holes);
    if (pieces.size() == 1 && pieces[0].first == building.s0 &&
        pieces[0].second == building.s1) {
      kept.push_back(building);
      continue;
    }
    for (const auto& [s0, s1] : pieces) {
      if (s1 - s0 < 3.0) continue;
      Building piece = building;
      piece.s0 = s0;
      piece.s1 = s1;
      const Eigen::Vector2d a =
          road.Centre(s0) + side * front * road.LeftNormal(s0);
      const Eigen::Vector2d b =
          road.Centre(s1) + side * front * road.LeftNormal(s1);
      VerticalBox& box = piece.box;
      box.axis_u = (b - a).normalized();
      box.half_u = 0.5 * (b - a).norm();
      box.centre = 0.5 * (a + b) + side * 0.5 * depth * box.axis_v();
      piece.window_offset_m =
          0.5 * (std::fmod(2.0 * box.half_u, piece.window_period_m) +
                 piece.window_period_m - piece.window_width_m);
      piece.salt = building.salt + static_cast<uint64_t>(s0 * 1000.0);
      kept.push_back(piece);
    }
  }
  world->buildings = std::move(kept);
}

void ParkAtSideCrossings(const SimulationOptions& options, World* world) {
  if (world->side_streets.empty()) return;
  std::mt19937_64 rng(SubSeed(options.seed, kJunctionSeed, 2));
  const Road& road = world->road;
  for (Crossing& c : world->crossings) {
    if (c.side_street < 0) continue;
    const SideStreet& street = world->side_streets[c.side_street];
    const bool want =
        Bernoulli(&rng, options.side_crossing_vehicle_probability);
    const bool turning = Bernoulli(&rng, 0.5);
    const double length = Uniform(&rng, 4.0, 4.8);
    const double width = Uniform(&rng, 1.7, 1.9);
    const double height = Uniform(&rng, 1.4, 1.75);
    const double gap = Uniform(&rng, 0.5, 1.5);
    const double shift = Uniform(&rng, -0.5, 0.5);
    const bool left_kerb = Bernoulli(&rng, 0.5);
    const float tone = static_cast<float>(Uniform(&rng, 25.0, 225.0));
    const uint64_t salt = rng();
    if (!want) continue;
    const double w = street.width_m;
    const double centre_along =
        (c.origin_xy - street.axis_xy).dot(street.direction);
    const double lean = 0.5 * w * std::abs(c.tan_skew);
    const double kerb = 0.5 * road.width_m() / std::cos(street.angle_rad) +
                        0.5 * w * std::abs(std::tan(street.angle_rad));
    // Waiting to turn into the side street, in its lane (traffic keeps
    // right), before the crossing: only where it stays off the road.
    double along =
        centre_along - 0.5 * c.band_length_m - lean - gap - 0.5 * length;
    double across = -0.25 * w;
    const bool fits_turning = along - 0.5 * length >= kerb + 0.3;
    if (!(turning && fits_turning)) {
      // Parked at the side street's kerb over the crossing's outer band.
      along = centre_along + shift * c.band_length_m;
      across = (left_kerb ? 1.0 : -1.0) * (0.5 * w - 0.5 * width - 0.1);
    }
    ParkedVehicle v;
    v.box.centre =
        street.axis_xy + along * street.direction + across * street.across();
    v.box.axis_u = street.direction;
    v.box.half_u = 0.5 * length;
    v.box.half_v = 0.5 * width;
    double s = 0.0, l = 0.0;
    road.ToRoadCoordinates(v.box.centre, c.s_m, &s, &l);
    v.box.z0 = GroundHeight(*world, v.box.centre, s, l) - 0.05;
    v.box.z1 = v.box.z0 + height;
    v.body_tone = tone;
    v.s0 = 1e300;
    v.s1 = -1e300;
    for (const Eigen::Vector2d& p : v.box.Footprint()) {
      road.ToRoadCoordinates(p, s, &s, &l);
      v.s0 = std::min(v.s0, s);
      v.s1 = std::max(v.s1, s);
    }
    v.occludes_crossing = true;
    v.salt = salt;
    c.occluded_by_vehicle = true;
    c.side_vehicle = turning && fits_turning ? "turning" : "parked";
    world->vehicles.push_back(v);
  }
}

}  // namespace world_internal
}  // namespace zebrageo::sim
