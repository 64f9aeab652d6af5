// The road marks as they are (truth/roadmarks.geojson) and as the
// database holds them (roadmarks.geojson: corners with noise, stale and
// repainted crossings, line gaps and moved stretches).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"
#include "survey/math_util.h"

namespace zebrageo::sim {

using world_internal::kDatabaseSeed;
using world_internal::StopLineBefore;
using world_internal::Subtract;

namespace {

// Samples of a line at constant l over [s0, s1], every `step` metres.
std::vector<Eigen::Vector3d> SampleLine(const Road& road, double l, double s0,
                                        double s1, double step) {
  std::vector<Eigen::Vector3d> points;
  const int n = std::max(1, static_cast<int>(std::ceil((s1 - s0) / step)));
  for (int i = 0; i <= n; ++i) {
    points.push_back(road.SurfacePoint(s0 + (s1 - s0) * i / n, l));
  }
  return points;
}

struct LineGeometry {
  std::string id;
  std::string type;
  std::vector<Eigen::Vector3d> points;
};

std::vector<LineGeometry> LineGeometries(const World& world) {
  std::vector<LineGeometry> out;
  int dash = 0, solid = 0;
  for (const LinePiece& line : world.lines) {
    const bool dashed = line.type == "lane_dashed";
    out.push_back({dashed ? "dash-" + std::to_string(++dash)
                          : "solid-" + std::to_string(++solid),
                   line.type,
                   SampleLine(world.road, line.l_m, line.s0, line.s1,
                              dashed ? 1.0 : 2.0)});
  }
  for (const StopLine& stop : world.stop_lines) {
    const Road& road = world.road;
    out.push_back({"stop-" + world.crossings[stop.crossing].id,
                   "stop_line",
                   {road.SurfacePoint(stop.s_m, stop.l0),
                    road.SurfacePoint(stop.s_m, stop.l1)}});
  }
  return out;
}

// The database's copy of the lines: the street's, without the gaps, with
// the moved stretches at their old position, plus the removed stop lines.
std::vector<LineGeometry> DatabaseLineGeometries(
    const World& world, const SimulationOptions& options) {
  const std::vector<LineGeometry> street = LineGeometries(world);
  std::vector<LineGeometry> out;
  const Road& road = world.road;
  for (size_t i = 0; i < world.lines.size(); ++i) {
    const LinePiece& line = world.lines[i];
    const double step = line.type == "lane_dashed" ? 1.0 : 2.0;
    std::vector<std::pair<double, double>> gaps, not_here;
    std::vector<const DatabaseLineFault*> moved;
    for (const DatabaseLineFault& f : world.database_line_faults) {
      if (std::abs(f.l_m - line.l_m) > 1e-6) continue;
      if (f.kind == "gap") gaps.push_back({f.s0, f.s1});
      if (f.kind == "gap" || f.kind == "moved")
        not_here.push_back({f.s0, f.s1});
      if (f.kind == "moved") moved.push_back(&f);
    }
    std::vector<LineGeometry> pieces;
    for (const auto& [s0, s1] : Subtract(line.s0, line.s1, not_here)) {
      pieces.push_back(
          {"", line.type, SampleLine(road, line.l_m, s0, s1, step)});
    }
    for (const DatabaseLineFault* f : moved) {
      const double s0 = std::max(line.s0, f->s0);
      const double s1 = std::min(line.s1, f->s1);
      for (const auto& [a, b] : Subtract(s0, s1, gaps)) {
        pieces.push_back({"", line.type,
                          SampleLine(road, line.l_m + f->shift_m, a, b, step)});
      }
    }
    // A piece shorter than half a metre is not something an aerial survey
    // would digitise.
    int k = 0;
    for (LineGeometry& piece : pieces) {
      const double length = (piece.points.back() - piece.points.front()).norm();
      if (length < 0.5) continue;
      piece.id =
          street[i].id + (pieces.size() > 1 ? "." + std::to_string(++k) : "");
      out.push_back(std::move(piece));
    }
  }
  for (size_t i = world.lines.size(); i < street.size(); ++i) {
    out.push_back(street[i]);  // the stop lines
  }
  for (const DatabaseLineFault& f : world.database_line_faults) {
    if (f.kind != "removed") continue;
    const StopLine stop = StopLineBefore(world, f.crossing, options);
    out.push_back({"stop-" + world.crossings[f.crossing].id,
                   "stop_line",
                   {road.SurfacePoint(stop.s_m, stop.l0),
                    road.SurfacePoint(stop.s_m, stop.l1)}});
  }
  return out;
}

}  // namespace

RoadmarkDatabase MakeTruthRoadmarks(const World& world,
                                    const LocalFrame& frame) {
  RoadmarkDatabase db;
  for (const Band& band : world.bands) {
    RoadmarkBand out;
    out.crossing_id = world.crossings[band.crossing].id;
    out.band = band.band;
    for (int k = 0; k < 4; ++k) {
      out.corners[k] = frame.GeodeticFromEnu(band.corners[k]);
    }
    db.bands.push_back(out);
  }
  for (const LineGeometry& line : LineGeometries(world)) {
    RoadmarkLine out;
    out.id = line.id;
    out.type = line.type;
    for (const Eigen::Vector3d& p : line.points) {
      out.points.push_back(frame.GeodeticFromEnu(p));
    }
    db.lines.push_back(out);
  }
  return db;
}

RoadmarkDatabase MakeDatabaseRoadmarks(const World& world,
                                       const SimulationOptions& options,
                                       const LocalFrame& frame) {
  std::mt19937_64 rng(SubSeed(options.seed, kDatabaseSeed));
  const double sxy = options.database_sigma_xy_m;
  const double sz = options.database_sigma_z_m;
  auto noise = [&]() {
    const double e = Gaussian(&rng, sxy);
    const double n = Gaussian(&rng, sxy);
    return Eigen::Vector3d(e, n, Gaussian(&rng, sz));
  };
  // The side streets' crossings draw their noise from their own generator:
  // the rest of the database does not change with the junctions.
  std::mt19937_64 side_rng(SubSeed(options.seed, kDatabaseSeed, 8));
  auto side_noise = [&]() {
    const double e = Gaussian(&side_rng, sxy);
    const double n = Gaussian(&side_rng, sxy);
    return Eigen::Vector3d(e, n, Gaussian(&side_rng, sz));
  };
  RoadmarkDatabase db;
  for (const Crossing& c : world.crossings) {
    if (!c.in_db) continue;
    const Eigen::Vector2d origin = c.origin_xy - c.repaint_shift_xy;
    for (int k = 1; k <= c.num_db_bands; ++k) {
      if (std::find(c.db_missing_bands.begin(), c.db_missing_bands.end(), k) !=
              c.db_missing_bands.end() ||
          IsIslandBand(c, k)) {
        continue;  // the gap keeps the street's numbering
      }
      const auto corners = DesignBandCorners(world, c, k, origin);
      RoadmarkBand out;
      out.crossing_id = c.id;
      out.band = k;
      out.sigma_xy_m = sxy;
      out.sigma_z_m = sz;
      for (int v = 0; v < 4; ++v) {
        out.corners[v] =
            frame.GeodeticFromEnu(corners[v] + c.db_offset_enu +
                                  (c.side_street < 0 ? noise() : side_noise()));
      }
      db.bands.push_back(out);
    }
  }
  for (const LineGeometry& line : DatabaseLineGeometries(world, options)) {
    RoadmarkLine out;
    out.id = line.id;
    out.type = line.type;
    out.sigma_xy_m = sxy;
    out.sigma_z_m = sz;
    for (const Eigen::Vector3d& p : line.points) {
      out.points.push_back(frame.GeodeticFromEnu(p + noise()));
    }
    db.lines.push_back(out);
  }
  return db;
}

}  // namespace zebrageo::sim
