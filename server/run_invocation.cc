#include "server/run_invocation.h"

#include <algorithm>
#include <fstream>
#include <regex>
#include <sstream>

#include "pipeline/exit_codes.h"
#include "pipeline/run_options.h"
#include "survey/atomic_file.h"

namespace zebrageo {
namespace {

using nlohmann::json;

json ReadJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return json();
  return json::parse(in, nullptr, /*allow_exceptions=*/false);
}

// The stages of `zebrageo run`, in order, and what each counts for in the
// whole run's fraction (report included).
const std::vector<std::string> kStages = {"reconstruct", "match", "adjust"};

}  // namespace

std::string RunOptionsProblem(const json& options) {
  if (!options.is_object()) return "options: must be a JSON object";
  // The check of `zebrageo run --options FILE`: unknown members, wrong
  // types and refused values are named by their path.
  try {
    RunOptionsFromJson(options);
  } catch (const UsageError& error) {
    return std::string("options: ") + error.what();
  }
  return "";
}

json DefaultRunOptions() { return RunOptionsToJson(RunOptions()); }

std::vector<std::string> RunArguments(const std::string& survey,
                                      const JobFiles& files,
                                      const json& options) {
  std::vector<std::string> args = {"--log-level", "info", "run",
                                   survey,        "-o",   files.Results()};
  if (!options.empty()) {
    WriteFileAtomically(files.Options(), [&](std::ostream& out) {
      out << options.dump(1) << "\n";
    });
    args.push_back("--options");
    args.push_back(files.Options());
  }
  return args;
}

RunProgress ReadRunProgress(const JobFiles& files) {
  RunProgress progress;
  const json live = ReadJsonFile(files.Progress());
  if (live.is_object() && live.contains("fraction")) {
    progress.stage = live.value("stage", "");
    progress.step = live.value("step", "");
    progress.fraction = std::clamp(live.value("fraction", 0.0), 0.0, 1.0);
    return progress;
  }
  const json state = ReadJsonFile(files.Results() + "/run_state.json");
  if (!state.is_object() || !state.contains("stages")) return progress;
  const json& stages = state["stages"];
  int complete = 0;
  for (const std::string& stage : kStages) {
    if (!stages.contains(stage) || !stages[stage].is_object()) break;
    progress.stage = stage;
    if (!stages[stage].value("complete", false)) break;
    ++complete;
  }
  if (complete == static_cast<int>(kStages.size())) progress.stage = "report";
  double within = 0.0;
  // Within a stage: the run's last progress line in the log, "HH:MM:SS step:
  // done/total (NN%), S s" (tools/progress_bars.cc, every 10 % when stderr is
  // not a terminal; glog's "I... ] step: ..." with --log-level debug). The
  // lines of the stage's own name advance the fraction (the largest: a stage
  // never goes back); the last line names the step (the tie points inside
  // adjust).
  static const std::regex kLine(
      R"((?:\] |[0-9]{2}:[0-9]{2}:[0-9]{2} )([A-Za-z][A-Za-z ]*): ([0-9]+)/([0-9]+) \([0-9]+%\))");
  const std::string tail = LogTail(files.Log(), 40, 1 << 16);
  for (std::sregex_iterator it(tail.begin(), tail.end(), kLine), end; it != end;
       ++it) {
    progress.step = (*it)[1].str();
    const double done = std::stod((*it)[2].str());
    const double total = std::stod((*it)[3].str());
    if (progress.step == progress.stage && total > 0) {
      within = std::max(within, std::clamp(done / total, 0.0, 1.0));
    }
  }
  if (progress.step.empty() ||
      tail.find(progress.step + ": done in") != std::string::npos) {
    progress.step.clear();
  }
  progress.fraction = (complete + within) / (kStages.size() + 1.0);
  return progress;
}

std::string LogTail(const std::string& log_path, int lines, size_t max_bytes) {
  std::ifstream in(log_path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  const std::streamoff start = std::max<std::streamoff>(
      0, size - static_cast<std::streamoff>(max_bytes));
  in.seekg(start);
  std::string text(static_cast<size_t>(size - start), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  if (lines <= 0) return "";
  size_t position = text.size();
  if (position > 0 && text[position - 1] == '\n') --position;
  int seen = 0;
  while (position > 0) {
    const size_t newline = text.rfind('\n', position - 1);
    if (newline == std::string::npos) {
      position = 0;
      break;
    }
    if (++seen == lines) {
      position = newline + 1;
      break;
    }
    position = newline;
  }
  return text.substr(position);
}

std::string RunErrorFromLog(const std::string& log_path) {
  std::istringstream tail(LogTail(log_path, 200));
  const std::string prefix = "zebrageo: error: ";
  std::string error;
  for (std::string line; std::getline(tail, line);) {
    if (line.compare(0, prefix.size(), prefix) == 0) {
      error = line.substr(prefix.size());
    }
  }
  return error;
}

void ReadReportSummary(const JobFiles& files, json* warnings, json* timings) {
  const json report = ReadJsonFile(files.Results() + "/report.json");
  if (!report.is_object()) return;
  if (report.contains("warnings") && report["warnings"].is_array()) {
    *warnings = report["warnings"];
  }
  for (const char* key : {"timings_s"}) {
    if (report.contains(key)) {
      *timings = report[key];
      break;
    }
  }
}

}  // namespace zebrageo
