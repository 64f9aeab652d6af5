// The adjust stage (SURVEY_FORMAT.md "Outputs"), in named steps:
//   tie points     image tie points between exposures (tiepoints/)
//   adjust         the trajectory with the zebra crossings as control, the
//                  road lines registered on it, and again with them
//                  (pipeline/adjustment_pass.h)
//   keep control   the vertex matches the adjustment rejected removed from
//                  the control, their observations refused
//   rematch        with RunOptions::rematch, the second registration pass
//                  on the adjusted trajectory (pipeline/rematch_stage.h);
//                  while it adds or removes matches, adjust and rematch
//                  again (three passes at most)
//   write          every file of the stage, each once, through the
//                  results contract: trajectory_corrected.csv, poses.csv,
//                  gcp_residuals.csv, bands.geojson, adjustment.json,
//                  colmap/ (geodata/colmap_export.h), line_matches.csv and
//                  line_control.json, and matches.csv and
//                  crossing_decisions.csv when a step changed them
// The trajectory and the poses are written last: their presence means the
// stage finished. Reads the survey as loaded and the reconstruction and
// match stages' outputs (StageResults); leaves what it wrote there.
#ifndef ZEBRAGEO_PIPELINE_ADJUST_STAGE_H_
#define ZEBRAGEO_PIPELINE_ADJUST_STAGE_H_

#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/run_options.h"
#include "pipeline/stage_results.h"
#include "survey/cancellation.h"
#include "survey/survey.h"

namespace zebrageo {

// Returns the stage's warnings: the survey's, the road lines' and the
// second pass's refusals (adjustment.json lists the adjustment's own).
// Throws StageFailedError when the adjustment is not usable (nothing
// written), InputError for inconsistent inputs, CancelledError when
// `cancel` is cancelled (between solves; nothing written).
std::vector<std::string> RunAdjustStage(const Survey& survey,
                                        StageResults* results,
                                        const RunOptions& options,
                                        const ProgressListener& progress = {},
                                        const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_ADJUST_STAGE_H_
