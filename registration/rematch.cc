#include "registration/rematch.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "registration/observations.h"
#include "registration/paint_probe.h"
#include "survey/option_check.h"

namespace zebrageo {

std::string RematchOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, min_control_crossings, 1);
  OPTION_GE(check, min_hit_bands, 1);
  OPTION_GT(check, gate_m, 0.0);
  // Half a band period: beyond it a wrong band offset can be nearer.
  OPTION_IN(check, cross_track_gate_m, "(", 0.0, 0.5, ")");
  OPTION_GE(check, max_line_control_gap_m, 0.0);
  OPTION_GE(check, max_cross_track_control_gap_m, 0.0);
  OPTION_IN(check, max_sideways_m, "[", 0.0, 0.5, ")");
  OPTION_GE(check, max_line_drift_sd_m, 0.0);
  OPTION_GE(check, max_line_bracket_gap_s, 0.0);
  OPTION_GT(check, sd_gate_factor, 0.0);
  OPTION_IN(check, max_heading_error_rad, "(", 0.0, 0.5, ")");
  return check.problem();
}

namespace {

// The times of the exposures `exposure_ids` (those in `exposures`) and
// `more`, sorted, each once.
std::vector<double> SortedExposureTimes(
    const std::vector<int64_t>& exposure_ids, const ExposureTable& exposures,
    std::vector<double> more) {
  std::map<int64_t, double> time_of;
  for (const Exposure& e : exposures.exposures) time_of[e.exposure_id] = e.time;
  for (int64_t id : exposure_ids) {
    const auto t = time_of.find(id);
    if (t != time_of.end()) more.push_back(t->second);
  }
  std::sort(more.begin(), more.end());
  more.erase(std::unique(more.begin(), more.end()), more.end());
  return more;
}

// "" when the adjustment (its adjustment.json, survey/results_adjustment.h,
// null when missing) can gate the second pass, else why not.
std::string AdjustmentUnfitForRematch(const AdjustmentRecord* record,
                                      bool across_from_fitted_lines,
                                      int min_control_crossings) {
  if (record == nullptr) {
    return std::string(kAdjustmentJsonFile) + " is missing";
  }
  if (!record->posterior_sd_computed) {
    return "the adjustment has no posterior covariance to gate it";
  }
  // Road lines alone: their error model is fitted on many stretches of
  // line, and the pass is gated across the track only.
  if (record->road_lines_only) return "";
  // Gated across the track by the lines the adjusted trajectory fits.
  if (across_from_fitted_lines) return "";
  const int crossings =
      record->counts.control_crossings + record->counts.check_crossings;
  if (crossings < min_control_crossings) {
    return "the adjustment has " + std::to_string(crossings) +
           " control crossings (" + std::to_string(min_control_crossings) +
           " needed to trust its error model)";
  }
  return "";
}

// The seconds from `t` to the farther of the `sorted` times just before
// and just after it (infinity unless there are both): between two line
// points the lines bound the error on both sides; beyond the last one a
// switch they did not see is unbounded.
double BracketGap(const std::vector<double>& sorted, double t) {
  const auto after = std::lower_bound(sorted.begin(), sorted.end(), t);
  if (after == sorted.end() || after == sorted.begin()) {
    return std::numeric_limits<double>::infinity();
  }
  return std::max(*after - t, t - *(after - 1));
}

// The sd of the change of the cross-track error over `dt` seconds by the
// adjustment's position model (a first-order Gauss-Markov process on
// each axis: var = 2 sigma^2 (1 - exp(-dt / tau))); infinity when the
// record has no estimated model.
double CrossTrackDriftSd(const AdjustmentRecord& record, double dt) {
  const auto& model = record.model;
  const double sigma =
      std::max(model.position_sigma_m.x(), model.position_sigma_m.y());
  const double tau =
      std::min(model.position_tau_s.x(), model.position_tau_s.y());
  if (!model.position_model_estimated || !(tau > 0.0) || !(sigma > 0.0) ||
      !std::isfinite(dt)) {
    return std::numeric_limits<double>::infinity();
  }
  return sigma * std::sqrt(2.0 * (1.0 - std::exp(-dt / tau)));
}

// Whether the road lines bound the cross-track error at time `t`, beyond
// max_line_control_gap_m of them (RematchOptions::max_line_drift_sd_m).
bool BoundedByLines(const AdjustmentRecord& record,
                    const std::vector<double>& line_times, double t,
                    const RematchOptions& rematch) {
  const double gap_s = BracketGap(line_times, t);
  return gap_s <= rematch.max_line_bracket_gap_s &&
         CrossTrackDriftSd(record, gap_s) <= rematch.max_line_drift_sd_m;
}

// How far the vehicle moved sideways on `trajectory` from time t0 to t1:
// its horizontal displacement across its own heading, summed over the
// samples between them (negative to the left).
double SidewaysMotion(const Trajectory& trajectory, double t0, double t1) {
  if (t1 < t0) std::swap(t0, t1);
  std::vector<double> times = {t0};
  for (const TrajectorySample& s : trajectory.samples()) {
    if (s.time > t0 && s.time < t1) times.push_back(s.time);
  }
  times.push_back(t1);
  Pose previous;
  if (!trajectory.InterpolatePose(t0, &previous)) {
    return std::numeric_limits<double>::infinity();
  }
  double sideways = 0.0;
  for (size_t k = 1; k < times.size(); ++k) {
    Pose pose;
    if (!trajectory.InterpolatePose(times[k], &pose)) {
      return std::numeric_limits<double>::infinity();
    }
    // Body FRD: y points right.
    Eigen::Vector3d right = previous.q_enu_body * Eigen::Vector3d::UnitY();
    right.z() = 0.0;
    if (right.norm() > 0.0)
      sideways += (pose.p_enu - previous.p_enu).dot(right.normalized());
    previous = pose;
  }
  return sideways;
}

// Whether one of the sorted `times` just before or just after `t` lies at
// most `gap_m` travelled (horizontally, on `trajectory`) from it with the
// vehicle moving at most `max_sideways_m` sideways in between.
bool NearWithoutSidewaysMotion(const std::vector<double>& sorted, double t,
                               const Trajectory& trajectory, double gap_m,
                               double max_sideways_m) {
  Pose at;
  if (!trajectory.InterpolatePose(t, &at)) return false;
  const auto after = std::lower_bound(sorted.begin(), sorted.end(), t);
  for (auto it : {after, after == sorted.begin() ? sorted.end() : after - 1}) {
    Pose pose;
    if (it != sorted.end() && trajectory.InterpolatePose(*it, &pose) &&
        (pose.p_enu - at.p_enu).head<2>().norm() <= gap_m &&
        (std::isinf(max_sideways_m) ||
         std::abs(SidewaysMotion(trajectory, *it, t)) <= max_sideways_m)) {
      return true;
    }
  }
  return false;
}

// Whether the vehicle travelled at most `gap_m` (horizontally, on
// `trajectory`) between time `t` and one of the `sorted` times.
bool NearAny(const std::vector<double>& sorted, double t,
             const Trajectory& trajectory, double gap_m) {
  return NearWithoutSidewaysMotion(sorted, t, trajectory, gap_m,
                                   std::numeric_limits<double>::infinity());
}

// Drops the observations near no line point that the adjusted trajectory
// fits or farther from it than max_sideways_m sideways
// (RematchInput::across_from_fitted_lines).
void KeepNearFittedLines(const std::vector<double>& times,
                         const Trajectory& trajectory,
                         const RematchOptions& rematch,
                         std::vector<CrossingObservation>* observations) {
  observations->erase(
      std::remove_if(
          observations->begin(), observations->end(),
          [&](const CrossingObservation& o) {
            const bool unmeasured = !NearWithoutSidewaysMotion(
                times, o.time_s, trajectory, rematch.max_line_control_gap_m,
                rematch.max_sideways_m);
            VLOG_IF(1, unmeasured)
                << "second pass: exposure " << o.exposure_id << " group "
                << o.group_id
                << " not searched: no line point the adjusted trajectory "
                   "fits within "
                << rematch.max_line_control_gap_m << " m without moving over "
                << rematch.max_sideways_m << " m sideways";
            return unmeasured;
          }),
      observations->end());
}

// Drops the observations where nothing measured the cross-track position:
// farther than gap_m travelled (on `trajectory`) from every one of the
// sorted `times` and not between two of them that the error model bounds
// (BoundedByLines).
void KeepMeasuredAcross(const std::vector<double>& times, double gap_m,
                        const Trajectory& trajectory,
                        const AdjustmentRecord& record,
                        const RematchOptions& rematch,
                        std::vector<CrossingObservation>* observations) {
  observations->erase(
      std::remove_if(observations->begin(), observations->end(),
                     [&](const CrossingObservation& o) {
                       const bool unmeasured =
                           !NearAny(times, o.time_s, trajectory, gap_m) &&
                           !BoundedByLines(record, times, o.time_s, rematch);
                       VLOG_IF(1, unmeasured)
                           << "second pass: exposure " << o.exposure_id
                           << " group " << o.group_id
                           << " not searched: nothing measured the "
                              "cross-track position within "
                           << gap_m << " m or on both sides";
                       return unmeasured;
                     }),
      observations->end());
}

// The times at which something measured the cross-track position of the
// adjusted trajectory: the road lines' control points and the exposures
// whose bands were matched to a crossing the adjustment kept; sorted.
std::vector<double> CrossTrackControlTimes(const Survey& survey,
                                           const RematchInput& first) {
  std::vector<int64_t> ids;
  if (first.matches != nullptr) {
    for (const VertexMatch& m : *first.matches) {
      if (first.rejected_crossings == nullptr ||
          !first.rejected_crossings->count(m.crossing_id)) {
        ids.push_back(m.exposure_id);
      }
    }
  }
  return SortedExposureTimes(ids, survey.exposures,
                             first.line_control_times != nullptr
                                 ? *first.line_control_times
                                 : std::vector<double>());
}

// The second pass: the bands matched again on the survey as the adjustment
// left it (its corrected trajectory), with the rematch gates. *bands_of:
// the band ids of each observation (exposure, group).
MatchResult MatchOnAdjustedTrajectory(
    const Survey& survey, const RematchInput& first,
    const MatchOptions& options, const RematchOptions& rematch,
    std::map<std::pair<int64_t, int64_t>, std::set<int64_t>>* bands_of) {
  Survey adjusted = survey;
  adjusted.trajectory = Trajectory(*first.adjusted_trajectory, survey.frame);
  const std::vector<ReconstructedVertex>& vertices = *first.vertices;
  MatchInput input;
  input.observations =
      BuildObservations(adjusted, vertices, kReconstructedBandsFile, nullptr);
  input.exposures = ExposurePoses(adjusted);
  const RoadmarkIndex index(adjusted.roadmarks, adjusted.frame);
  input.index = &index;
  input.rig = &adjusted.rig;
  ImagePaintProbe probe(adjusted);
  input.paint_probe = first.paint_probe;
  if (!input.paint_probe) {
    input.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                                 const BandCornersEnu& band,
                                 const std::vector<BandCornersEnu>& seen) {
      return probe.Classify(exposure_id, pose, band, seen);
    };
  }
  MatchOptions tight = options;
  const std::vector<double> none;
  if (first.across_from_fitted_lines) {
    KeepNearFittedLines(
        first.line_control_times != nullptr ? *first.line_control_times : none,
        adjusted.trajectory, rematch, &input.observations);
    // Along the track and in heading as the first pass (one or two
    // crossings: no error model to gate it); across it, a band offset lies
    // far outside.
    tight.max_cross_track_m = rematch.cross_track_gate_m;
  } else if (first.adjustment->road_lines_only) {
    // Only where the lines measured the cross-track position: near one of
    // their points, or between two where their own error model says it
    // cannot have moved by a band offset.
    KeepMeasuredAcross(
        first.line_control_times != nullptr ? *first.line_control_times : none,
        rematch.max_line_control_gap_m, adjusted.trajectory, *first.adjustment,
        rematch, &input.observations);
    // Road lines corrected the trajectory across the track and in height:
    // along-track and in heading it is the input's, searched as in the
    // first pass; across it, a band offset (a metre) lies far outside.
    tight.max_cross_track_m = rematch.cross_track_gate_m;
  } else {
    // The gate is the adjusted trajectory's posterior sd, which holds
    // across the track only where something measured it
    // (RematchOptions::max_cross_track_control_gap_m). Whole dashes, which
    // shrink the along-track sd and with it the radial gate, exposed this
    // (seed 435).
    if (first.line_control_times != nullptr &&
        !first.line_control_times->empty()) {
      KeepMeasuredAcross(CrossTrackControlTimes(survey, first),
                         rematch.max_cross_track_control_gap_m,
                         adjusted.trajectory, *first.adjustment, rematch,
                         &input.observations);
    }
    tight.max_drift_m = rematch.gate_m;
    tight.sd_gate_factor = rematch.sd_gate_factor;
    tight.max_heading_error_rad = rematch.max_heading_error_rad;
    tight.min_hit_bands = rematch.min_hit_bands;
  }
  for (const CrossingObservation& o : input.observations) {
    for (const ObservedBand& b : o.bands) {
      (*bands_of)[{o.exposure_id, o.group_id}].insert(b.band_id);
    }
  }
  return MatchBands(input, tight, {}, first.cancel);
}

