// The observations of the adjustment's state from its input
// (adjustment_observations.h).
#include "adjustment/adjustment_observations.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace zebrageo {
namespace adjustment_internal {
namespace {

// The band period vector of a database crossing: the least-squares slope
// of its bands' centres against their numbers (zero with fewer than two
// bands).
Eigen::Vector3d BandPeriodEnu(const RoadmarkDatabase& roadmarks,
                              const LocalFrame& frame,
                              const std::string& crossing_id) {
  std::vector<std::pair<double, Eigen::Vector3d>> centres;
  for (const RoadmarkBand& band : roadmarks.bands) {
    if (band.crossing_id != crossing_id) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Geodetic& corner : band.corners) {
      centre += frame.EnuFromGeodetic(corner) / 4.0;
    }
    centres.emplace_back(band.band, centre);
  }
  if (centres.size() < 2) return Eigen::Vector3d::Zero();
  double mean_n = 0.0;
  Eigen::Vector3d mean_c = Eigen::Vector3d::Zero();
  for (const auto& [n, c] : centres) {
    mean_n += n / centres.size();
    mean_c += c / centres.size();
  }
  double snn = 0.0;
  Eigen::Vector3d snc = Eigen::Vector3d::Zero();
  for (const auto& [n, c] : centres) {
    snn += (n - mean_n) * (n - mean_n);
    snc += (n - mean_n) * (c - mean_c);
  }
  return snn > 0.0 ? Eigen::Vector3d(snc / snn) : Eigen::Vector3d::Zero();
}

}  // namespace

