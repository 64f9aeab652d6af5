// Runs stages in order into one results folder, resumably (the run state
// of `zebrageo run`).
//
// After a stage's outputs are complete (each written atomically), the
// pipeline records it in RESULTS/run_state.json with a fingerprint of the
// inputs (survey files' sizes and times, options, version). A rerun with the
// same fingerprint skips the stages recorded complete whose outputs are all
// present, and resumes at the first one that is not; `from_stage` redoes
// from a named stage. Killing a run therefore loses at most the stage in
// progress, and the rerun gives the same results as an uninterrupted run
// because every stage is deterministic.
#ifndef ZEBRAGEO_PIPELINE_RUN_STATE_H_
#define ZEBRAGEO_PIPELINE_RUN_STATE_H_

#include <functional>
#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/report.h"

namespace zebrageo {

inline constexpr char kRunStateFile[] = "run_state.json";

struct PipelineStage {
  std::string name;
  // Files (relative to the results folder) the stage writes.
  std::vector<std::string> outputs;
  // Runs the stage with a (done, total) progress callback; returns its
  // warnings. Throws on failure (InputError, StageFailedError...).
  std::function<std::vector<std::string>(
      const std::function<void(int, int)>& progress)>
      run;
};

struct PipelineOptions {
  // Redo from this stage (its name), even if recorded complete. Empty:
  // resume after the last complete stage.
  std::string from_stage;
};

struct PipelineRun {
  std::vector<StageTiming> timings;
  std::vector<std::string> warnings;  // of every stage, resumed ones too
};

// A fingerprint of the inputs: the survey folder's files named in
// `input_files` (size and modification time), `settings` (options as
// text) and the program version.
std::string InputFingerprint(const std::vector<std::string>& input_files,
                             const std::string& settings);

// Throws UsageError for an unknown from_stage.
PipelineRun RunPipeline(const std::string& results_folder,
                        const std::string& fingerprint,
                        const std::vector<PipelineStage>& stages,
                        const PipelineOptions& options,
                        const ProgressListener& progress = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_RUN_STATE_H_
