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

}  // namespace

std::vector<std::string> RunAdjustStage(const Survey& survey,
                                        StageResults* results,
                                        const AdjustmentOptions& options,
                                        bool tie_points, bool lines,
                                        const ProgressListener& progress) {
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
      tie_points &&
      data.missing_images < static_cast<int>(data.exposures.images.size());
  if (use_ties) {
    StepProgress step(progress, "tie points");
    tracks = BuildTieTracks(TiePointOptions(), data.survey_folder, data.rig,
                            data.trajectory, data.exposures, &tie_summary,
                            step.Callback());
    step.Finish();
  }
  AdjustmentInput input = data.Input();
  if (use_ties) input.tie_tracks = &tracks;

  StepProgress step(progress, "adjust");
  AdjustmentResult result = AdjustTrajectory(options, input, step.Callback());
  step.Finish();
  std::vector<std::string> warnings = data.warnings;
  if (lines && result.summary.IsUsable()) {
    const std::vector<LineControlPoint> line_points =
        MatchLinesForAdjustment(data, options, result, results->LinePoints(),
                                results_folder, &warnings);
    if (!line_points.empty()) {
      input.line_points = &line_points;
      StepProgress line_step(progress, "adjust with lines");
      result = AdjustTrajectory(options, input, line_step.Callback());
      line_step.Finish();
    }
  }
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

}  // namespace zebrageo
