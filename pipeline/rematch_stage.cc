#include "pipeline/rematch_stage.h"

#include <filesystem>
#include <optional>
#include <utility>

#include "pipeline/adjustment_pass.h"
#include "registration/paint_probe.h"
#include "survey/output_crs.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// The crossings of results_folder's gcp_residuals.csv with a rejected
// vertex; empty without the file.
std::set<std::string> RejectedCrossingsIn(const std::string& results_folder) {
  const fs::path path = fs::path(results_folder) / kGcpResidualsFile;
  std::set<std::string> crossings;
  if (!fs::exists(path)) return crossings;
  for (const GcpResidual& r :
       ReadGcpResiduals(path.string(), kGcpResidualsFile)) {
    if (r.status == GcpStatus::kRejected) crossings.insert(r.crossing_id);
  }
  return crossings;
}

// LineControlTimes of results_folder's line_matches.csv; empty without it.
// A stale line_matches.csv can only narrow the search.
std::vector<double> LineControlTimesIn(const std::string& results_folder,
                                       const ExposureTable& exposures) {
  const fs::path path = fs::path(results_folder) / kLineMatchesFile;
  if (!fs::exists(path)) return {};
  return LineControlTimes(ReadLineMatches(path.string(), kLineMatchesFile),
                          exposures);
}

}  // namespace

RematchSummary RematchStep(
    const Survey& survey, const RunOptions& options,
    const AdjustedTrajectory& adjusted,
    const std::vector<ReconstructedVertex>& vertices,
    const std::vector<VertexMatch>& matches,
    const std::vector<CrossingDecision>& decisions,
    const std::vector<ReconstructedLinePoint>* lines,
    const CancellationToken& cancel,
    const decltype(MatchInput::paint_probe)& paint_probe) {
  RematchInput first;
  first.adjustment = adjusted.record;
  first.vertices = &vertices;
  first.matches = &matches;
  first.decisions = &decisions;
  first.adjusted_trajectory = adjusted.trajectory;
  // After road lines alone, the pass searches where they held the
  // cross-track position. After crossings and lines, it searches no
  // farther from those positions and the crossings than
  // RematchOptions::max_cross_track_control_gap_m.
  first.line_control_times = &adjusted.line_control_times;
  first.rejected_crossings = &adjusted.rejected_crossings;
  first.cancel = cancel;
  ImagePaintProbe probe(survey, options.paint_probe);
  first.paint_probe = paint_probe;
  if (!first.paint_probe) {
    first.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                                 const BandCornersEnu& band,
                                 const std::vector<BandCornersEnu>& seen) {
      return probe.Classify(exposure_id, pose, band, seen);
    };
  }
  std::optional<RoadLinesAdjustment> on_lines;
  if (adjusted.record != nullptr &&
      SecondPassOnRoadLines(*adjusted.record, decisions, options.lines,
                            options.second_pass)) {
    on_lines = AdjustByRoadLinesAlone(AdjustmentDataOf(survey, vertices, {}),
                                      lines, options.adjustment,
                                      options.line_registration, cancel);
    if (on_lines) {
      first.adjustment = &on_lines->record;
      first.adjusted_trajectory = &on_lines->trajectory;
      first.line_control_times = &on_lines->line_control_times;
    }
  }
  RematchSummary rematch = RematchWithAdjustedTrajectory(
      survey, first, options.matching, options.second_pass);
  if (!on_lines) return rematch;
  rematch.message +=
      " (searched on the trajectory the road lines alone "
      "corrected: too few crossings for the adjustment's "
      "error model)";
  const AdjustmentRecord& record = *adjusted.record;
  if (rematch.added == 0 && rematch.dropped == 0 &&
      record.counts.control_crossings > 0 && adjusted.fitted_line_times &&
      !adjusted.fitted_line_times->empty()) {
    first.adjustment = &record;
    first.adjusted_trajectory = adjusted.trajectory;
    first.line_control_times = &*adjusted.fitted_line_times;
    first.across_from_fitted_lines = true;
    rematch = RematchWithAdjustedTrajectory(survey, first, options.matching,
                                            options.second_pass);
    rematch.message +=
        " (searched on the adjusted trajectory near the road lines it "
        "fits: too few crossings for its error model)";
  }
  return rematch;
}

RematchSummary RunRematchStage(const Survey& survey, StageResults* results,
                               const RunOptions& options,
                               const CancellationToken& cancel) {
  const std::unique_ptr<OutputCrs> crs = OutputCrs::Of(survey);
  AdjustedTrajectory adjusted;
  // adjustment.json first: without it (or unreadable) the pass is skipped
  // and nothing else is read.
  adjusted.record = results->Adjustment();
  if (adjusted.record == nullptr) {
    return RematchStep(survey, options, adjusted, {}, {}, {}, nullptr, cancel);
  }
  adjusted.trajectory = &results->CorrectedTrajectory();
  adjusted.line_control_times =
      LineControlTimesIn(results->folder(), survey.exposures);
  adjusted.rejected_crossings = RejectedCrossingsIn(results->folder());
  RematchSummary summary =
      RematchStep(survey, options, adjusted, results->Vertices(),
                  results->Matches(), results->Decisions(),
                  options.lines ? results->LinePoints() : nullptr, cancel);
  if (summary.added == 0 && summary.dropped == 0) return summary;
  const std::vector<std::string> comments = WithSurveyIdentity(
      survey.exposures, {"zebrageo run: " + summary.message});
  WriteMatches(summary.matches, comments, results->PathOf(kMatchesFile),
               crs.get());
  WriteCrossingDecisions(summary.decisions, comments,
                         results->PathOf(kCrossingDecisionsFile));
  results->SetMatches(summary.matches, summary.decisions);
  return summary;
}

}  // namespace zebrageo
