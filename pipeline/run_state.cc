#include "pipeline/run_state.h"

#include <glog/logging.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/exit_codes.h"
#include "pipeline/progress.h"
#include "pipeline/version.h"
#include "survey/atomic_file.h"
#include "survey/fnv_hash.h"

namespace zebrageo {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

json ReadState(const std::string& path) {
  std::ifstream in(path);
  if (!in) return json::object();
  try {
    json state = json::parse(in);
    return state.is_object() ? state : json::object();
  } catch (const json::exception&) {
    // An unreadable state only means nothing can be resumed.
    return json::object();
  }
}

void WriteState(const std::string& path, const json& state) {
  WriteFileAtomically(path,
                      [&](std::ostream& out) { out << state.dump(1) << "\n"; });
}

bool OutputsPresent(const std::string& folder, const PipelineStage& stage) {
  for (const std::string& output : stage.outputs) {
    if (!fs::is_regular_file(folder + "/" + output)) return false;
  }
  return true;
}

// The running executable's size and time: a rebuilt zebrageo (a development
// build keeps its version number) must not resume outputs of the old one.
std::string ExecutableStamp() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (error) return "";
  const auto size = fs::file_size(self, error);
  if (error) return "";
  const auto time = fs::last_write_time(self, error);
  if (error) return "";
  std::ostringstream stamp;
  stamp << size << ":" << time.time_since_epoch().count();
  return stamp.str();
}

int StageIndex(const std::vector<PipelineStage>& stages,
               const std::string& name) {
  for (size_t i = 0; i < stages.size(); ++i) {
    if (stages[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

// The index of the first stage to run: the named from_stage, the first
// that cannot be resumed (not recorded complete with its fingerprint, an
// output missing), or an earlier one whose outputs a stage that must run
// rewrote; stages.size() when everything resumes.
size_t FirstStageToRun(const std::string& folder,
                       const std::vector<PipelineStage>& stages,
                       const json& records, int from_index) {
  size_t first =
      from_index >= 0 ? static_cast<size_t>(from_index) : stages.size();
  for (size_t i = 0; i < first; ++i) {
    const json& record = records.value(stages[i].name, json::object());
    if (!record.value("complete", false) ||
        record.value("fingerprint", "") != stages[i].fingerprint ||
        !OutputsPresent(folder, stages[i])) {
      first = i;
    }
  }
  for (bool moved = true; moved;) {
    moved = false;
    for (size_t i = first; i < stages.size(); ++i) {
      for (const std::string& name : stages[i].rewrites) {
        const int j = StageIndex(stages, name);
        if (j >= 0 && static_cast<size_t>(j) < first &&
            records.value(name, json::object()).value("rewritten", false)) {
          first = static_cast<size_t>(j);
          moved = true;
        }
      }
    }
  }
  return first;
}

}  // namespace

StageFingerprint::StageFingerprint() : hash_(kFnv1aOffset) {
  Add(ZEBRAGEO_VERSION_STRING).Add(ExecutableStamp());
}

void StageFingerprint::Mix(const char* data, size_t size) {
  hash_ = Fnv1a(data, size, hash_);
}

StageFingerprint& StageFingerprint::Add(const std::string& text) {
  // The length first: "ab" + "c" and "a" + "bc" differ.
  const std::string length = std::to_string(text.size()) + ":";
  Mix(length.data(), length.size());
  Mix(text.data(), text.size());
  return *this;
}

StageFingerprint& StageFingerprint::AddFileContents(const std::string& path) {
  Add(path);
  std::ifstream in(path, std::ios::binary);
  char buffer[1 << 16];
  while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
    Mix(buffer, static_cast<size_t>(in.gcount()));
  }
  return *this;
}

StageFingerprint& StageFingerprint::AddFileStamp(const std::string& path) {
  std::error_code error;
  const auto size = fs::file_size(path, error);
  const auto time = fs::last_write_time(path, error);
  return Add(path + ":" + std::to_string(error ? 0 : size) + ":" +
             std::to_string(time.time_since_epoch().count()));
}

std::string StageFingerprint::Hex() const {
  std::ostringstream hex;
  hex << std::hex << hash_;
  return hex.str();
}

PipelineRun RunPipeline(const std::string& results_folder,
                        const std::vector<PipelineStage>& stages,
                        const PipelineOptions& options,
                        const ProgressListener& progress,
                        const CancellationToken& cancel) {
  const int from_index =
      options.from_stage.empty() ? -1 : StageIndex(stages, options.from_stage);
  if (!options.from_stage.empty() && from_index < 0) {
    std::string names;
    for (const PipelineStage& stage : stages) names += " " + stage.name;
    throw UsageError("--from " + options.from_stage +
                     ": not a stage (stages:" + names + ")");
  }
  fs::create_directories(results_folder);
  RemoveStaleTemporaries(results_folder);
  const std::string state_path = results_folder + "/" + kRunStateFile;
  json state = ReadState(state_path);
  if (!state.contains("stages") || !state["stages"].is_object()) {
    state = json{{"stages", json::object()}};
  }
  json& records = state["stages"];
  const size_t first =
      FirstStageToRun(results_folder, stages, records, from_index);

  PipelineRun run;
  for (size_t i = 0; i < stages.size(); ++i) {
    const PipelineStage& stage = stages[i];
    json& record = records[stage.name];
    if (i < first) {
      LOG(INFO) << stage.name << ": complete in a previous run, resumed";
      run.timings.push_back({stage.name, record.value("seconds", 0.0), true});
      for (const json& w : record.value("warnings", json::array())) {
        run.warnings.push_back(w.get<std::string>());
      }
      continue;
    }
    cancel.ThrowIfCancelled();
    // Recorded as incomplete before it starts, so a kill during it never
    // leaves it looking complete; the stages whose outputs it rewrites no
    // longer hold their own.
    record = json{{"complete", false}, {"fingerprint", stage.fingerprint}};
    for (const std::string& name : stage.rewrites) {
      records[name]["rewritten"] = true;
    }
    WriteState(state_path, state);
    StepProgress step(progress, stage.name);
    const std::vector<std::string> warnings = stage.run(step.Callback());
    step.Finish();
    const double seconds = step.ElapsedSeconds();
    record = json{{"complete", true},
                  {"fingerprint", stage.fingerprint},
                  {"seconds", seconds},
                  {"warnings", warnings}};
    WriteState(state_path, state);
    run.timings.push_back({stage.name, seconds, false});
    run.warnings.insert(run.warnings.end(), warnings.begin(), warnings.end());
  }
  return run;
}

}  // namespace zebrageo
