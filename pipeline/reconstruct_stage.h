// The reconstruct stage (SURVEY_FORMAT.md "Stage outputs"): the zebra bands
// of every stereo pair in 3D (reconstruction/reconstruction.h), then, with
// RunOptions::lines, the road lines on the road plane the zebra step
// estimated (reconstruction/road_lines.h). Writes, each once and
// atomically, reconstructed_bands.csv and skipped_exposures.csv
// (survey/results.h) and reconstructed_lines.csv (survey/results_lines.h).
#ifndef ZEBRAGEO_PIPELINE_RECONSTRUCT_STAGE_H_
#define ZEBRAGEO_PIPELINE_RECONSTRUCT_STAGE_H_

#include <functional>
#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/run_options.h"
#include "pipeline/stage_results.h"
#include "survey/cancellation.h"
#include "survey/survey.h"

namespace zebrageo {

// `progress`: the bands' (done, total) exposures; the road lines are the
// step "road lines" of `steps`. Returns the stage's warnings. Throws
// InputError when more than SurveyLoadOptions's max_missing_image_fraction
// of the exposures had an unreadable image, StageFailedError when no band
// could be reconstructed at all, CancelledError (between exposures).
std::vector<std::string> RunReconstructStage(
    const Survey& survey, StageResults* results, const RunOptions& options,
    const std::function<void(int, int)>& progress = {},
    const ProgressListener& steps = {}, const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_RECONSTRUCT_STAGE_H_
