// Buildings along the road, parked vehicles (some over a crossing's end
// bands) and the shadows they all cast, each from its own generator.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"
#include "survey/math_util.h"

namespace zebrageo::sim::world_internal {
namespace {

std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(),
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
              return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
            });
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                  const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) -
           (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

Shadow CastShadow(const VerticalBox& box, double ground_z,
                  const Eigen::Vector3d& sun, float factor) {
  const double height = box.z1 - ground_z;
  const Eigen::Vector2d offset =
      -height * Eigen::Vector2d(sun.x(), sun.y()) / sun.z();
  std::vector<Eigen::Vector2d> points;
  for (const Eigen::Vector2d& p : box.Footprint()) {
    points.push_back(p);
    points.push_back(p + offset);
  }
  Shadow shadow;
  shadow.polygon = ConvexHull(points);
  shadow.factor = factor;
  return shadow;
}

bool VehicleFits(const World& world, double s0, double s1, double side) {
  if (NearCrossing(world, s0, s1, 0.5)) return false;
  for (const ParkedVehicle& v : world.vehicles) {
    const double v_side =
        (v.box.centre - world.road.Centre(0.5 * (v.s0 + v.s1)))
            .dot(world.road.LeftNormal(0.5 * (v.s0 + v.s1)));
    if ((v_side > 0) == (side > 0) && s1 > v.s0 - 0.8 && s0 < v.s1 + 0.8) {
      return false;
    }
  }
  return true;
}

ParkedVehicle MakeVehicle(const Road& road, double s, double side,
                          double length, std::mt19937_64* rng) {
  ParkedVehicle v;
  const double l = side * (0.5 * road.width_m() + 0.1);
  v.box.centre = road.Centre(s) + l * road.LeftNormal(s);
  v.box.axis_u = road.Tangent(s);
  v.box.half_u = 0.5 * length;
  v.box.half_v = 0.5 * Uniform(rng, 1.7, 1.9);
  v.box.z0 = road.Height(s, l) - 0.05;
  v.box.z1 = v.box.z0 + Uniform(rng, 1.4, 1.75);
  v.body_tone = static_cast<float>(Uniform(rng, 25.0, 225.0));
  v.s0 = s - 0.5 * length;
  v.s1 = s + 0.5 * length;
  v.salt = (*rng)();
  return v;
}

}  // namespace

void BuildFacades(const SimulationOptions& options, World* world) {
  if (!options.facades) return;
  std::mt19937_64 rng(SubSeed(options.seed, kBuildingSeed));
  const Road& road = world->road;
  const double front = 0.5 * road.width_m() + options.sidewalk_width_m;
  for (double side : {-1.0, 1.0}) {
    double s = -10.0;
    while (s < road.length_m() + 10.0) {
      const double length = Uniform(&rng, 8.0, 26.0);
      const double depth = Uniform(&rng, 10.0, 15.0);
      const double height = Uniform(&rng, 7.0, 20.0);
      const double gap = Bernoulli(&rng, options.facade_gap_probability)
                             ? Uniform(&rng, 3.0, 8.0)
                             : 0.0;
      const double s0 = s, s1 = s + length;
      s = s1 + gap;
      const Eigen::Vector2d a =
          road.Centre(s0) + side * front * road.LeftNormal(s0);
      const Eigen::Vector2d b =
          road.Centre(s1) + side * front * road.LeftNormal(s1);
      Building building;
      building.s0 = s0;
      building.s1 = s1;
      VerticalBox& box = building.box;
      box.axis_u = (b - a).normalized();
      box.half_u = 0.5 * (b - a).norm();
      box.half_v = 0.5 * depth;
      box.centre = 0.5 * (a + b) + side * 0.5 * depth * box.axis_v();
      const double ground = std::min(
          {road.Height(s0, side * front), road.Height(s1, side * front),
           road.Height(0.5 * (s0 + s1), side * front)});
      box.z0 = ground - 0.5;
      box.z1 = ground + height;
      building.front_side = side > 0 ? -1 : 1;
      building.wall_tone = static_cast<float>(Uniform(&rng, 110.0, 185.0));
      building.window_tone = static_cast<float>(Uniform(&rng, 30.0, 60.0));
      building.window_period_m =
          options.window_period_m * Uniform(&rng, 0.9, 1.1);
      building.window_width_m =
          building.window_period_m * Uniform(&rng, 0.38, 0.55);
      building.window_height_m = Uniform(&rng, 1.3, 1.7);
      building.sill_height_m = Uniform(&rng, 0.8, 1.0);
      building.floor_height_m = Uniform(&rng, 2.9, 3.3);
      building.ground_floor_height_m = Uniform(&rng, 3.6, 4.5);
      const double face = 2.0 * box.half_u;
      building.window_offset_m =
          0.5 * (std::fmod(face, building.window_period_m) +
                 building.window_period_m - building.window_width_m);
      building.shop_front = Bernoulli(&rng, 0.5);
      building.salt = rng();
      world->buildings.push_back(building);
    }
  }
}

