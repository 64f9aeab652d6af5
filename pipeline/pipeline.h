// `zebrageo run` as a library call: every stage on one loaded survey into
// one results folder, resumably (pipeline/run_state.h), then the report.
//
// The sequence (RunSurveyPipeline):
//   reconstruct   zebra bands, then road lines (pipeline/reconstruct_stage.h)
//   match         bands to the road-mark database (pipeline/match_stage.h)
//   adjust        the trajectory with the crossings and road lines as
//                 control, the second registration pass, the adjustment
//                 again while the pass changes the control
//                 (pipeline/adjust_stage.h, pipeline/rematch_stage.h)
//   report        report.json and report.html (pipeline/report_stage.h)
// Each stage writes its files through the results contract
// (survey/results*.h), each once. A run is carried out in a RunContext: its
// progress, its cancellation and its log, so one process can run several
// surveys side by side.
#ifndef ZEBRAGEO_PIPELINE_PIPELINE_H_
#define ZEBRAGEO_PIPELINE_PIPELINE_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/report_stage.h"
#include "pipeline/run_options.h"
#include "survey/cancellation.h"
#include "survey/run_log.h"
#include "survey/survey.h"

namespace zebrageo {

// How one run is carried out, beside its options (which are data and
// decide its results).
struct RunContext {
  // Progress of every step (pipeline/progress.h).
  ProgressListener progress;
  // Redo from this stage: reconstruct, match or adjust. Empty: resume every
  // stage whose options and inputs did not change (pipeline/run_state.h).
  std::string from_stage;
  // Stops the run at the next checkpoint with CancelledError
  // (survey/cancellation.h).
  CancellationToken cancel;
  // The run's own log (survey/run_log.h); null: glog's destinations only.
  RunLog* log = nullptr;
};

struct RunSummary {
  std::vector<StageTiming> timings;
  std::vector<std::string> warnings;  // of the stages, resumed ones too
  nlohmann::json report;              // as written to report.json
};

// Runs the stages into `results_folder` (created if needed; the caller
// holds it, pipeline/results_session.h) and writes the report. Throws
// UsageError for bad options, InputError for bad input, StageFailedError
// when a stage has no usable result, CancelledError when context.cancel
// was cancelled (the stage in progress is left incomplete, nothing of it
// written: a rerun resumes the stages before it).
RunSummary RunSurveyPipeline(const Survey& survey,
                             const std::string& results_folder,
                             const RunOptions& options,
                             const RunContext& context = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_PIPELINE_H_
