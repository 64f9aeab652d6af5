#include "pipeline/run_state.h"

#include <glog/logging.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/exit_codes.h"
#include "pipeline/progress.h"
#include "survey/atomic_file.h"
#include "tools/version.h"

namespace zebrageo {
namespace {

using nlohmann::json;

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
    if (!std::filesystem::is_regular_file(folder + "/" + output)) return false;
  }
  return true;
}

// The running executable's size and time: a rebuilt zebrageo (a development
// build keeps its version number) must not resume outputs of the old one.
std::string ExecutableStamp() {
  std::error_code error;
  const std::filesystem::path self =
      std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return "";
  const auto size = std::filesystem::file_size(self, error);
  if (error) return "";
  const auto time = std::filesystem::last_write_time(self, error);
  if (error) return "";
  std::ostringstream stamp;
  stamp << size << ":" << time.time_since_epoch().count();
  return stamp.str();
}

}  // namespace

std::string InputFingerprint(const std::vector<std::string>& input_files,
                             const std::string& settings) {
  std::ostringstream text;
  text << ZEBRAGEO_VERSION_STRING << "|" << ExecutableStamp() << "|"
       << settings;
  for (const std::string& file : input_files) {
    std::error_code error;
    const auto size = std::filesystem::file_size(file, error);
    const auto time = std::filesystem::last_write_time(file, error);
    text << "|" << file << ":" << (error ? 0 : size) << ":"
         << time.time_since_epoch().count();
  }
  std::ostringstream hex;
  hex << std::hex << std::hash<std::string>()(text.str());
  return hex.str();
}

PipelineRun RunPipeline(const std::string& results_folder,
                        const std::string& fingerprint,
                        const std::vector<PipelineStage>& stages,
                        const PipelineOptions& options,
                        const ProgressListener& progress) {
  int from_index = -1;
  if (!options.from_stage.empty()) {
    for (size_t i = 0; i < stages.size(); ++i) {
      if (stages[i].name == options.from_stage)
        from_index = static_cast<int>(i);
    }
    if (from_index < 0) {
      std::string names;
      for (const PipelineStage& stage : stages) names += " " + stage.name;
      throw UsageError("--from " + options.from_stage +
                       ": not a stage (stages:" + names + ")");
    }
  }
  std::filesystem::create_directories(results_folder);
  RemoveStaleTemporaries(results_folder);
  const std::string state_path = results_folder + "/" + kRunStateFile;
  json state = ReadState(state_path);
  if (state.value("fingerprint", "") != fingerprint) {
    state = json{{"fingerprint", fingerprint}, {"stages", json::object()}};
  }

  PipelineRun run;
  bool must_run = false;  // once a stage runs, every later one runs too
  for (size_t i = 0; i < stages.size(); ++i) {
    const PipelineStage& stage = stages[i];
    json& record = state["stages"][stage.name];
    must_run =
        must_run || (from_index >= 0 && static_cast<int>(i) >= from_index);
    const bool complete = record.is_object() &&
                          record.value("complete", false) &&
                          OutputsPresent(results_folder, stage);
    if (!must_run && complete) {
      LOG(INFO) << stage.name << ": complete in a previous run, resumed";
      run.timings.push_back({stage.name, record.value("seconds", 0.0), true});
      for (const json& w : record.value("warnings", json::array())) {
        run.warnings.push_back(w.get<std::string>());
      }
      continue;
    }
    must_run = true;
    // Record the stage as incomplete before it starts, so a kill during it
    // never leaves it looking complete.
    record = json{{"complete", false}};
    WriteState(state_path, state);
    StepProgress step(progress, stage.name);
    const std::vector<std::string> warnings = stage.run(step.Callback());
    step.Finish();
    const double seconds = step.ElapsedSeconds();
    record =
        json{{"complete", true}, {"seconds", seconds}, {"warnings", warnings}};
    WriteState(state_path, state);
    run.timings.push_back({stage.name, seconds, false});
    run.warnings.insert(run.warnings.end(), warnings.begin(), warnings.end());
  }
  return run;
}

}  // namespace zebrageo
