// `zebrageo run` as a library call: every stage on one loaded survey into
// one results folder, resumably (pipeline/run_state.h), then the report.
//
// The sequence (RunSurveyPipeline):
//   reconstruct   zebra bands, then road lines (reconstructed_*.csv)
//   match         bands to the road-mark database (matches.csv, ...)
//   adjust        the trajectory with the crossings as control; with road
//                 lines, the lines matched on that trajectory and a second
//                 adjustment with them; then the second registration pass
//                 with the adjusted trajectory and, if it added matches, the
//                 adjustment again
//   report        report.json and report.html
// Each stage writes its files through the results contract
// (survey/results*.h); progress goes to one callback (pipeline/progress.h).
#ifndef ZEBRAGEO_PIPELINE_PIPELINE_H_
#define ZEBRAGEO_PIPELINE_PIPELINE_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/report.h"
#include "pipeline/run_options.h"
#include "survey/survey.h"

namespace zebrageo {

// How one run is carried out, beside its options (which are data and
// decide its results).
struct RunContext {
  // Progress of every step (pipeline/progress.h).
  ProgressListener progress;
  // Redo from this stage: reconstruct, match or adjust. Empty: resume
  // after the last complete stage (pipeline/run_state.h).
  std::string from_stage;
};

struct RunSummary {
  std::vector<StageTiming> timings;
  std::vector<std::string> warnings;  // of the stages, resumed ones too
  nlohmann::json report;              // as written to report.json
};

// Runs the stages into `results_folder` (created if needed; the caller
// holds it, pipeline/results_session.h) and writes the report. Throws
// UsageError for bad options, InputError for bad input, StageFailedError
// when a stage has no usable result.
RunSummary RunSurveyPipeline(const Survey& survey,
                             const std::string& results_folder,
                             const RunOptions& options,
                             const RunContext& context = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_PIPELINE_H_
