#include "pipeline/adjust_outputs.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

// A 3D point of the COLMAP export and its observations.
struct ColmapPoint {
  Eigen::Vector3d X;
  std::vector<std::pair<int, Eigen::Vector2d>> track;  // image, uv
};

// The index of each image of the exposure table by (exposure, camera).
std::map<std::pair<int64_t, int>, int> ImageIndexOf(
    const ExposureTable& exposures) {
  std::map<std::pair<int64_t, int>, int> image_of;
  for (size_t i = 0; i < exposures.images.size(); ++i) {
    image_of[{exposures.images[i].exposure_id, exposures.images[i].camera}] =
        static_cast<int>(i);
  }
  return image_of;
}

// The control vertices (adjusted), observed where their matched vertices
// were seen: in both images of the vertex's stereo pair.
std::vector<ColmapPoint> ControlPointsForColmap(
    const AdjustmentData& data, const AdjustmentResult& result) {
  const Rig& rig = data.rig;
  const std::map<std::pair<int64_t, int>, int> image_of =
      ImageIndexOf(data.exposures);
  std::vector<ColmapPoint> points;
  std::map<std::tuple<std::string, int, int>, int> index;
  for (const ControlPointResult& p : result.control_points) {
    if (p.status != ControlStatus::kControl) continue;
    index[{p.crossing_id, p.band, p.db_vertex}] =
        static_cast<int>(points.size());
    points.push_back({p.adjusted_enu, {}});
  }
  std::map<std::tuple<int64_t, int64_t, int>, const ReconstructedVertex*>
      vertex_of;
  for (const ReconstructedVertex& v : data.vertices) {
    vertex_of[{v.exposure_id, v.band_id, v.vertex}] = &v;
  }
  for (const VertexMatch& m : data.matches) {
    const auto p = index.find({m.crossing_id, m.band, m.db_vertex});
    const auto v = vertex_of.find({m.exposure_id, m.band_id, m.vertex});
    if (p == index.end() || v == vertex_of.end()) continue;
    const ReconstructedVertex& vertex = *v->second;
    if (vertex.pair < 0 ||
        vertex.pair >= static_cast<int>(rig.stereo_pairs.size())) {
      continue;
    }
    for (int side = 0; side < 2; ++side) {
      const auto image =
          image_of.find({m.exposure_id, rig.stereo_pairs[vertex.pair][side]});
      if (image == image_of.end()) continue;
      points[p->second].track.emplace_back(
          image->second, side == 0 ? vertex.uv_left : vertex.uv_right);
    }
  }
  return points;
}

// The observations of a COLMAP model both ways: per image, its 2D points
// (uv, point); per point, its track (image, index of the 2D point).
struct ColmapObservations {
  std::vector<std::vector<std::pair<Eigen::Vector2d, int>>> image_points;
  std::vector<std::vector<std::pair<int, int>>> tracks;
};

ColmapObservations ObservationsOf(const std::vector<ColmapPoint>& points,
                                  size_t num_images) {
  ColmapObservations observations;
  auto& image_points = observations.image_points;
  auto& tracks = observations.tracks;
  image_points.resize(num_images);
  tracks.resize(points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    std::map<int, int> seen;  // one observation per image
    for (const auto& [image, uv] : points[p].track) {
      if (seen.count(image)) continue;
      seen[image] = 1;
      tracks[p].emplace_back(image,
                             static_cast<int>(image_points[image].size()));
      image_points[image].emplace_back(uv, static_cast<int>(p));
    }
  }
  return observations;
}

std::set<std::tuple<std::string, int, int>> RejectedVertices(
    const AdjustmentResult& result) {
  std::set<std::tuple<std::string, int, int>> rejected;
  for (const ControlPointResult& p : result.control_points) {
    if (p.status != ControlStatus::kRejected) continue;
    rejected.insert({p.crossing_id, p.band, p.db_vertex});
  }
  return rejected;
}

}  // namespace

