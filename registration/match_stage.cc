#include "registration/match_stage.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "registration/paint_probe.h"
#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/results_adjustment.h"

namespace zebrageo {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Rounded for a person; positions keep full precision.
double Round(double value, double unit) {
  return std::round(value / unit) * unit;
}

json Position(const LocalFrame& frame, const Eigen::Vector3d& p_enu) {
  const Geodetic g = frame.GeodeticFromEnu(p_enu);
  return json::array({g.lon_deg, g.lat_deg, Round(g.h_m, 1e-4)});
}

json FeatureOf(json geometry, json properties) {
  return json{{"type", "Feature"},
              {"geometry", std::move(geometry)},
              {"properties", std::move(properties)}};
}

// The trajectory's claimed horizontal sd at `time` (the larger of the two
// bracketing samples, the larger of east and north).
double ClaimedHorizontalSd(const Trajectory& trajectory, double time) {
  const int i = trajectory.FindSegment(time);
  if (i < 0) return 0.0;
  double sd = 0.0;
  for (int k = i; k <= i + 1; ++k) {
    const TrajectorySample& s = trajectory.samples()[k];
    sd = std::max({sd, s.sd_enu_m.x(), s.sd_enu_m.y()});
  }
  return sd;
}

}  // namespace

std::vector<CrossingObservation> BuildObservations(
    const Survey& survey, const std::vector<ReconstructedVertex>& vertices,
    const std::string& display_name, int* incomplete_bands) {
  std::map<int64_t, double> time_of_exposure;
  for (const Exposure& exposure : survey.exposures.exposures) {
    time_of_exposure[exposure.exposure_id] = exposure.time;
  }
  // (exposure, group) -> band_id -> vertices, in file order.
  std::map<std::pair<int64_t, int64_t>,
           std::map<int64_t, std::vector<const ReconstructedVertex*>>>
      groups;
  std::vector<std::pair<int64_t, int64_t>> order;
  for (const ReconstructedVertex& v : vertices) {
    if (!time_of_exposure.count(v.exposure_id)) {
      throw InputError(display_name, 0,
                       "band_id " + std::to_string(v.band_id) +
                           ": exposure_id " + std::to_string(v.exposure_id) +
                           " is not in " + survey.manifest.exposures);
    }
    if (v.pair < 0 ||
        v.pair >= static_cast<int>(survey.rig.stereo_pairs.size())) {
      throw InputError(display_name, 0,
                       "band_id " + std::to_string(v.band_id) + ": pair " +
                           std::to_string(v.pair) +
                           " is not a stereo pair of " + survey.manifest.rig);
    }
    const auto key = std::make_pair(v.exposure_id, v.group_id);
    if (!groups.count(key)) order.push_back(key);
    groups[key][v.band_id].push_back(&v);
  }
  int incomplete = 0;
  std::vector<CrossingObservation> observations;
  for (const auto& key : order) {
    CrossingObservation obs;
    obs.exposure_id = key.first;
    obs.group_id = key.second;
    obs.time_s = time_of_exposure[key.first];
    // Exposures were checked to lie inside the trajectory by LoadSurvey.
    if (!survey.trajectory.InterpolatePose(obs.time_s, &obs.pose)) {
      throw InputError(display_name, 0,
                       "exposure " + std::to_string(key.first) +
                           " is outside the trajectory");
    }
    obs.sd_horizontal_m = ClaimedHorizontalSd(survey.trajectory, obs.time_s);
    for (const auto& [band_id, list] : groups[key]) {
      if (list.size() != 4) {
        ++incomplete;
        continue;
      }
      std::vector<const ReconstructedVertex*> sorted = list;
      std::sort(sorted.begin(), sorted.end(),
                [](const ReconstructedVertex* a, const ReconstructedVertex* b) {
                  return a->vertex < b->vertex;
                });
      ObservedBand band;
      band.band_id = band_id;
      band.pair = sorted[0]->pair;
      double score = 1.0;
      for (int k = 0; k < 4; ++k) {
        band.vertex[k] = sorted[k]->vertex;
        band.p_body[k] = sorted[k]->p_body;
        score = std::min(score, sorted[k]->score);
      }
      band.score = score;
      obs.bands.push_back(band);
    }
    observations.push_back(std::move(obs));
  }
  if (incomplete_bands != nullptr) *incomplete_bands = incomplete;
  return observations;
}

