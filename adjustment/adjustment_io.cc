#include "adjustment/adjustment_io.h"

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tuple>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

std::string RequiredStageFile(const std::string& results_folder,
                              const char* name, const char* command) {
  const std::string path = (fs::path(results_folder) / name).string();
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    throw InputError(name, 0,
                     std::string("not found in ") + results_folder +
                         ": run `zebrageo " + command + "` first");
  }
  return path;
}

nlohmann::json Vector3Json(const Eigen::Vector3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

nlohmann::json SummaryJson(const AdjustmentData& data,
                           const AdjustmentOptions& options,
                           const AdjustmentResult& result,
                           const TiePointSummary* ties) {
  const AdjustmentSummary& s = result.summary;
  nlohmann::json j;
  j["usable"] = s.usable;
  j["message"] = s.message;
  j["sigma0"] = s.sigma0;
  j["iterations"] = s.iterations;
  j["solves"] = s.solves;
  j["time_s"] = s.time_in_seconds;
  j["counts"] = {
      {"exposures", s.num_exposures},
      {"trajectory_samples", data.trajectory.size()},
      {"knots", s.num_knots},
      {"control_vertices", s.num_control_points},
      {"check_vertices", s.num_check_points},
      {"rejected_vertices", s.num_rejected_points},
      {"control_crossings", s.num_control_crossings},
      {"check_crossings", s.num_check_crossings},
      {"tie_tracks", s.num_tie_tracks},
      {"residuals", s.num_residuals},
      {"reconstructed_vertices", data.vertices.size()},
      {"matches", data.matches.size()},
  };
  nlohmann::json rms = nlohmann::json::object();
  for (const ObservationRms& r : s.rms) {
    rms[r.type] = {{"unit", r.unit},
                   {"count", r.count},
                   {"before", r.before},
                   {"after", r.after}};
  }
  j["rms"] = rms;
  j["control_rmse_m"] = {{"horizontal", s.control_rmse_horizontal_m},
                         {"vertical", s.control_rmse_vertical_m}};
  // Check points are held out: their RMSE is the honest accuracy figure. It
  // includes the database's own error (its sigma and per-crossing offset).
  // No check point evaluated: null, so no one reads a perfect 0.
  const bool checked = s.num_check_points_evaluated > 0;
  j["check_rmse_m"] = {
      {"horizontal", checked ? nlohmann::json(s.check_rmse_horizontal_m)
                             : nlohmann::json(nullptr)},
      {"vertical", checked ? nlohmann::json(s.check_rmse_vertical_m)
                           : nlohmann::json(nullptr)},
      {"vertices", s.num_check_points},
      {"evaluated_vertices", s.num_check_points_evaluated},
      {"expected_from_database",
       {{"horizontal", checked
                           ? nlohmann::json(s.check_database_rms_horizontal_m)
                           : nlohmann::json(nullptr)},
        {"vertical", checked ? nlohmann::json(s.check_database_rms_vertical_m)
                             : nlohmann::json(nullptr)}}},
      {"implied_trajectory",
       {{"horizontal",
         checked ? nlohmann::json(s.check_implied_trajectory_horizontal_m)
                 : nlohmann::json(nullptr)},
        {"vertical", checked
                         ? nlohmann::json(s.check_implied_trajectory_vertical_m)
                         : nlohmann::json(nullptr)}}},
      {"note",
       "check residual = trajectory error + database error; "
       "implied_trajectory = sqrt(max(0, rmse^2 - expected_from_database^2)), "
       "for the adjustment made without the check crossings"},
      {"crossings", s.num_check_crossings},
      {"held_out_then_control", s.check_points_in_final}};
  j["correction_m"] = {{"max_horizontal", s.max_correction_horizontal_m},
                       {"max_vertical", s.max_correction_vertical_m},
                       {"rms_horizontal", s.rms_correction_horizontal_m}};
  j["posterior_sd_m"] = {
      {"computed", s.covariance_computed},
      {"median_horizontal", s.median_posterior_sd_horizontal_m},
      {"median_vertical", s.median_posterior_sd_vertical_m}};
  nlohmann::json rejected = nlohmann::json::array();
  for (const ControlPointResult& p : result.control_points) {
    if (p.status != ControlStatus::kRejected) continue;
    rejected.push_back(
        {{"crossing_id", p.crossing_id},
         {"band", p.band},
         {"vertex", p.db_vertex},
         {"normalized_residual", p.normalized_residual},
         {"d_enu_m", Vector3Json(p.image_enu - p.database_enu)}});
  }
  j["rejected"] = rejected;
  nlohmann::json rig = nlohmann::json::array();
  for (size_t c = 0; c < result.T_body_cam.size(); ++c) {
    const Eigen::Isometry3d& T = result.T_body_cam[c];
    const Eigen::AngleAxisd change(
        data.rig.cameras[c].T_body_cam.linear().transpose() * T.linear());
    rig.push_back({{"camera", data.rig.cameras[c].camera.name()},
                   {"lever_arm_m", Vector3Json(T.translation())},
                   {"boresight_change_deg", change.angle() * 180.0 / M_PI}});
  }
  j["rig"] = rig;
  j["model"] = {
      {"knot_spacing_s", options.knot_spacing_s},
      {"position_model_estimated", options.estimate_position_model},
      // Along-track, cross-track, up.
      {"position_sigma_m", Vector3Json(s.position_sigma_m)},
      {"position_tau_s", Vector3Json(s.position_tau_s)},
      {"attitude_sigma_deg", Vector3Json(RadToDeg(1.0) * s.attitude_sigma_rad)},
      {"vehicle_motion_sigma_deg",
       {RadToDeg(s.motion_sigma_rad.x()), RadToDeg(s.motion_sigma_rad.y())}},
      {"tie_sigma_px", s.tie_sigma_px},
      {"vertex_sigma_px", options.vertex_sigma_px},
      {"crossing_offset_sigma_m", options.crossing_offset_sigma_m},
      {"check_crossing_share", options.check_crossing_share},
      {"blunder_threshold", options.blunder_threshold},
      {"self_calibrate_rig", options.self_calibrate_rig},
  };
  if (ties != nullptr) {
    j["tie_points"] = {{"images_read", ties->images_read},
                       {"images_missing", ties->images_missing},
                       {"matches", ties->matches},
                       {"tracks", ties->tracks},
                       {"observations", ties->observations},
                       {"time_s", ties->time_in_seconds}};
  }
  std::vector<std::string> warnings = data.warnings;
  warnings.insert(warnings.end(), s.warnings.begin(), s.warnings.end());
  j["warnings"] = warnings;
  return j;
}

void WriteColmapExport(const AdjustmentData& data,
                       const AdjustmentResult& result,
                       const std::string& folder) {
  fs::create_directories(folder);
  const Rig& rig = data.rig;
  WriteFileAtomically(folder + "/cameras.txt", [&](std::ostream& out) {
    out << "# Camera list with one line of data per camera:\n"
           "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
           "# zebrageo rig cameras; FULL_OPENCV fx fy cx cy k1 k2 p1 p2 k3 k4 "
           "k5 k6 (cx, cy + 0.5: COLMAP pixel centres)\n";
    for (size_t c = 0; c < rig.cameras.size(); ++c) {
      const Camera& camera = rig.cameras[c].camera;
      const auto d = camera.distortion();
      out << c + 1 << " FULL_OPENCV " << camera.width() << " "
          << camera.height() << " " << FormatDouble(camera.fx()) << " "
          << FormatDouble(camera.fy()) << " " << FormatDouble(camera.cx() + 0.5)
          << " " << FormatDouble(camera.cy() + 0.5) << " " << FormatDouble(d[0])
          << " " << FormatDouble(d[1]) << " " << FormatDouble(d[2]) << " "
          << FormatDouble(d[3]) << " " << FormatDouble(d[4]) << " 0 0 0\n";
    }
  });
  // Points: control vertices (adjusted), then tie points. Observations are
  // found again per image: control observations are the matched vertices.
  struct Point {
    Eigen::Vector3d X;
    std::vector<std::pair<int, Eigen::Vector2d>> track;  // image, uv
  };
  std::vector<Point> points;
  std::map<std::pair<int64_t, int>, int> image_of;  // (exposure, camera)
  for (size_t i = 0; i < data.exposures.images.size(); ++i) {
    image_of[{data.exposures.images[i].exposure_id,
              data.exposures.images[i].camera}] = static_cast<int>(i);
  }
  {
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
  }
  for (const TieTrack& track : result.tie_tracks) {
    Point point{track.p_enu, {}};
    for (const TieObservation& o : track.observations) {
      point.track.emplace_back(o.image, o.uv);
    }
    points.push_back(point);
  }
  // Per image: its 2D points, and each point's (image, index) track.
  std::vector<std::vector<std::pair<Eigen::Vector2d, int>>> image_points(
      data.exposures.images.size());
  std::vector<std::vector<std::pair<int, int>>> tracks(points.size());
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
  std::map<std::pair<int64_t, std::string>, const CameraPose*> pose_of;
  for (const CameraPose& pose : result.camera_poses) {
    pose_of[{pose.exposure_id, pose.camera}] = &pose;
  }
  WriteFileAtomically(folder + "/images.txt", [&](std::ostream& out) {
    out << "# Image list with two lines of data per image:\n"
           "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
           "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
           "# World frame: the survey's ENU frame (metres).\n";
    for (size_t i = 0; i < data.exposures.images.size(); ++i) {
      const ExposureImage& image = data.exposures.images[i];
      const auto pose = pose_of.find(
          {image.exposure_id, rig.cameras[image.camera].camera.name()});
      if (pose == pose_of.end()) continue;
      // COLMAP stores cam_from_world.
      const Eigen::Quaterniond q = pose->second->q_enu_cam.conjugate();
      const Eigen::Vector3d t = -(q * pose->second->p_enu);
      out << i + 1 << " " << FormatDouble(q.w()) << " " << FormatDouble(q.x())
          << " " << FormatDouble(q.y()) << " " << FormatDouble(q.z()) << " "
          << FormatDouble(t.x()) << " " << FormatDouble(t.y()) << " "
          << FormatDouble(t.z()) << " " << image.camera + 1 << " "
          << image.image << "\n";
      bool first = true;
      for (const auto& [uv, point] : image_points[i]) {
        out << (first ? "" : " ") << FormatDouble(uv.x() + 0.5) << " "
            << FormatDouble(uv.y() + 0.5) << " " << point + 1;
        first = false;
      }
      out << "\n";
    }
  });
  WriteFileAtomically(folder + "/points3D.txt", [&](std::ostream& out) {
    out << "# 3D point list with one line of data per point:\n"
           "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, "
           "POINT2D_IDX)\n";
    for (size_t p = 0; p < points.size(); ++p) {
      const Eigen::Vector3d& X = points[p].X;
      out << p + 1 << " " << FormatDouble(X.x()) << " " << FormatDouble(X.y())
          << " " << FormatDouble(X.z()) << " 255 255 255 0";
      for (const auto& [image, index] : tracks[p]) {
        out << " " << image + 1 << " " << index;
      }
      out << "\n";
    }
  });
}

}  // namespace