// Vertex matches of the first pass that the second makes differently, and
// the crossings the first pass matched them to.
int Disagreements(const std::vector<VertexMatch>& first,
                  const std::vector<VertexMatch>& second,
                  std::set<std::string>* contradicted) {
  std::map<std::tuple<int64_t, int64_t, int>, const VertexMatch*> first_match;
  for (const VertexMatch& m : first) {
    first_match[{m.exposure_id, m.band_id, m.vertex}] = &m;
  }
  int disagreements = 0;
  for (const VertexMatch& m : second) {
    const auto f = first_match.find({m.exposure_id, m.band_id, m.vertex});
    if (f != first_match.end() &&
        (f->second->crossing_id != m.crossing_id || f->second->band != m.band ||
         f->second->db_vertex != m.db_vertex)) {
      ++disagreements;
      contradicted->insert(f->second->crossing_id);
    }
  }
  return disagreements;
}

// The first pass's matches and decisions without the crossings in
// `contradicted`: their decisions refused (why), their vertex matches
// removed (counted in summary->dropped).
void DropContradicted(const std::set<std::string>& contradicted,
                      std::vector<VertexMatch>* matches,
                      std::vector<CrossingDecision>* decisions,
                      RematchSummary* summary) {
  const auto before = matches->size();
  matches->erase(std::remove_if(matches->begin(), matches->end(),
                                [&](const VertexMatch& m) {
                                  return contradicted.count(m.crossing_id) > 0;
                                }),
                 matches->end());
  summary->dropped = static_cast<int>(before - matches->size());
  for (CrossingDecision& d : *decisions) {
    if (d.decision != Decision::kMatched ||
        !contradicted.count(d.crossing_id)) {
      continue;
    }
    d.decision = Decision::kRefused;
    d.reason = "refused: with the adjusted trajectory crossing " +
               d.crossing_id +
               " comes out at another band or vertex (second pass); neither "
               "trusted; first pass: " +
               d.reason;
    d.crossing_id.clear();
  }
}