std::vector<ExposurePose> ExposurePoses(const Survey& survey) {
  std::vector<ExposurePose> poses;
  for (const Exposure& exposure : survey.exposures.exposures) {
    ExposurePose pose;
    pose.exposure_id = exposure.exposure_id;
    pose.time_s = exposure.time;
    if (survey.trajectory.InterpolatePose(exposure.time, &pose.pose)) {
      poses.push_back(pose);
    }
  }
  return poses;
}

void WriteMatchEvidence(const MatchResult& result, const MatchOptions& options,
                        const std::vector<std::string>& warnings,
                        const LocalFrame& frame, const std::string& path) {
  const MatchSummary& s = result.summary;
  json root;
  root["summary"] = {{"observations", s.observations},
                     {"matched", s.matched},
                     {"refused", s.refused},
                     {"no_candidate", s.no_candidate},
                     {"ambiguous", s.ambiguous},
                     {"inconsistent", s.inconsistent},
                     {"resolved_by_neighbours", s.resolved_by_neighbours},
                     {"vertex_matches", s.vertex_matches},
                     {"crossings_matched", s.crossings_matched},
                     {"faults", s.faults},
                     {"seconds", Round(s.seconds, 1e-3)},
                     {"report", s.BriefReport()}};
  root["warnings"] = warnings;
  root["options"] = {
      {"max_drift_m", options.max_drift_m},
      {"sd_gate_factor", options.sd_gate_factor},
      {"max_heading_error_rad", options.max_heading_error_rad},
      {"hit_tolerance_m", options.hit_tolerance_m},
      {"vertex_tolerance_m", options.vertex_tolerance_m},
      {"missing_band_weight", options.missing_band_weight},
      {"max_missing_views", options.max_missing_views},
      {"contradiction_weight", options.contradiction_weight},
      {"unexplained_band_weight", options.unexplained_band_weight},
      {"visibility_margin_px", options.visibility_margin_px},
      {"visibility_safety_px", options.visibility_safety_px},
      {"visibility_range_m", options.visibility_range_m},
      {"window_s", options.window_s},
      {"same_correction_tolerance_m", options.same_correction_tolerance_m},
      {"drift_rate_m_per_s", options.drift_rate_m_per_s},
      {"min_hit_bands", options.min_hit_bands},
      {"min_margin", options.min_margin},
      {"min_strong_margin", options.min_strong_margin},
      {"probe_range_m", options.probe_range_m},
      {"require_both_ends", options.require_both_ends},
      {"resolve_base_m", options.resolve_base_m},
      {"max_drift_per_metre", options.max_drift_per_metre},
      {"max_drift_acceleration_m_per_s2",
       options.max_drift_acceleration_m_per_s2},
      {"max_resolve_bound_m", options.max_resolve_bound_m},
      {"max_exclusion_bound_m", options.max_exclusion_bound_m},
      {"max_sd_ratio", options.max_sd_ratio},
      {"neighbour_window_s", options.neighbour_window_s},
      {"neighbour_tolerance_m", options.neighbour_tolerance_m},
      {"max_drift_rate_m_per_s", options.max_drift_rate_m_per_s},
      {"max_informative_tolerance_m", options.max_informative_tolerance_m},
      {"shifted_crossing_threshold_m", options.shifted_crossing_threshold_m},
      {"refuse_shifted_crossings", options.refuse_shifted_crossings},
      {"min_views_for_fault", options.min_views_for_fault}};
  json observations = json::array();
  for (const ObservationEvidence& e : result.evidence) {
    json o = {{"exposure_id", e.exposure_id},
              {"group_id", e.group_id},
              {"time", e.time_s},
              {"decision", DecisionName(e.decision)},
              {"crossing_id",
               e.crossing_id.empty() ? json(nullptr) : json(e.crossing_id)},
              {"reason", e.reason},
              {"bands", e.bands},
              {"usable_bands", e.usable_bands},
              {"candidate_db_bands", e.candidate_db_bands},
              {"hypotheses", e.hypotheses},
              {"hits", e.hits},
              {"missing", e.missing},
              {"contradictions", e.contradictions},
              {"unexplained", e.unexplained},
              {"own_score", Round(e.own_score, 1e-3)},
              {"aggregated_score", Round(e.aggregated_score, 1e-3)},
              {"resolved_by_neighbours", e.resolved_by_neighbours}};
    if (e.has_runner_up) {
      o["runner_up"] = {{"what", e.runner_up},
                        {"score", Round(e.runner_up_score, 1e-3)},
                        {"margin", Round(e.robust_margin, 1e-3)},
                        {"both_ends_margin", Round(e.both_ends_margin, 1e-3)}};
    }
    if (e.hypotheses > 0) {
      o["correction"] = {
          {"de_m", Round(e.correction.shift_enu_m.x(), 1e-4)},
          {"dn_m", Round(e.correction.shift_enu_m.y(), 1e-4)},
          {"dheading_deg", Round(RadToDeg(e.correction.heading_rad), 1e-4)}};
    }
    if (e.decision == Decision::kMatched) {
      o["matched_bands"] = e.matched_bands;
      o["vertex_matches"] = e.vertex_matches;
      o["vertex_rms_m"] = Round(e.vertex_rms_m, 1e-4);
    }
    observations.push_back(std::move(o));
  }
  root["observations"] = std::move(observations);
  json faults = json::array();
  for (const DatabaseFault& f : result.faults) {
    const Geodetic g = frame.GeodeticFromEnu(
        Eigen::Vector3d(f.location_enu.x(), f.location_enu.y(), 0.0));
    json fault = {{"kind", FaultKindName(f.kind)},
                  {"crossing_id",
                   f.crossing_id.empty() ? json(nullptr) : json(f.crossing_id)},
                  {"views", f.views},
                  {"exposure_ids", f.exposure_ids},
                  {"east", Round(f.location_enu.x(), 1e-3)},
                  {"north", Round(f.location_enu.y(), 1e-3)},
                  {"lat", g.lat_deg},
                  {"lon", g.lon_deg},
                  {"description", f.description}};
    if (f.band != 0) fault["band"] = f.band;
    if (f.kind == FaultKind::kCrossingShifted) {
      fault["shift_m"] = Round(f.shift_m, 1e-3);
    }
    faults.push_back(std::move(fault));
  }
  root["faults"] = std::move(faults);
  WriteFileAtomically(path,
                      [&](std::ostream& out) { out << root.dump(1) << "\n"; });
}