AdjustmentInput AdjustmentData::Input() const {
  AdjustmentInput input;
  input.rig = &rig;
  input.frame = &frame;
  input.trajectory = &trajectory;
  input.exposures = &exposures;
  input.roadmarks = &roadmarks;
  input.vertices = &vertices;
  input.matches = &matches;
  return input;
}

AdjustmentData LoadAdjustmentData(const std::string& survey_folder,
                                  const std::string& results_folder,
                                  const SurveyPathOptions& paths) {
  AdjustmentData data;
  data.survey_folder = survey_folder;
  data.manifest = ReadManifest(survey_folder, paths);
  auto path_of = [&](const std::string& name) {
    return (fs::path(survey_folder) / name).string();
  };
  data.rig = ReadRig(path_of(data.manifest.rig), data.manifest.rig);
  std::vector<TrajectorySample> samples =
      ReadSurveyTrajectory(survey_folder, data.manifest);
  data.frame =
      LocalFrame(data.manifest.origin.value_or(samples.front().position));
  data.trajectory = Trajectory(std::move(samples), data.frame);
  data.exposures = ReadExposures(path_of(data.manifest.exposures),
                                 data.manifest.exposures, data.rig);
  for (const ExposureImage& image : data.exposures.images) {
    if (!data.trajectory.Covers(image.time)) {
      throw InputError(data.manifest.exposures, image.line,
                       "exposure " + std::to_string(image.exposure_id) +
                           " at time " + FormatDouble(image.time) +
                           " is outside the trajectory's span");
    }
    std::error_code error;
    if (!fs::is_regular_file(path_of(image.image), error))
      ++data.missing_images;
  }
  if (data.missing_images > 0 &&
      data.missing_images < static_cast<int>(data.exposures.images.size())) {
    data.warnings.push_back(std::to_string(data.missing_images) + " of " +
                            std::to_string(data.exposures.images.size()) +
                            " images are missing: no tie points in them");
  }
  data.roadmarks = ReadSurveyRoadmarks(survey_folder, data.manifest,
                                       data.trajectory.samples());
  data.vertices = ReadReconstructedBands(
      RequiredStageFile(results_folder, kReconstructedBandsFile, "reconstruct"),
      kReconstructedBandsFile);
  data.matches = ReadMatches(
      RequiredStageFile(results_folder, kMatchesFile, "match"), kMatchesFile);
  return data;
}