// The first pass's decisions with the observations it left undecided and
// the second matched; their vertex matches are added to *matches.
std::vector<CrossingDecision> MergeSecondPass(
    const std::vector<CrossingDecision>& first, const MatchResult& second,
    const std::map<std::pair<int64_t, int64_t>, std::set<int64_t>>& bands_of,
    const RematchOptions& rematch, const RematchInput& input,
    std::vector<VertexMatch>* matches, RematchSummary* summary) {
  const std::set<std::string> none;
  const std::set<std::string>& rejected =
      input.rejected_crossings != nullptr ? *input.rejected_crossings : none;
  const bool across_by_lines =
      input.adjustment->road_lines_only || input.across_from_fitted_lines;
  const std::string gate =
      across_by_lines
          ? std::to_string(rematch.cross_track_gate_m).substr(0, 4) +
                " m across the track, " +
                (input.across_from_fitted_lines
                     ? "near road lines the adjusted trajectory fits"
                     : "after road lines alone")
          : std::to_string(rematch.gate_m).substr(0, 4) +
                " m or 5 posterior sd";
  std::vector<CrossingDecision> merged = first;
  for (CrossingDecision& d : merged) {
    if (d.decision == Decision::kMatched) continue;
    const auto it = std::find_if(
        second.decisions.begin(), second.decisions.end(),
        [&](const CrossingDecision& s) {
          return s.exposure_id == d.exposure_id && s.group_id == d.group_id;
        });
    if (it == second.decisions.end() || it->decision != Decision::kMatched) {
      if (it != second.decisions.end()) {
        VLOG(1) << "second pass: exposure " << d.exposure_id << " group "
                << d.group_id << " still undecided: " << it->reason;
      }
      continue;
    }
    if (rejected.count(it->crossing_id)) {
      VLOG(1) << "second pass: exposure " << d.exposure_id << " group "
              << d.group_id << " not matched again to " << it->crossing_id
              << ", which the adjustment rejected";
      continue;
    }
    const auto bands = bands_of.find({d.exposure_id, d.group_id});
    int added_vertices = 0;
    for (const VertexMatch& m : second.matches) {
      if (bands != bands_of.end() && m.exposure_id == d.exposure_id &&
          bands->second.count(m.band_id)) {
        matches->push_back(m);
        ++added_vertices;
      }
    }
    if (added_vertices == 0) continue;
    d.decision = Decision::kMatched;
    d.crossing_id = it->crossing_id;
    d.reason = "matched with the adjusted trajectory (second pass; gate " +
               gate + "): " + it->reason + "; first pass: " + d.reason;
    ++summary->added;
  }
  return merged;
}

}  // namespace

