// MatchBands: the five steps of band_matcher_internal.h in order, and the
// public types' methods.
#include "registration/band_matcher.h"

#include <glog/logging.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "registration/band_matcher_internal.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

using band_matcher_internal::MatchState;

MatchResult RunSteps(const MatchInput& input, const MatchOptions& options,
                     const std::function<void(int, int)>& progress,
                     const CancellationToken& cancel) {
  namespace internal = band_matcher_internal;
  const auto start = std::chrono::steady_clock::now();
  MatchState state(input, options);
  // 1. Hypotheses per observation.
  internal::PrepareObservations(&state);
  const int n = static_cast<int>(state.obs.size());
  state.hypotheses.assign(n, {});
  state.candidate_bands.assign(n, 0);
  state.chosen.assign(n, -1);
  state.accepted.assign(n, false);
  state.ambiguous.assign(n, false);
  state.unbeaten_offsets.assign(n, {});
  state.evidence.assign(n, ObservationEvidence());
  for (int o = 0; o < n; ++o) {
    cancel.ThrowIfCancelled();
    const CrossingObservation& source = input.observations[o];
    ObservationEvidence& ev = state.evidence[o];
    ev.exposure_id = source.exposure_id;
    ev.group_id = source.group_id;
    ev.time_s = source.time_s;
    ev.bands = static_cast<int>(source.bands.size());
    ev.usable_bands = state.obs[o].usable;
    internal::GenerateHypotheses(o, &state);
    if (progress && (o % 64 == 0 || o + 1 == n)) progress(o + 1, n);
  }
  // 2. Their evidence over the window.
  state.window.assign(n, {0, 0});
  internal::Aggregate(&state);
  // 3. Each observation alone. Only observations whose match survives
  // refinement may vouch for their neighbours.
  for (int o = 0; o < n; ++o) internal::DecideAlone(o, &state);
  for (int o = 0; o < n; ++o) {
    if (state.accepted[o]) internal::RefuseUnrefined(o, &state);
  }
  // 4. Continuity across crossings.
  internal::CheckContinuity(&state);
  internal::ResolveFromNeighbours(&state);
  internal::DetectShiftedCrossings(&state);
  // 5. Vertex matches and findings.
  for (int o : state.by_time) {
    if (state.accepted[o]) internal::EmitMatches(o, &state);
  }
  internal::DetectFaults(&state);
  MatchResult result;
  result.summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  internal::Finish(&state, &result);
  return result;
}

}  // namespace

std::string MatchOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_drift_m, 0.0);
  OPTION_GE(check, sd_gate_factor, 0.0);
  OPTION_GE(check, max_cross_track_m, 0.0);
  OPTION_GT(check, max_heading_error_rad, 0.0);
  OPTION_REQUIRE(check, max_heading_error_rad < 0.5, max_heading_error_rad,
                 "must be < 0.5 (bands would pair with crossings of other "
                 "roads)");
  OPTION_GT(check, min_band_length_m, 0.0);
  OPTION_LT(check, min_band_length_m, max_band_length_m);
  OPTION_GT(check, min_band_width_m, 0.0);
  OPTION_LT(check, min_band_width_m, max_band_width_m);
  OPTION_GT(check, max_length_difference_m, 0.0);
  OPTION_GT(check, max_width_difference_m, 0.0);
  OPTION_GT(check, hit_tolerance_m, 0.0);
  OPTION_REQUIRE(check, hit_tolerance_m < 0.5, hit_tolerance_m,
                 "must be < 0.5 (half the band period, or neighbouring bands "
                 "would explain each other)");
  OPTION_GT(check, vertex_tolerance_m, 0.0);
  OPTION_GE(check, missing_band_weight, 0.0);
  OPTION_GT(check, max_missing_views, 0);
  OPTION_GE(check, contradiction_weight, 0.0);
  OPTION_GE(check, unexplained_band_weight, 0.0);
  OPTION_GE(check, max_unexplained_per_hit, 0.0);
  OPTION_GE(check, visibility_margin_px, 0.0);
  OPTION_GE(check, visibility_safety_px, 0.0);
  OPTION_GE(check, visibility_range_m, 0.0);
  OPTION_GE(check, window_s, 0.0);
  OPTION_GT(check, same_correction_tolerance_m, 0.0);
  OPTION_GE(check, drift_rate_m_per_s, 0.0);
  OPTION_GT(check, min_margin, 0.0);
  OPTION_GE(check, min_strong_margin, 0.0);
  OPTION_GT(check, probe_range_m, 0.0);
  OPTION_GE(check, neighbour_window_s, 0.0);
  OPTION_GT(check, neighbour_tolerance_m, 0.0);
  OPTION_GE(check, max_drift_rate_m_per_s, 0.0);
  OPTION_GT(check, max_informative_tolerance_m, 0.0);
  OPTION_GE(check, resolve_base_m, 0.0);
  OPTION_GE(check, max_drift_per_metre, 0.0);
  OPTION_GE(check, max_drift_acceleration_m_per_s2, 0.0);
  OPTION_GE(check, max_resolve_bound_m, 0.0);
  OPTION_GE(check, max_exclusion_bound_m, 0.0);
  OPTION_GT(check, max_sd_ratio, 0.0);
  OPTION_GT(check, shifted_crossing_threshold_m, 0.0);
  OPTION_GE(check, min_hit_bands, 1);
  OPTION_GE(check, min_views_for_fault, 1);
  return check.problem();
}

Eigen::Vector3d CorrectedEnu(const Pose& measured,
                             const PoseCorrection& correction,
                             const Eigen::Vector3d& p_body) {
  const Pose pose = band_matcher_internal::CorrectedPose(measured, correction);
  return pose.q_enu_body * p_body + pose.p_enu;
}

MatchResult MatchBands(const MatchInput& input, const MatchOptions& options,
                       const std::function<void(int, int)>& progress,
                       const CancellationToken& cancel) {
  MatchResult result;
  const std::string problem = options.Check();
  if (!problem.empty()) {
    result.summary.message = "MatchOptions: " + problem;
    return result;
  }
  if (input.index == nullptr) {
    result.summary.message = "MatchInput: no road-mark index";
    return result;
  }
  result = RunSteps(input, options, progress, cancel);
  LOG(INFO) << result.summary.BriefReport();
  return result;
}

}  // namespace zebrageo
