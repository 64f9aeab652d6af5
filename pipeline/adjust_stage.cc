// The adjust stage: the trajectory adjusted with the matched band vertices
// (and road lines) as control, its files written through the contract.
#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <utility>

#include "adjustment/adjustment_io.h"
#include "adjustment/trajectory_adjuster.h"
#include "pipeline/exit_codes.h"
#include "pipeline/stages.h"
#include "registration/match_stage.h"
#include "survey/atomic_file.h"
#include "survey/output_crs.h"
#include "survey/results.h"
#include "tiepoints/tie_points.h"

namespace zebrageo {
namespace {

// Exposures the reconstruction skipped (their images could not be read):
// they get no pose (SURVEY_FORMAT.md).
std::set<int64_t> SkippedExposureIds(StageResults* results) {
  std::set<int64_t> ids;
  for (const SkippedExposure& s : results->SkippedExposures()) {
    ids.insert(s.exposure_id);
  }
  return ids;
}

// The times of the line control points that hold the position across
// their line (not the height alone, not a dash's along-track position),
// sorted.
std::vector<double> CrossTrackTimes(
    const std::vector<LineControlPoint>& control) {
  std::vector<double> times;
  for (const LineControlPoint& c : control) {
    if (!c.along_track && c.sqrt_information.row(0).norm() > 0.0) {
      times.push_back(c.time);
    }
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

// The times of the control points of CrossTrackTimes that `result`'s
// trajectory fits across their line within max_residual_m, sorted. A
// point it does not fit (a GNSS switch the smooth correction could not
// follow, a line moved in the database) measured nothing the trajectory
// holds.
std::vector<double> FittedCrossTrackTimes(
    const std::vector<LineControlPoint>& control,
    const AdjustmentResult& result, double max_residual_m) {
  const auto& samples = result.corrected_samples;
  if (samples.size() < 2 || result.corrected_poses.size() != samples.size()) {
    return {};
  }
  std::vector<LineControlPoint> fitted;
  for (const LineControlPoint& c : control) {
    if (c.time < samples.front().time || c.time > samples.back().time) {
      continue;
    }
    // Interpolated as Trajectory::InterpolatePose does.
    const auto it = std::upper_bound(
        samples.begin(), samples.end(), c.time,
        [](double t, const TrajectorySample& s) { return t < s.time; });
    const size_t i = std::min<size_t>(
        std::max<ptrdiff_t>(0, it - samples.begin() - 1), samples.size() - 2);
    const double span = samples[i + 1].time - samples[i].time;
    const double u = span > 0.0 ? (c.time - samples[i].time) / span : 0.0;
    const Pose pose = InterpolatePoses(result.corrected_poses[i],
                                       result.corrected_poses[i + 1], u);
    const double residual =
        c.across_enu.dot(pose.T_enu_body() * c.p_body - c.db_point_enu);
    if (std::abs(residual) <= max_residual_m) fitted.push_back(c);
  }
  return CrossTrackTimes(fitted);
}

}  // namespace

AdjustmentResult AdjustWithRoadLines(
    const AdjustmentData& data, AdjustmentInput input,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const std::vector<ReconstructedLinePoint>* line_points,
    const std::string& results_folder, std::vector<std::string>* warnings,
    const ProgressListener& progress, std::vector<double>* line_control_times,
    std::vector<double>* fitted_line_times) {
  if (line_control_times != nullptr) line_control_times->clear();
  if (fitted_line_times != nullptr) fitted_line_times->clear();
  StepProgress step(progress, "adjust");
  AdjustmentResult result = AdjustTrajectory(options, input, step.Callback());
  step.Finish();
  if (line_points == nullptr || !result.summary.IsUsable()) return result;
  const std::vector<LineControlPoint> control =
      MatchLinesForAdjustment(data, options, registration, result, line_points,
                              results_folder, warnings);
  if (control.empty()) return result;
  if (line_control_times != nullptr) {
    *line_control_times = CrossTrackTimes(control);
  }
  input.line_points = &control;
  StepProgress line_step(progress, "adjust with lines");
  result = AdjustTrajectory(options, input, line_step.Callback());
  line_step.Finish();
  if (fitted_line_times != nullptr && result.summary.IsUsable()) {
    *fitted_line_times =
        FittedCrossTrackTimes(control, result, kFittedLineResidualM);
  }
  return result;
}

bool SecondPassOnRoadLines(const AdjustmentRecord& record,
                           const std::vector<CrossingDecision>& decisions,
                           bool lines, const RematchOptions& rematch) {
  if (!lines || record.road_lines_only) return false;
  const int crossings =
      record.counts.control_crossings + record.counts.check_crossings;
  if (crossings >= rematch.min_control_crossings) return false;
  for (const CrossingDecision& d : decisions) {
    if (d.decision != Decision::kMatched) return true;
  }
  return false;
}

std::vector<std::string> RunAdjustStage(
    const Survey& survey, StageResults* results, const RunOptions& run,
    const ProgressListener& progress, std::vector<double>* line_control_times,
    std::vector<double>* fitted_line_times) {
  const AdjustmentOptions& options = run.adjustment;
  const std::string& results_folder = results->folder();
  // The survey as loaded (not read again), with the stages' outputs.
  AdjustmentData data =
      AdjustmentDataOf(survey, results->Vertices(), results->Matches());
  // The survey's warnings first: adjustment.json and the adjust command's
  // report.json list them too.
  data.warnings.insert(data.warnings.begin(), survey.warnings.begin(),
                       survey.warnings.end());
  LOG(INFO) << "adjust: " << data.vertices.size() << " reconstructed vertices, "
            << data.matches.size() << " matches, "
            << data.exposures.exposures.size() << " exposures";

  std::vector<TieTrack> tracks;
  TiePointSummary tie_summary;
  const bool use_ties =
      run.tie_points &&
      data.missing_images < static_cast<int>(data.exposures.images.size());
  if (use_ties) {
    StepProgress step(progress, "tie points");
    tracks = BuildTieTracks(run.tie_point_matching, data.survey_folder,
                            data.rig, data.trajectory, data.exposures,
                            &tie_summary, step.Callback());
    step.Finish();
  }
  AdjustmentInput input = data.Input();
  if (use_ties) input.tie_tracks = &tracks;

  std::vector<std::string> warnings = data.warnings;
  AdjustmentResult result = AdjustWithRoadLines(
      data, input, options, run.line_registration,
      run.lines ? results->LinePoints() : nullptr, results_folder, &warnings,
      progress, line_control_times, fitted_line_times);
  if (!result.summary.IsUsable()) {
    // A solver's message ("Ceres failed: ...") names no input: the survey's
    // warnings (gaps, rates, with their lines and times) may.
    std::string context;
    for (size_t i = 0; i < survey.warnings.size() && i < 3; ++i) {
      context +=
          (i == 0 ? "; the survey's warnings: " : "; ") + survey.warnings[i];
    }
    throw StageFailedError("adjust: " + result.summary.message +
                           "; no results were written" + context);
  }
  const std::set<int64_t> skipped = SkippedExposureIds(results);
  result.camera_poses.erase(
      std::remove_if(result.camera_poses.begin(), result.camera_poses.end(),
                     [&skipped](const CameraPose& pose) {
                       return skipped.count(pose.exposure_id) > 0;
                     }),
      result.camera_poses.end());
  RemoveStaleTemporaries(results_folder);
  AdjustmentRecord record = WriteAdjustmentResults(
      data, options, result, use_ties ? &tie_summary : nullptr, results_folder);
  std::vector<VertexMatch> matches = std::move(data.matches);
  std::vector<CrossingDecision> decisions = results->Decisions();
  const int removed =
      RemoveRejectedMatches(result, results_folder, &matches, &decisions);
  results->SetMatches(std::move(matches), std::move(decisions));
  results->SetAdjustment(std::move(result.corrected_samples),
                         std::move(record));
  if (removed > 0) {
    LOG(INFO) << "adjust: " << removed
              << " vertex matches rejected by the adjustment removed from "
              << kMatchesFile;
  }
  // survey.yaml's output_crs, beside the contract's WGS84 and ENU columns.
  AddOutputCrs(survey, results_folder);
  LOG(INFO) << "adjust: " << result.summary.BriefReport();
  return warnings;
}

std::optional<RoadLinesAdjustment> AdjustByRoadLinesAlone(
    const AdjustmentData& data,
    const std::vector<ReconstructedLinePoint>* line_points,
    const AdjustmentOptions& user_options,
    const LineRegistrationOptions& registration) {
  if (line_points == nullptr || line_points->empty() ||
      !user_options.road_lines.line_control_without_crossings) {
    return std::nullopt;
  }
  AdjustmentOptions options = user_options;
  options.log_warnings = false;  // a trial: the user gets another result
  AdjustmentInput input = data.Input();
  const std::vector<VertexMatch> no_matches;
  input.matches = &no_matches;
  // Without control the first adjustment keeps the input trajectory; the
  // lines are then placed by the cross-track offsets they agree on.
  std::vector<std::string> warnings;
  RoadLinesAdjustment out;
  AdjustmentResult result =
      AdjustWithRoadLines(data, input, options, registration, line_points, "",
                          &warnings, nullptr, &out.line_control_times);
  if (!result.summary.IsUsable() || !result.summary.line_control_only) {
    return std::nullopt;
  }
  out.record = AdjustmentRecordOf(data, options, result, nullptr);
  out.trajectory = std::move(result.corrected_samples);
  return out;
}

}  // namespace zebrageo