CrossingTable AddControlPoints(const Context& context, State* state) {
  const AdjustmentInput& input = context.input;
  const AdjustmentOptions& options = context.options;
  const Rig& rig = *input.rig;
  std::unordered_map<int64_t, double> exposure_time;
  for (const Exposure& e : input.exposures->exposures) {
    exposure_time[e.exposure_id] = e.time;
  }
  std::map<std::tuple<int64_t, int64_t, int>, const ReconstructedVertex*>
      vertex_of;
  for (const ReconstructedVertex& v : *input.vertices) {
    vertex_of[{v.exposure_id, v.band_id, v.vertex}] = &v;
  }
  std::map<std::pair<std::string, int>, const RoadmarkBand*> band_of;
  for (const RoadmarkBand& b : input.roadmarks->bands) {
    band_of[{b.crossing_id, b.band}] = &b;
  }
  CrossingTable crossings;
  std::map<std::tuple<std::string, int, int>, int> point_of;
  std::map<std::string, int> crossing_of;
  int unknown_vertices = 0, unknown_bands = 0, bad_pairs = 0,
      outside_trajectory = 0;
  for (const VertexMatch& m : *input.matches) {
    const auto v = vertex_of.find({m.exposure_id, m.band_id, m.vertex});
    if (v == vertex_of.end()) {
      ++unknown_vertices;
      continue;
    }
    const auto b = band_of.find({m.crossing_id, m.band});
    if (b == band_of.end() || m.db_vertex < 0 || m.db_vertex > 3) {
      ++unknown_bands;
      continue;
    }
    const ReconstructedVertex& vertex = *v->second;
    if (vertex.pair < 0 ||
        vertex.pair >= static_cast<int>(rig.stereo_pairs.size())) {
      ++bad_pairs;
      continue;
    }
    const auto t = exposure_time.find(m.exposure_id);
    Pose ins_pose;
    if (t == exposure_time.end() || !context.InsPoseAt(t->second, &ins_pose)) {
      ++outside_trajectory;
      continue;
    }
    auto [it, inserted] = point_of.try_emplace(
        std::make_tuple(m.crossing_id, m.band, m.db_vertex),
        static_cast<int>(state->points.size()));
    if (inserted) {
      const RoadmarkBand& band = *b->second;
      ControlPoint p;
      p.crossing_id = m.crossing_id;
      p.band = m.band;
      p.db_vertex = m.db_vertex;
      auto [c, new_crossing] = crossing_of.try_emplace(
          m.crossing_id, static_cast<int>(crossings.names.size()));
      if (new_crossing) {
        crossings.names.push_back(m.crossing_id);
        crossings.first_time.push_back(t->second);
        crossings.period_enu.push_back(
            BandPeriodEnu(*input.roadmarks, *input.frame, m.crossing_id));
      }
      p.crossing = c->second;
      crossings.first_time[p.crossing] =
          std::min(crossings.first_time[p.crossing], t->second);
      p.database_enu = input.frame->EnuFromGeodetic(band.corners[m.db_vertex]);
      const double sxy =
          std::max(band.sigma_xy_m, options.control.min_database_sigma_m);
      const double sz =
          std::max(band.sigma_z_m, options.control.min_database_sigma_m);
      p.sigma_m = Eigen::Vector3d(sxy, sxy, sz);
      p.estimate = p.database_enu;
      state->points.push_back(p);
    }
    ControlPoint& p = state->points[it->second];
    const auto& pair = rig.stereo_pairs[vertex.pair];
    const int exposure = state->ExposureIndex(t->second);
    p.stereo.push_back(
        {t->second, exposure, ins_pose, vertex.p_body, vertex.covariance_body});
    p.observations.push_back(
        {t->second, pair[0], vertex.uv_left, ins_pose, 1.0, exposure});
    p.observations.push_back(
        {t->second, pair[1], vertex.uv_right, ins_pose, 1.0, exposure});
  }
  if (unknown_vertices > 0) {
    context.Warn(std::to_string(unknown_vertices) +
                 " rows of matches.csv name a vertex that is not in "
                 "reconstructed_bands.csv: ignored");
  }
  if (unknown_bands > 0) {
    context.Warn(std::to_string(unknown_bands) +
                 " rows of matches.csv name a database band or vertex that "
                 "is not in the road-mark database: ignored");
  }
  if (bad_pairs > 0) {
    context.Warn(std::to_string(bad_pairs) +
                 " matched vertices name a stereo pair that is not in "
                 "rig.yaml: ignored");
  }
  if (outside_trajectory > 0) {
    context.Warn(std::to_string(outside_trajectory) +
                 " matched vertices belong to exposures outside the "
                 "trajectory: ignored");
  }
  state->crossing_offsets.assign(crossings.names.size(),
                                 Eigen::Vector3d::Zero());
  return crossings;
}

void AddTieAndLinePoints(const Context& context, State* state) {
  const AdjustmentInput& input = context.input;
  const Rig& rig = *input.rig;
  if (input.tie_tracks != nullptr) {
    for (size_t i = 0; i < input.tie_tracks->size(); ++i) {
      const TieTrack& track = (*input.tie_tracks)[i];
      TiePoint tie;
      tie.estimate = track.p_enu;
      tie.source = static_cast<int>(i);
      for (const TieObservation& o : track.observations) {
        Pose ins_pose;
        if (o.camera < 0 || o.camera >= static_cast<int>(rig.cameras.size()) ||
            !context.InsPoseAt(o.time, &ins_pose)) {
          continue;
        }
        tie.observations.push_back({o.time, o.camera, o.uv, ins_pose, o.scale,
                                    state->ExposureIndex(o.time)});
      }
      if (tie.observations.size() >= 2) state->ties.push_back(tie);
    }
  }
  context.summary->num_tie_tracks = static_cast<int>(state->ties.size());
  if (input.line_points != nullptr) {
    for (const LineControlPoint& line : *input.line_points) {
      Pose ins_pose;
      if (context.InsPoseAt(line.time, &ins_pose)) {
        state->lines.push_back(
            {line, ins_pose, state->ExposureIndex(line.time)});
      }
    }
  }
}

}  // namespace adjustment_internal
}  // namespace zebrageo
