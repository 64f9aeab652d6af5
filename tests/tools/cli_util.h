// Helpers for tests that drive the real `zebrageo` binary.
#ifndef ZEBRAGEO_TESTS_TOOLS_CLI_UTIL_H_
#define ZEBRAGEO_TESTS_TOOLS_CLI_UTIL_H_

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace zebrageo {

inline std::string Quote(const std::string& s) { return "'" + s + "'"; }

// Runs `zebrageo ARGS` through the shell with stdout and stderr captured to
// files. Returns the exit status, or 128 + the signal that killed it.
inline int RunZebrageo(const std::string& args, const std::string& out_path,
                       const std::string& err_path) {
  const std::string command = Quote(ZEBRAGEO_BINARY) + " " + args + " >" +
                              Quote(out_path) + " 2>" + Quote(err_path);
  const int status = std::system(command.c_str());
  if (status == -1) return -1;
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  // The shell reports a child killed by a signal as 128 + signal.
  return WEXITSTATUS(status);
}

inline std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Every regular file under `folder`, relative to it.
inline std::vector<std::string> FilesUnder(const std::string& folder) {
  std::vector<std::string> files;
  if (!std::filesystem::is_directory(folder)) return files;
  for (const auto& entry :
       std::filesystem::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file()) {
      files.push_back(std::filesystem::relative(entry.path(), folder).string());
    }
  }
  return files;
}

// ../shared/tools/score_results.py (independent of zebrageo; it picks its
// own python3) beside the repository.
inline std::string Scorer() {
  return std::string(ZEBRAGEO_SHARED_DIR) + "/tools/score_results.py";
}

// score_results.py MODE SURVEY RESULTS FLAGS: whether it passed (exit 0)
// and what it printed (also written to `out_path`).
struct Score {
  bool passed = false;
  std::string text;
};
inline Score ScoreResults(const std::string& mode, const std::string& survey,
                          const std::string& results, const std::string& flags,
                          const std::string& out_path) {
  const int status = std::system(
      ("python3 " + Quote(Scorer()) + " " + mode + " " + Quote(survey) + " " +
       Quote(results) + " " + flags + " > " + Quote(out_path) + " 2>&1")
          .c_str());
  Score score;
  score.passed = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  score.text = ReadWholeFile(out_path);
  return score;
}

// The horizontal RMSE after ("after: H 4.3 cm") of score_results.py poses,
// metres; -1 when absent.
inline double HorizontalAfterM(const std::string& poses_output) {
  std::smatch match;
  const std::regex after(R"(after: H ([0-9.]+) cm)");
  if (!std::regex_search(poses_output, match, after)) return -1.0;
  return 0.01 * std::stod(match[1].str());
}

// `zebrageo simulate SIMULATE_ARGS -o SURVEY`, then `zebrageo run SURVEY
// -o RESULTS --threads 2`, as a user runs them, their output kept in
// `log_folder`. Returns "" or which step failed with its stderr.
inline std::string SimulateAndRun(const std::string& simulate_args,
                                  const std::string& survey,
                                  const std::string& results,
                                  const std::string& log_folder) {
  const std::string log = log_folder + "/";
  if (RunZebrageo("--log-level error simulate " + simulate_args + " -o " +
                      Quote(survey),
                  log + "simulate.out", log + "simulate.err") != 0) {
    return "simulate failed: " + ReadWholeFile(log + "simulate.err");
  }
  if (RunZebrageo("--log-level warning run " + Quote(survey) + " -o " +
                      Quote(results) + " --threads 2",
                  log + "run.out", log + "run.err") != 0) {
    return "run failed: " + ReadWholeFile(log + "run.err");
  }
  return "";
}

// A small survey (80 m, 2 crossings, 640x480 images, ~20 exposures) that
// the whole pipeline processes in a few seconds.
inline std::string SmallSurveyArguments() {
  return "--preset demo --seed 1 --set road_length_m=80 --set "
         "num_crossings=2 --set num_stale_crossings=0 --set "
         "min_crossing_spacing_m=25 --set image_width=640 --set "
         "image_height=480 --set focal_px=560 --set supersampling=2 --set "
         "exposure_spacing_m=4";
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_TOOLS_CLI_UTIL_H_