AdjustmentRecord AdjustmentRecordOf(const AdjustmentData& data,
                                    const AdjustmentOptions& options,
                                    const AdjustmentResult& result,
                                    const TiePointSummary* ties) {
  const AdjustmentSummary& s = result.summary;
  AdjustmentRecord r;
  r.usable = s.usable;
  r.message = s.message;
  r.sigma0 = s.sigma0;
  r.iterations = s.iterations;
  r.solves = s.solves;
  r.time_s = s.time_in_seconds;
  r.counts = {s.num_exposures,
              data.trajectory.size(),
              s.num_knots,
              s.num_control_points,
              s.num_check_points,
              s.num_rejected_points,
              s.num_control_crossings,
              s.num_check_crossings,
              s.num_tie_tracks,
              s.num_residuals,
              static_cast<int64_t>(data.vertices.size()),
              static_cast<int64_t>(data.matches.size())};
  for (const ObservationRms& rms : s.rms) {
    r.rms[rms.type] = {rms.unit, rms.count, rms.before, rms.after};
  }
  r.control_rmse_horizontal_m = s.control_rmse_horizontal_m;
  r.control_rmse_vertical_m = s.control_rmse_vertical_m;
  r.check = {s.check_rmse_horizontal_m,
             s.check_rmse_vertical_m,
             s.num_check_points,
             s.num_check_points_evaluated,
             s.check_database_rms_horizontal_m,
             s.check_database_rms_vertical_m,
             s.check_implied_trajectory_horizontal_m,
             s.check_implied_trajectory_vertical_m,
             s.num_check_crossings,
             s.check_points_in_final};
  r.max_correction_horizontal_m = s.max_correction_horizontal_m;
  r.max_correction_vertical_m = s.max_correction_vertical_m;
  r.rms_correction_horizontal_m = s.rms_correction_horizontal_m;
  r.road_lines_only = s.line_control_only;
  r.posterior_sd_computed = s.covariance_computed;
  r.median_posterior_sd_horizontal_m = s.median_posterior_sd_horizontal_m;
  r.median_posterior_sd_vertical_m = s.median_posterior_sd_vertical_m;
  for (const WeakStretch& w : s.weak_stretches) {
    r.weakly_held.push_back({TrackAxisName(w.axis), w.begin_time_s,
                             w.end_time_s, w.length_m, w.threshold_m,
                             w.max_sd_m, w.median_sd_m, w.held_by_no_control});
  }
  for (const ControlPointResult& p : result.control_points) {
    if (p.status != ControlStatus::kRejected) continue;
    r.rejected.push_back({p.crossing_id, p.band, p.db_vertex,
                          p.normalized_residual, p.image_enu - p.database_enu});
  }
  for (size_t c = 0; c < result.T_body_cam.size(); ++c) {
    const Eigen::Isometry3d& T = result.T_body_cam[c];
    const Eigen::AngleAxisd change(
        data.rig.cameras[c].T_body_cam.linear().transpose() * T.linear());
    r.rig.push_back({data.rig.cameras[c].camera.name(), T.translation(),
                     RadToDeg(change.angle())});
  }
  AdjustmentRecord::Model& m = r.model;
  m.knot_spacing_s = options.model.knot_spacing_s;
  m.position_model_estimated = options.model.estimate_position_model;
  // Along-track, cross-track, up.
  m.position_sigma_m = s.position_sigma_m;
  m.position_tau_s = s.position_tau_s;
  m.attitude_sigma_deg = RadToDeg(1.0) * s.attitude_sigma_rad;
  m.attitude_significance = s.attitude_significance;
  for (int a = 0; a < 3; ++a) m.attitude_held[a] = s.attitude_held[a] != 0;
  m.vehicle_motion_sigma_deg = Eigen::Vector2d(
      RadToDeg(s.motion_sigma_rad.x()), RadToDeg(s.motion_sigma_rad.y()));
  m.tie_sigma_px = s.tie_sigma_px;
  m.vertex_sigma_px = options.control.vertex_sigma_px;
  m.crossing_offset_sigma_m = options.control.crossing_offset_sigma_m;
  m.check_crossing_share = options.control.check_crossing_share;
  m.blunder_threshold = options.blunders.blunder_threshold;
  m.self_calibrate_rig = options.rig_calibration.self_calibrate_rig;
  if (ties != nullptr) {
    r.tie_points = AdjustmentRecord::TiePoints{
        ties->images_read, ties->images_missing, ties->matches,
        ties->tracks,      ties->observations,   ties->time_in_seconds};
  }
  for (const GuardVerdict& v : s.guard_verdicts) {
    r.guard.crossings.push_back(
        {v.id, v.used, v.input_misfit_m, v.adjusted_misfit_m, v.z, v.worse});
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto finite = [nan](double t) { return std::isfinite(t) ? t : nan; };
  for (const KeptStretch& k : s.kept_input) {
    r.guard.input_kept.push_back({finite(k.ramp_begin_s), finite(k.begin_s),
                                  finite(k.end_s), finite(k.ramp_end_s),
                                  k.crossings, k.input_misfit_m,
                                  k.adjusted_misfit_m});
  }
  r.warnings = data.warnings;
  r.warnings.insert(r.warnings.end(), s.warnings.begin(), s.warnings.end());
  return r;
}

std::vector<GcpResidual> GcpResidualsOf(
    const std::vector<ControlPointResult>& points) {
  std::vector<GcpResidual> residuals;
  for (const ControlPointResult& p : points) {
    GcpResidual r;
    r.crossing_id = p.crossing_id;
    r.band = p.band;
    r.vertex = p.db_vertex;
    r.role =
        p.status == ControlStatus::kCheck ? GcpRole::kCheck : GcpRole::kControl;
    r.d_enu = p.adjusted_enu - p.database_enu;
    r.rms_px = p.rms_px;
    r.n_images = p.n_images;
    r.status = p.status == ControlStatus::kRejected ? GcpStatus::kRejected
               : p.status == ControlStatus::kCheck  ? GcpStatus::kCheck
                                                    : GcpStatus::kControl;
    r.normalized_residual = p.normalized_residual;
    residuals.push_back(r);
  }
  return residuals;
}

ColmapModel ColmapModelOf(const AdjustmentData& data,
                          const AdjustmentResult& result) {
  ColmapModel model;
  model.camera_notes = {
      "zebrageo rig cameras; FULL_OPENCV fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6 "
      "(cx, cy + 0.5: COLMAP pixel centres)"};
  char origin[160];
  std::snprintf(origin, sizeof(origin),
                "World frame: the survey's ENU frame (metres), origin at "
                "latitude %.9f, longitude %.9f degrees, height %.4f m "
                "(WGS84 ellipsoidal).",
                data.frame.origin().lat_deg, data.frame.origin().lon_deg,
                data.frame.origin().h_m);
  model.image_notes = {origin};
  const Rig& rig = data.rig;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const Camera& camera = rig.cameras[c].camera;
    const auto d = camera.distortion();
    model.cameras.push_back(
        {static_cast<int64_t>(c + 1),
         "FULL_OPENCV",
         camera.width(),
         camera.height(),
         {camera.fx(), camera.fy(), camera.cx() + 0.5, camera.cy() + 0.5, d[0],
          d[1], d[2], d[3], d[4], 0.0, 0.0, 0.0}});
  }
  // Points: control vertices (adjusted), then tie points. Observations are
  // found again per image: control observations are the matched vertices.
  std::vector<ColmapPoint> points = ControlPointsForColmap(data, result);
  for (const TieTrack& track : result.tie_tracks) {
    ColmapPoint point{track.p_enu, {}};
    for (const TieObservation& o : track.observations) {
      point.track.emplace_back(o.image, o.uv);
    }
    points.push_back(point);
  }
  const ColmapObservations observations =
      ObservationsOf(points, data.exposures.images.size());
  // The adjusted pose of each image that has one, and its 2D points.
  std::map<std::pair<int64_t, std::string>, const CameraPose*> pose_of;
  for (const CameraPose& pose : result.camera_poses) {
    pose_of[{pose.exposure_id, pose.camera}] = &pose;
  }
  std::vector<const CameraPose*> image_pose(data.exposures.images.size());
  for (size_t i = 0; i < data.exposures.images.size(); ++i) {
    const ExposureImage& image = data.exposures.images[i];
    const auto pose = pose_of.find(
        {image.exposure_id, rig.cameras[image.camera].camera.name()});
    if (pose != pose_of.end()) image_pose[i] = pose->second;
  }
  for (size_t i = 0; i < data.exposures.images.size(); ++i) {
    const ExposureImage& image = data.exposures.images[i];
    const CameraPose* const pose = image_pose[i];
    if (pose == nullptr) continue;
    ColmapImage colmap;
    colmap.id = static_cast<int64_t>(i + 1);
    // COLMAP stores cam_from_world.
    colmap.q = pose->q_enu_cam.conjugate();
    colmap.t = -(colmap.q * pose->p_enu);
    colmap.camera_id = image.camera + 1;
    colmap.name = image.image;
    for (const auto& [uv, point] : observations.image_points[i]) {
      colmap.points2d.emplace_back(uv + Eigen::Vector2d(0.5, 0.5), point + 1);
    }
    model.images.push_back(std::move(colmap));
  }
  for (size_t p = 0; p < points.size(); ++p) {
    ColmapPoint3D point;
    point.id = static_cast<int64_t>(p + 1);
    point.X = points[p].X;
    // COLMAP's ERROR: the mean reprojection error of the track, pixels.
    double error_sum = 0.0;
    int error_count = 0;
    for (const auto& [image, index] : observations.tracks[p]) {
      point.track.emplace_back(image + 1, index);
      const CameraPose* pose = image_pose[image];
      if (pose == nullptr) continue;
      const Camera& camera =
          rig.cameras[data.exposures.images[image].camera].camera;
      Eigen::Vector2d uv;
      if (camera.Project(pose->q_enu_cam.conjugate() * (point.X - pose->p_enu),
                         &uv)) {
        error_sum +=
            (uv - observations.image_points[image][index].first).norm();
        ++error_count;
      }
    }
    point.error = error_count > 0 ? error_sum / error_count : 0.0;
    model.points.push_back(std::move(point));
  }
  return model;
}