void WriteGcpResidualsWithStatus(const std::vector<ControlPointResult>& points,
                                 const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    CsvWriter csv(&out);
    csv.Comment(
        "d* = adjusted (control) or image-only (check, rejected) minus "
        "database, metres ENU; status: control | check | rejected (blunder, "
        "removed from the adjustment)");
    csv.Header({"crossing_id", "band", "vertex", "role", "de", "dn", "du",
                "d3d", "rms_px", "n_images", "status", "normalized_residual"});
    for (const ControlPointResult& p : points) {
      const Eigen::Vector3d d = p.adjusted_enu - p.database_enu;
      csv.Add(p.crossing_id)
          .Add(p.band)
          .Add(p.db_vertex)
          .Add(p.status == ControlStatus::kCheck ? "check" : "control")
          .AddFixed(d.x(), 4)
          .AddFixed(d.y(), 4)
          .AddFixed(d.z(), 4)
          .AddFixed(d.norm(), 4)
          .AddFixed(p.rms_px, 3)
          .Add(p.n_images)
          .Add(ControlStatusName(p.status))
          .AddFixed(p.normalized_residual, 2);
      csv.EndRow();
    }
  });
}

void WriteAdjustmentResults(const AdjustmentData& data,
                            const AdjustmentOptions& options,
                            const AdjustmentResult& result,
                            const TiePointSummary* tie_summary,
                            const std::string& results_folder) {
  fs::create_directories(results_folder);
  auto out = [&](const char* name) {
    return (fs::path(results_folder) / name).string();
  };
  WriteColmapExport(data, result, out(kColmapFolder));
  WriteGcpResidualsWithStatus(result.control_points, out(kGcpResidualsFile));
  WriteAdjustedBands(result.bands, out(kBandsGeoJsonFile));
  const nlohmann::json summary =
      SummaryJson(data, options, result, tie_summary);
  WriteFileAtomically(out(kAdjustmentJsonFile), [&](std::ostream& stream) {
    stream << summary.dump(2) << "\n";
  });
  nlohmann::json report;
  report["survey"] = data.manifest.name;
  report["stage"] = "adjust";
  report["note"] =
      "minimal report written by `zebrageo adjust`; `zebrageo report` "
      "replaces it";
  report["counts"] = summary["counts"];
  report["rms"] = summary["rms"];
  report["check_rmse_m"] = summary["check_rmse_m"];
  report["timings_s"] = {{"adjust", result.summary.time_in_seconds}};
  report["adjustment"] = summary;
  report["warnings"] = summary["warnings"];
  WriteFileAtomically(out(kReportJsonFile), [&](std::ostream& stream) {
    stream << report.dump(2) << "\n";
  });
  // The trajectory and the poses last: their presence means the stage
  // finished.
  WriteTrajectorySamples(result.corrected_samples,
                         out(kTrajectoryCorrectedFile));
  WriteCameraPoses(result.camera_poses, out(kPosesFile));
}