void WriteMatchesGeoJson(const MatchInput& input, const MatchResult& result,
                         const LocalFrame& frame, const std::string& path) {
  const RoadmarkIndex& index = *input.index;
  // (crossing_id, band) -> database band.
  std::map<std::pair<std::string, int>, int> db_band;
  for (size_t b = 0; b < index.bands().size(); ++b) {
    db_band[{index.bands()[b].crossing_id, index.bands()[b].band}] =
        static_cast<int>(b);
  }
  // (exposure_id, band_id) -> observation and band.
  std::map<std::pair<int64_t, int64_t>, std::pair<int, int>> observed;
  for (size_t o = 0; o < input.observations.size(); ++o) {
    const CrossingObservation& obs = input.observations[o];
    for (size_t b = 0; b < obs.bands.size(); ++b) {
      observed[{obs.exposure_id, obs.bands[b].band_id}] = {static_cast<int>(o),
                                                           static_cast<int>(b)};
    }
  }
  json features = json::array();
  std::set<std::pair<int64_t, int64_t>> bands_drawn;
  for (const VertexMatch& m : result.matches) {
    const auto found = observed.find({m.exposure_id, m.band_id});
    const auto db = db_band.find({m.crossing_id, m.band});
    if (found == observed.end() || db == db_band.end()) continue;
    const int o = found->second.first;
    const CrossingObservation& obs = input.observations[o];
    const ObservedBand& band = obs.bands[found->second.second];
    const ObservationEvidence& ev = result.evidence[o];
    int k = 0;
    while (k < 3 && band.vertex[k] != m.vertex) ++k;
    const Eigen::Vector3d measured =
        obs.pose.q_enu_body * band.p_body[k] + obs.pose.p_enu;
    const Eigen::Vector3d corrected =
        CorrectedEnu(obs.pose, ev.correction, band.p_body[k]);
    const Eigen::Vector3d& corner =
        index.bands()[db->second].corners_enu[m.db_vertex];
    features.push_back(FeatureOf(
        {{"type", "LineString"},
         {"coordinates",
          json::array({Position(frame, measured), Position(frame, corner)})}},
        {{"kind", "vertex_match"},
         {"exposure_id", m.exposure_id},
         {"band_id", m.band_id},
         {"vertex", m.vertex},
         {"crossing_id", m.crossing_id},
         {"band", m.band},
         {"db_vertex", m.db_vertex},
         {"drift_m", Round((measured - corner).head<2>().norm(), 1e-3)},
         {"residual_m", Round((corrected - corner).head<2>().norm(), 1e-4)}}));
    if (bands_drawn.insert({m.exposure_id, m.band_id}).second) {
      json ring = json::array();
      for (int v = 0; v <= 4; ++v) {
        ring.push_back(Position(
            frame, CorrectedEnu(obs.pose, ev.correction, band.p_body[v % 4])));
      }
      features.push_back(
          FeatureOf({{"type", "Polygon"}, {"coordinates", json::array({ring})}},
                    {{"kind", "matched_band_corrected"},
                     {"exposure_id", m.exposure_id},
                     {"band_id", m.band_id},
                     {"crossing_id", m.crossing_id},
                     {"band", m.band}}));
    }
  }
  for (const DatabaseFault& f : result.faults) {
    features.push_back(
        FeatureOf({{"type", "Point"},
                   {"coordinates",
                    Position(frame, Eigen::Vector3d(f.location_enu.x(),
                                                    f.location_enu.y(), 0.0))}},
                  {{"kind", "database_fault"},
                   {"fault", FaultKindName(f.kind)},
                   {"crossing_id", f.crossing_id.empty() ? json(nullptr)
                                                         : json(f.crossing_id)},
                   {"band", f.band == 0 ? json(nullptr) : json(f.band)},
                   {"views", f.views},
                   {"description", f.description}}));
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    // One feature per line: diffable, and QGIS reads it as it is.
    out << "{\"type\": \"FeatureCollection\", \"features\": [\n";
    for (size_t i = 0; i < features.size(); ++i) {
      out << (i > 0 ? ",\n" : "") << features[i].dump();
    }
    out << "\n]}\n";
  });
}