RematchSummary RematchWithAdjustedTrajectory(const Survey& survey,
                                             const RematchInput& first,
                                             const MatchOptions& options,
                                             const RematchOptions& rematch) {
  RematchSummary summary;
  const std::string unfit = AdjustmentUnfitForRematch(
      first.adjustment, first.across_from_fitted_lines,
      rematch.min_control_crossings);
  if (!unfit.empty()) {
    summary.message = "second registration pass skipped: " + unfit;
    return summary;
  }
  std::vector<VertexMatch> matches = *first.matches;
  for (const CrossingDecision& d : *first.decisions) {
    summary.observations += d.decision != Decision::kMatched;
  }
  if (summary.observations == 0) {
    summary.message = "second registration pass: nothing left undecided";
    return summary;
  }
  std::map<std::pair<int64_t, int64_t>, std::set<int64_t>> bands_of;
  const MatchResult second =
      MatchOnAdjustedTrajectory(survey, first, options, rematch, &bands_of);
  if (!second.summary.IsUsable()) {
    summary.message =
        "second registration pass failed: " + second.summary.message;
    return summary;
  }
  // What the first pass matched must come out the same. Where it does not
  // (a band offset decided at one end, where a band worn off the street
  // fakes the bare road, and the trajectory the road lines corrected puts
  // the crossing a period away), one of two independent placements is
  // wrong: the crossings concerned are refused, and nothing is added (the
  // adjusted trajectory may be the wrong one). The caller adjusts again
  // without them and may search once more.
  std::set<std::string> contradicted;
  summary.disagreements = Disagreements(matches, second.matches, &contradicted);
  std::vector<CrossingDecision> merged = *first.decisions;
  if (summary.disagreements > 0) {
    DropContradicted(contradicted, &matches, &merged, &summary);
    std::ostringstream message;
    message << "second registration pass not used: with the adjusted "
               "trajectory "
            << summary.disagreements
            << " vertex matches of the first pass come out differently; "
               "crossing(s)";
    for (const std::string& id : contradicted) message << " " << id;
    message << " refused (" << summary.dropped << " vertex matches removed)";
    summary.message = message.str();
    LOG(WARNING) << summary.message;
  } else {
    merged = MergeSecondPass(*first.decisions, second, bands_of, rematch, first,
                             &matches, &summary);
    std::ostringstream message;
    message << "second registration pass with the adjusted trajectory: "
            << summary.added << " of " << summary.observations
            << " undecided observations matched";
    summary.message = message.str();
  }
  if (summary.added == 0 && summary.dropped == 0) return summary;
  std::sort(matches.begin(), matches.end(),
            [](const VertexMatch& a, const VertexMatch& b) {
              return std::tie(a.exposure_id, a.band_id, a.vertex) <
                     std::tie(b.exposure_id, b.band_id, b.vertex);
            });
  summary.matches = std::move(matches);
  summary.decisions = std::move(merged);
  return summary;
}

std::vector<double> LineControlTimes(const std::vector<LineMatch>& rows,
                                     const ExposureTable& exposures) {
  std::vector<int64_t> ids;
  for (const LineMatch& row : rows) {
    if (row.constrains_across) ids.push_back(row.exposure_id);
  }
  return SortedExposureTimes(ids, exposures, {});
}

}  // namespace zebrageo