namespace {

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

int RemoveRejectedMatches(const AdjustmentData& data,
                          const AdjustmentResult& result,
                          const std::string& results_folder) {
  const auto rejected = RejectedVertices(result);
  if (rejected.empty()) return 0;
  std::set<std::string> rejected_crossings;
  for (const auto& vertex : rejected) {
    rejected_crossings.insert(std::get<0>(vertex));
  }
  const std::vector<VertexMatch> kept =
      MatchesKeptAsControl(data.matches, result);
  std::map<int64_t, int> kept_per_exposure;
  for (const VertexMatch& m : kept) ++kept_per_exposure[m.exposure_id];
  std::set<int64_t> touched;
  for (const VertexMatch& m : data.matches) {
    if (rejected.count({m.crossing_id, m.band, m.db_vertex})) {
      touched.insert(m.exposure_id);
    }
  }
  const int removed = static_cast<int>(data.matches.size() - kept.size());
  if (removed == 0) return 0;
  const fs::path folder(results_folder);
  std::string names;
  for (const std::string& id : rejected_crossings) {
    names += (names.empty() ? "" : " ") + id;
  }
  WriteMatches(kept,
               {"zebrageo adjust removed " + std::to_string(removed) +
                " vertex matches the adjustment rejected (crossings " + names +
                "; gcp_residuals.csv, report.json warnings)"},
               (folder / kMatchesFile).string());
  const fs::path decisions_path = folder / kCrossingDecisionsFile;
  if (fs::exists(decisions_path)) {
    std::vector<CrossingDecision> decisions =
        ReadCrossingDecisions(decisions_path.string(), kCrossingDecisionsFile);
    for (CrossingDecision& d : decisions) {
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
    WriteCrossingDecisions(decisions, {"zebrageo match, then adjust"},
                           decisions_path.string());
  }
  return removed;
}

}  // namespace zebrageo