std::set<std::string> RejectedCrossings(const AdjustmentResult& result) {
  std::set<std::string> crossings;
  for (const auto& vertex : RejectedVertices(result)) {
    crossings.insert(std::get<0>(vertex));
  }
  return crossings;
}

std::vector<VertexMatch> MatchesKeptAsControl(
    const std::vector<VertexMatch>& matches, const AdjustmentResult& result) {
  const auto rejected = RejectedVertices(result);
  std::vector<VertexMatch> kept;
  for (const VertexMatch& m : matches) {
    if (!rejected.count({m.crossing_id, m.band, m.db_vertex})) {
      kept.push_back(m);
    }
  }
  return kept;
}

int RemoveRejectedMatches(const AdjustmentResult& result,
                          std::vector<VertexMatch>* matches,
                          std::vector<CrossingDecision>* decisions,
                          std::string* rejected_crossings) {
  const auto rejected = RejectedVertices(result);
  if (rejected.empty()) return 0;
  std::vector<VertexMatch> kept = MatchesKeptAsControl(*matches, result);
  const int removed = static_cast<int>(matches->size() - kept.size());
  if (removed == 0) return 0;
  rejected_crossings->clear();
  for (const std::string& id : RejectedCrossings(result)) {
    *rejected_crossings += (rejected_crossings->empty() ? "" : " ") + id;
  }
  std::map<int64_t, int> kept_per_exposure;
  for (const VertexMatch& m : kept) ++kept_per_exposure[m.exposure_id];
  std::set<int64_t> touched;
  for (const VertexMatch& m : *matches) {
    if (rejected.count({m.crossing_id, m.band, m.db_vertex})) {
      touched.insert(m.exposure_id);
    }
  }
  *matches = std::move(kept);
  for (CrossingDecision& d : *decisions) {
    if (d.decision != Decision::kMatched || !touched.count(d.exposure_id) ||
        kept_per_exposure.count(d.exposure_id)) {
      continue;
    }
    d.reason = "matched to " + d.crossing_id +
               ", then rejected by the adjustment: inconsistent with the "
               "other crossings and the trajectory (report.json warnings); "
               "was: " +
               d.reason;
    d.decision = Decision::kRefused;
    d.crossing_id.clear();
  }
  return removed;
}

}  // namespace zebrageo
