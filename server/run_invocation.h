// How a job becomes a `zebrageo run` command line, and how its progress and
// outcome are read back: the one place that knows the CLI's arguments,
// files and messages.
#ifndef ZEBRAGEO_SERVER_RUN_INVOCATION_H_
#define ZEBRAGEO_SERVER_RUN_INVOCATION_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace zebrageo {

// A job's folder under the data root: jobs/<id>/ holds survey/ (an
// upload's extraction), results/, log.txt, options.json, progress.json.
struct JobFiles {
  std::string folder;
  std::string Survey() const { return folder + "/survey"; }
  std::string Results() const { return folder + "/results"; }
  std::string Log() const { return folder + "/log.txt"; }
  std::string Options() const { return folder + "/options.json"; }
  std::string Progress() const { return folder + "/progress.json"; }
  std::string ResultsZip() const { return folder + "/results.zip"; }
};

// "" when `options` (RunOptions as JSON) would be accepted by `zebrageo
// run`, otherwise the CLI's own message for it.
std::string RunOptionsProblem(const nlohmann::json& options);
// RunOptions() with its defaults, as `zebrageo run --print-options` prints.
nlohmann::json DefaultRunOptions();

// The arguments of `zebrageo` (argv[1...]) that process `survey` into the
// job's results with its options (written to files.Options() first when
// there are any).
std::vector<std::string> RunArguments(const std::string& survey,
                                      const JobFiles& files,
                                      const nlohmann::json& options);

struct RunProgress {
  std::string stage;  // "" before the first
  std::string step;
  double fraction = 0.0;  // of the whole run
};
// What the child has done so far: its --progress-json file, or else which
// stages its results' run_state.json records.
RunProgress ReadRunProgress(const JobFiles& files);

// The CLI's error message in the log's last lines ("zebrageo: error: X"
// gives X), or "" when there is none.
std::string RunErrorFromLog(const std::string& log_path);
// The last `lines` lines of the log (at most `max_bytes` read).
std::string LogTail(const std::string& log_path, int lines,
                    size_t max_bytes = 1 << 20);

// report.json's warnings and stage timings, when it is there.
void ReadReportSummary(const JobFiles& files, nlohmann::json* warnings,
                       nlohmann::json* timings);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_RUN_INVOCATION_H_
