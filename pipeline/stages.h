// Each processing stage as one call on a loaded survey and the stage
// outputs of a results folder (pipeline/stage_results.h: in memory, or read
// from the folder where an earlier run wrote them), shared by the stage
// commands and the whole run (pipeline/pipeline.h). Each writes its files
// through the results contract (survey/results*.h), leaves what it wrote in
// StageResults for the next stage, returns its warnings and throws
// InputError (bad input) or StageFailedError (no usable result,
// pipeline/exit_codes.h).
#ifndef ZEBRAGEO_PIPELINE_STAGES_H_
#define ZEBRAGEO_PIPELINE_STAGES_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "adjustment/adjustment_io.h"
#include "adjustment/trajectory_adjuster.h"
#include "pipeline/progress.h"
#include "pipeline/run_options.h"
#include "pipeline/stage_results.h"
#include "reconstruction/reconstruction.h"
#include "reconstruction/road_lines.h"
#include "survey/results_lines.h"
#include "survey/survey.h"

namespace zebrageo {

// Writes reconstructed_bands.csv and skipped_exposures.csv. `road_plane`,
// if given, receives the road plane in the body frame as the stage
// estimated it.
std::vector<std::string> RunReconstructStage(
    const Survey& survey, const ReconstructionOptions& options,
    StageResults* results, const std::function<void(int, int)>& progress,
    RoadPlane* road_plane = nullptr);

// Writes reconstructed_lines.csv (road lines, issue 9) using the road plane
// of the zebra stage.
std::vector<std::string> RunRoadLinesStage(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads, StageResults* results,
    const std::function<void(int, int)>& progress);

// Throws InputError when more than SurveyLoadOptions's
// max_missing_image_fraction of the exposures had an unreadable image.
void ThrowIfTooManyUnreadable(const Survey& survey,
                              const ReconstructionSummary& summary);

// Writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv,
// bands.geojson, adjustment.json, a minimal report.json and colmap/ from
// the survey as loaded and the reconstruction's bands and the matches
// (rewritten without the matches the adjustment rejects).
// Progress steps: "tie points", "adjust", "adjust with lines".
// With `lines` and a reconstructed_lines.csv, the adjustment runs twice:
// zebra crossings alone, then with the road lines matched on that
// trajectory (line_matches.csv, line_control.json).
// The survey's warnings are part of the returned ones (and of
// adjustment.json's); exposures the reconstruction skipped get no pose.
// *line_control_times and *fitted_line_times (when not null):
// AdjustWithRoadLines'.
// The run's options it reads: tie_points, lines, tie_point_matching,
// line_registration and adjustment.
std::vector<std::string> RunAdjustStage(
    const Survey& survey, StageResults* results, const RunOptions& options,
    const ProgressListener& progress,
    std::vector<double>* line_control_times = nullptr,
    std::vector<double>* fitted_line_times = nullptr);

// The adjustment of `input` (zebra control), then, with `line_points`,
// again with the road lines matched on its trajectory
// (MatchLinesForAdjustment, below; files written into results_folder
// unless it is ""). What RunAdjustStage runs; progress steps "adjust" and
// "adjust with lines"; `progress` may be null. *line_control_times (when
// not null): the times of the line points that held the cross-track
// position (the second pass searches only near them after road lines
// alone). *fitted_line_times (when not null): those of them that the
// returned trajectory fits across their line within kFittedLineResidualM
// (RematchInput::across_from_fitted_lines).
inline constexpr double kFittedLineResidualM = 0.1;
AdjustmentResult AdjustWithRoadLines(
    const AdjustmentData& data, AdjustmentInput input,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const std::vector<ReconstructedLinePoint>* line_points,
    const std::string& results_folder, std::vector<std::string>* warnings,
    const ProgressListener& progress,
    std::vector<double>* line_control_times = nullptr,
    std::vector<double>* fitted_line_times = nullptr);

// Whether the second registration pass should search on the trajectory the
// road lines alone correct (AdjustByRoadLinesAlone) rather than on the
// adjustment's (`record`): with road lines, an adjustment that had too
// few crossings to trust its error model (RematchOptions::
// min_control_crossings: rematch.cc would skip the pass) and observations
// left undecided.
bool SecondPassOnRoadLines(const AdjustmentRecord& record,
                           const std::vector<CrossingDecision>& decisions,
                           bool lines, const RematchOptions& rematch);

// The trajectory of `data` corrected by the road lines alone (its zebra
// matches left out: adjustment.json's road_lines_only), and what
// adjustment.json would hold of it; nullopt without line points or when
// no line could be control. Writes nothing. The second registration pass
// (pipeline.cc) searches on it when the zebra crossings the adjustment
// used are too few to trust its error model.
struct RoadLinesAdjustment {
  std::vector<TrajectorySample> trajectory;
  AdjustmentRecord record;
  // Where the lines held the cross-track position (RematchInput::
  // line_control_times).
  std::vector<double> line_control_times;
};
std::optional<RoadLinesAdjustment> AdjustByRoadLinesAlone(
    const AdjustmentData& data,
    const std::vector<ReconstructedLinePoint>* line_points,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration);

// The reconstructed road-line points (what reconstructed_lines.csv holds)
// matched to the database lines with the trajectory of `zebra_result`,
// database lines that disagree with the others rejected (warnings), as
// control for the adjustment; writes line_matches.csv and
// line_control.json into results_folder (nothing when it is ""). Empty
// when reconstructed_lines is
// null (reconstructed without lines) or the database has no lines.
std::vector<LineControlPoint> MatchLinesForAdjustment(
    const AdjustmentData& data, const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const AdjustmentResult& zebra_result,
    const std::vector<ReconstructedLinePoint>* reconstructed_lines,
    const std::string& results_folder, std::vector<std::string>* warnings);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_STAGES_H_