MatchResult RunMatchStage(const Survey& survey,
                          const std::string& results_folder,
                          const MatchOptions& options,
                          const PaintProbeOptions& paint_probe,
                          const std::function<void(int, int)>& progress) {
  const std::string input_path =
      (fs::path(results_folder) / kReconstructedBandsFile).string();
  std::error_code error;
  if (!fs::is_regular_file(input_path, error)) {
    throw InputError(
        kReconstructedBandsFile, 0,
        "missing in " + results_folder + " (run `zebrageo reconstruct` first)");
  }
  return RunMatchStage(
      survey, ReadReconstructedBands(input_path, kReconstructedBandsFile),
      results_folder, options, paint_probe, progress);
}

MatchResult RunMatchStage(const Survey& survey,
                          const std::vector<ReconstructedVertex>& vertices,
                          const std::string& results_folder,
                          const MatchOptions& options,
                          const PaintProbeOptions& paint_probe,
                          const std::function<void(int, int)>& progress) {
  int incomplete = 0;
  MatchInput input;
  input.observations =
      BuildObservations(survey, vertices, kReconstructedBandsFile, &incomplete);
  input.exposures = ExposurePoses(survey);
  const RoadmarkIndex index(survey.roadmarks, survey.frame);
  input.index = &index;
  input.rig = &survey.rig;
  ImagePaintProbe probe(survey, paint_probe);
  input.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                               const BandCornersEnu& band,
                               const std::vector<BandCornersEnu>& seen) {
    return probe.Classify(exposure_id, pose, band, seen);
  };
  std::vector<std::string> warnings;
  if (incomplete > 0) {
    warnings.push_back(std::to_string(incomplete) +
                       " reconstructed band(s) have fewer than 4 vertices and "
                       "were not matched");
    LOG(WARNING) << warnings.back();
  }
  if (index.bands().empty()) {
    warnings.push_back(
        "the road-mark database has no zebra band: nothing "
        "can be matched");
    LOG(WARNING) << warnings.back();
  }
  MatchResult result = MatchBands(input, options, progress);
  if (!result.summary.IsUsable()) return result;
  if (result.summary.matched == 0 && !input.observations.empty()) {
    warnings.push_back("no reconstructed crossing could be matched");
    LOG(WARNING) << warnings.back();
  }
  const std::vector<std::string> comments = {"zebrageo match: " +
                                             result.summary.BriefReport()};
  fs::create_directories(results_folder);
  WriteMatches(result.matches, comments,
               (fs::path(results_folder) / kMatchesFile).string());
  WriteCrossingDecisions(
      result.decisions, comments,
      (fs::path(results_folder) / kCrossingDecisionsFile).string());
  WriteMatchEvidence(result, options, warnings, survey.frame,
                     (fs::path(results_folder) / kMatchEvidenceFile).string());
  WriteMatchesGeoJson(
      input, result, survey.frame,
      (fs::path(results_folder) / kMatchesGeoJsonFile).string());
  return result;
}

}  // namespace zebrageo