void ParkVehicles(const SimulationOptions& options, World* world) {
  std::mt19937_64 rng(SubSeed(options.seed, kVehicleSeed));
  const Road& road = world->road;
  // Vehicles hiding the outer bands of a crossing from the approach.
  for (int ci = 0; ci < static_cast<int>(world->crossings.size()); ++ci) {
    Crossing& c = world->crossings[ci];
    if (c.side_street >= 0) continue;  // ParkAtSideCrossings
    const bool want = Bernoulli(&rng, options.occluding_vehicle_probability);
    const double length = Uniform(&rng, 4.0, 4.8);
    const double gap = Uniform(&rng, 0.6, 1.5);
    if (!want || !c.in_street) continue;
    const double s = c.s_min - gap - 0.5 * length;
    if (!VehicleFits(*world, s - 0.5 * length, s + 0.5 * length, -1.0)) {
      continue;
    }
    ParkedVehicle v = MakeVehicle(road, s, -1.0, length, &rng);
    v.occludes_crossing = true;
    c.occluded_by_vehicle = true;
    world->vehicles.push_back(v);
  }
  const int count = PoissonCount(
      &rng, options.parked_vehicles_per_100m * world->road.length_m() / 100.0);
  for (int i = 0; i < count; ++i) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const double length = Uniform(&rng, 4.0, 4.8);
      const double s = Uniform(&rng, 3.0, road.length_m() - 3.0);
      const double side = Bernoulli(&rng, 0.5) ? 1.0 : -1.0;
      if (!VehicleFits(*world, s - 0.5 * length, s + 0.5 * length, side)) {
        continue;
      }
      world->vehicles.push_back(MakeVehicle(road, s, side, length, &rng));
      break;
    }
  }
}

// Vehicles parked at the kerb over a crossing's first or last band (after
// every other vehicle, from their own generator: the other presets' streets
// do not change with end_band_vehicle_probability).
void ParkOverEndBands(const SimulationOptions& options, World* world) {
  if (options.end_band_vehicle_probability <= 0.0) return;
  std::mt19937_64 rng(SubSeed(options.seed, kVehicleSeed, 2));
  const Road& road = world->road;
  const double half_width = 0.5 * road.width_m();
  for (Crossing& c : world->crossings) {
    if (c.side_street >= 0) continue;  // ParkAtSideCrossings
    const bool want = Bernoulli(&rng, options.end_band_vehicle_probability);
    const bool first = Bernoulli(&rng, 0.5);
    const double length = Uniform(&rng, 4.0, 4.8);
    const double along = Uniform(&rng, -1.0, 1.0);
    // Its inner side 0.8-1.2 m from the kerb: over the outer band (0.25 m
    // from the kerb, 0.5 m wide), not over the next one.
    const double inner = Uniform(&rng, 0.8, 1.2);
    if (!want || !c.in_street || c.num_street_bands < 2) continue;
    const int band = first ? 1 : c.num_street_bands;
    const double o =
        c.first_offset_m + (band - 1) * c.band_period_m + 0.5 * c.band_width_m;
    const double side = o < 0.0 ? -1.0 : 1.0;
    // Only an outer band at the kerb can be under a parked vehicle, and not
    // where the survey vehicle drives (its lane, with 1.8 m to spare).
    if (half_width - std::abs(o) > 1.0) continue;
    if (side * world->lane_offset_m > 0.0 &&
        half_width - inner < std::abs(world->lane_offset_m) + 1.8) {
      continue;
    }
    const double s = c.s_m + o * c.tan_skew + along;
    ParkedVehicle v = MakeVehicle(road, s, side, length, &rng);
    const double l_centre = side * (half_width - inner + v.box.half_v);
    v.box.centre = road.Centre(s) + l_centre * road.LeftNormal(s);
    v.box.z0 = road.Height(s, l_centre) - 0.05;
    v.occludes_crossing = true;
    c.end_band_vehicle = first ? "first" : "last";
    world->vehicles.push_back(v);
  }
}

void CastShadows(const SimulationOptions& options, World* world) {
  if (!options.shadows || world->sun_enu.z() < 0.05) return;
  const Road& road = world->road;
  for (const Building& b : world->buildings) {
    world->shadows.push_back(
        CastShadow(b.box, b.box.z0 + 0.5, world->sun_enu, 0.45f));
  }
  for (const ParkedVehicle& v : world->vehicles) {
    double s = 0.0, l = 0.0;
    road.ToRoadCoordinates(v.box.centre, 0.5 * (v.s0 + v.s1), &s, &l);
    world->shadows.push_back(CastShadow(
        v.box, GroundHeight(*world, v.box.centre, s, l), world->sun_enu, 0.5f));
    // Contact shadow under the body.
    VerticalBox under = v.box;
    under.half_u += 0.15;
    under.half_v += 0.15;
    under.z1 = under.z0;
    Shadow contact;
    for (const Eigen::Vector2d& p : under.Footprint()) {
      contact.polygon.push_back(p);
    }
    contact.factor = 0.55f;
    world->shadows.push_back(contact);
  }
}

}  // namespace zebrageo::sim::world_internal
