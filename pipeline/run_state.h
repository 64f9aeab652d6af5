// Runs stages in order into one results folder, resumably (the run state
// of `zebrageo run`).
//
// Each stage has a fingerprint of what its result depends on: the JSON of
// the options it reads, the input files it reads, and the fingerprint of
// the stage before it (so a change reaches every later stage), with the
// program's version. After a stage's outputs are complete (each written
// atomically), the pipeline records it in RESULTS/run_state.json with its
// fingerprint. A rerun skips a stage recorded complete with the same
// fingerprint whose outputs are all present, and runs from the first one
// that is not: changing an option reruns exactly the stages that read it
// and those after them. A stage that rewrites the outputs of an earlier
// one (the adjustment rewrites matches.csv) marks it; when the rewriting
// stage must run again, so must the earlier one, whose outputs are no
// longer its own. `from_stage` redoes from a named stage. Killing or
// cancelling a run therefore loses at most the stage in progress, and the
// rerun gives the same results as an uninterrupted run because every stage
// is deterministic.
#ifndef ZEBRAGEO_PIPELINE_RUN_STATE_H_
#define ZEBRAGEO_PIPELINE_RUN_STATE_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/progress.h"
#include "pipeline/report_stage.h"
#include "survey/cancellation.h"

namespace zebrageo {

inline constexpr char kRunStateFile[] = "run_state.json";

struct PipelineStage {
  std::string name;
  // Of what the stage's result depends on (StageFingerprint).
  std::string fingerprint;
  // Files (relative to the results folder) the stage writes.
  std::vector<std::string> outputs;
  // Earlier stages (names) whose outputs this one rewrites.
  std::vector<std::string> rewrites;
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

// A 64-bit FNV-1a hash of what a stage depends on, in hex.
class StageFingerprint {
 public:
  // Starts with the program (its version, and the running executable's
  // size and time: a rebuilt development binary keeps its version).
  StageFingerprint();

  StageFingerprint& Add(const std::string& text);
  // A file's path and contents (a missing file adds its path alone).
  StageFingerprint& AddFileContents(const std::string& path);
  // A file's path, size and modification time (images: their contents
  // would be read for nothing on every resume).
  StageFingerprint& AddFileStamp(const std::string& path);
  std::string Hex() const;

 private:
  void Mix(const char* data, size_t size);
  uint64_t hash_;
};

// Throws UsageError for an unknown from_stage, CancelledError when
// `cancel` is cancelled between stages (the stages check it inside).
PipelineRun RunPipeline(const std::string& results_folder,
                        const std::vector<PipelineStage>& stages,
                        const PipelineOptions& options,
                        const ProgressListener& progress = {},
                        const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_RUN_STATE_H_
