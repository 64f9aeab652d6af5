// Each processing stage as one call on a loaded survey and a results folder,
// shared by the stage commands and the whole run (pipeline/pipeline.h).
// Each writes its files through the results contract (survey/results*.h),
// returns its warnings and throws InputError (bad input) or
// StageFailedError (no usable result, pipeline/exit_codes.h).
#ifndef ZEBRAGEO_PIPELINE_STAGES_H_
#define ZEBRAGEO_PIPELINE_STAGES_H_

#include <functional>
#include <string>
#include <vector>

#include "adjustment/adjustment_io.h"
#include "adjustment/trajectory_adjuster.h"
#include "pipeline/progress.h"
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
    const std::string& results_folder,
    const std::function<void(int, int)>& progress,
    RoadPlane* road_plane = nullptr);

// Writes reconstructed_lines.csv (road lines, issue 9) using the road plane
// of the zebra stage.
std::vector<std::string> RunRoadLinesStage(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads,
    const std::string& results_folder,
    const std::function<void(int, int)>& progress);

// Throws InputError when more than SurveyLoadOptions's
// max_missing_image_fraction of the exposures had an unreadable image.
void ThrowIfTooManyUnreadable(const Survey& survey,
                              const ReconstructionSummary& summary);

// Writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv,
// bands.geojson, adjustment.json, a minimal report.json and colmap/ from
// the survey as loaded and RESULTS/reconstructed_bands.csv and matches.csv.
// Progress steps: "tie points", "adjust", "adjust with lines".
// With `lines` and a reconstructed_lines.csv, the adjustment runs twice:
// zebra crossings alone, then with the road lines matched on that
// trajectory (line_matches.csv, line_control.json).
// The survey's warnings are part of the returned ones (and of
// adjustment.json's); exposures listed in skipped_exposures.csv get no pose.
std::vector<std::string> RunAdjustStage(const Survey& survey,
                                        const std::string& results_folder,
                                        const AdjustmentOptions& options,
                                        bool tie_points, bool lines,
                                        const ProgressListener& progress);

// The road-line points of results_folder/reconstructed_lines.csv matched to
// the database lines with the trajectory of `zebra_result`, database lines
// that disagree with the others rejected (warnings), as control for the
// adjustment; writes line_matches.csv and line_control.json. Empty without
// lines.
std::vector<LineControlPoint> MatchLinesForAdjustment(
    const AdjustmentData& data, const AdjustmentOptions& options,
    const AdjustmentResult& zebra_result, const std::string& results_folder,
    std::vector<std::string>* warnings);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_STAGES_H_
