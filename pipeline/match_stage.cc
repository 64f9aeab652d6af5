#include "pipeline/match_stage.h"

#include <glog/logging.h>

#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/exit_codes.h"
#include "registration/band_matcher.h"
#include "registration/observations.h"
#include "registration/paint_probe.h"
#include "registration/roadmark_index.h"
#include "survey/option_json.h"
#include "survey/output_crs.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

// The options match_evidence.json records: the search's gates and the
// decision's weights.
nlohmann::json EvidenceOptions(const MatchOptions& options) {
  static const char* const kRecorded[] = {"max_drift_m",
                                          "sd_gate_factor",
                                          "max_heading_error_rad",
                                          "hit_tolerance_m",
                                          "vertex_tolerance_m",
                                          "missing_band_weight",
                                          "max_missing_views",
                                          "contradiction_weight",
                                          "unexplained_band_weight",
                                          "visibility_margin_px",
                                          "visibility_safety_px",
                                          "visibility_range_m",
                                          "window_s",
                                          "same_correction_tolerance_m",
                                          "drift_rate_m_per_s",
                                          "min_hit_bands",
                                          "min_margin",
                                          "min_strong_margin",
                                          "probe_range_m",
                                          "require_both_ends",
                                          "resolve_base_m",
                                          "max_drift_per_metre",
                                          "max_drift_acceleration_m_per_s2",
                                          "max_resolve_bound_m",
                                          "max_exclusion_bound_m",
                                          "max_sd_ratio",
                                          "neighbour_window_s",
                                          "neighbour_tolerance_m",
                                          "max_drift_rate_m_per_s",
                                          "max_informative_tolerance_m",
                                          "shifted_crossing_threshold_m",
                                          "refuse_shifted_crossings",
                                          "min_views_for_fault"};
  const nlohmann::json all = OptionsToJson(options);
  nlohmann::json recorded = nlohmann::json::object();
  for (const char* name : kRecorded) recorded[name] = all.at(name);
  return recorded;
}

// matches.geojson's vertices: each matched vertex where the measured pose
// and the corrected one place it, and its database corner; the band,
// corrected, on the first vertex of each band.
std::vector<MatchedVertexFeature> MatchedVertexFeatures(
    const MatchInput& input, const MatchResult& result) {
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
  std::vector<MatchedVertexFeature> features;
  std::set<std::pair<int64_t, int64_t>> bands_drawn;
  for (const VertexMatch& m : result.matches) {
    const auto found = observed.find({m.exposure_id, m.band_id});
    const auto db = db_band.find({m.crossing_id, m.band});
    if (found == observed.end() || db == db_band.end()) continue;
    const CrossingObservation& obs = input.observations[found->second.first];
    const ObservedBand& band = obs.bands[found->second.second];
    const PoseCorrection& correction =
        result.evidence[found->second.first].correction;
    int k = 0;
    while (k < 3 && band.vertex[k] != m.vertex) ++k;
    MatchedVertexFeature f;
    f.match = m;
    f.measured_enu = obs.pose.q_enu_body * band.p_body[k] + obs.pose.p_enu;
    f.corrected_enu = CorrectedEnu(obs.pose, correction, band.p_body[k]);
    f.database_enu = index.bands()[db->second].corners_enu[m.db_vertex];
    if (bands_drawn.insert({m.exposure_id, m.band_id}).second) {
      std::array<Eigen::Vector3d, 4> corners;
      for (int v = 0; v < 4; ++v) {
        corners[v] = CorrectedEnu(obs.pose, correction, band.p_body[v]);
      }
      f.corrected_band_enu = corners;
    }
    features.push_back(std::move(f));
  }
  return features;
}

// The warnings match_evidence.json lists (also in the log).
std::vector<std::string> MatchWarnings(const RoadmarkIndex& index,
                                       int incomplete) {
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
  return warnings;
}

}  // namespace

MatchSummary RunMatchStage(const Survey& survey, StageResults* results,
                           const RunOptions& options,
                           const std::function<void(int, int)>& progress,
                           const CancellationToken& cancel) {
  const std::unique_ptr<OutputCrs> crs = OutputCrs::Of(survey);
  int incomplete = 0;
  MatchInput input;
  input.observations = BuildObservations(survey, results->Vertices(),
                                         kReconstructedBandsFile, &incomplete);
  input.exposures = ExposurePoses(survey);
  const RoadmarkIndex index(survey.roadmarks, survey.frame);
  input.index = &index;
  input.rig = &survey.rig;
  ImagePaintProbe probe(survey, options.paint_probe);
  input.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                               const BandCornersEnu& band,
                               const std::vector<BandCornersEnu>& seen) {
    return probe.Classify(exposure_id, pose, band, seen);
  };
  std::vector<std::string> warnings = MatchWarnings(index, incomplete);
  MatchResult result = MatchBands(input, options.matching, progress, cancel);
  if (!result.summary.IsUsable()) {
    throw StageFailedError("match: " + result.summary.message);
  }
  if (result.summary.matched == 0 && !input.observations.empty()) {
    warnings.push_back("no reconstructed crossing could be matched");
    LOG(WARNING) << warnings.back();
  }
  cancel.ThrowIfCancelled();
  const std::vector<std::string> comments = WithSurveyIdentity(
      survey.exposures, {"zebrageo match: " + result.summary.BriefReport()});
  WriteMatches(result.matches, comments, results->PathOf(kMatchesFile),
               crs.get());
  WriteCrossingDecisions(result.decisions, comments,
                         results->PathOf(kCrossingDecisionsFile));
  WriteMatchEvidence(result, EvidenceOptions(options.matching), warnings,
                     survey.frame, results->PathOf(kMatchEvidenceFile));
  WriteMatchesGeoJson(MatchedVertexFeatures(input, result), result.faults,
                      survey.frame, results->folder(), crs.get());
  LOG(INFO) << "match: " << result.summary.BriefReport();
  results->SetMatches(std::move(result.matches), std::move(result.decisions));
  return result.summary;
}

}  // namespace zebrageo
