// Killing the real `zebrageo run` with SIGKILL in the middle of a stage and
// running it again gives the results of an uninterrupted run, resumes the
// stages that were complete, and leaves no temporary file.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

extern char** environ;

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string> kCompared = {"reconstructed_bands.csv",
                                            "matches.csv",
                                            "crossing_decisions.csv",
                                            "trajectory_corrected.csv",
                                            "poses.csv",
                                            "gcp_residuals.csv",
                                            "bands.geojson"};

// Numbers of a text file (comments skipped), in order; other tokens as text.
std::vector<std::string> Tokens(const std::string& path) {
  std::vector<std::string> tokens;
  std::istringstream in(ReadWholeFile(path));
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '#') continue;  // timings in comments
    std::string token;
    for (char c : line) {
      if (c == ',' || c == ' ' || c == '[' || c == ']' || c == '{' ||
          c == '}' || c == ':') {
        if (!token.empty()) tokens.push_back(token);
        token.clear();
      } else {
        token += c;
      }
    }
    if (!token.empty()) tokens.push_back(token);
  }
  return tokens;
}

// Same tokens; numbers equal to 1e-9 + 1e-11 relative (the multi-threaded
// solver may differ in the last bits; a stage resumed from a wrong or
// partial input would differ by centimetres).
void ExpectSameResults(const std::string& a, const std::string& b) {
  for (const std::string& file : kCompared) {
    SCOPED_TRACE(file);
    const std::vector<std::string> ta = Tokens(a + "/" + file);
    const std::vector<std::string> tb = Tokens(b + "/" + file);
    ASSERT_EQ(ta.size(), tb.size());
    ASSERT_FALSE(ta.empty());
    int differences = 0;
    for (size_t i = 0; i < ta.size() && differences < 5; ++i) {
      if (ta[i] == tb[i]) continue;
      char* end_a = nullptr;
      char* end_b = nullptr;
      const double va = std::strtod(ta[i].c_str(), &end_a);
      const double vb = std::strtod(tb[i].c_str(), &end_b);
      const bool numbers = *end_a == '\0' && *end_b == '\0';
      if (numbers && std::abs(va - vb) <= 1e-9 + 1e-11 * std::abs(va)) {
        continue;
      }
      ++differences;
      ADD_FAILURE() << "token " << i << ": " << ta[i] << " vs " << tb[i];
    }
  }
}

// Starts `zebrageo ARGS...` with stdout and stderr to /dev/null.
pid_t Spawn(const std::vector<std::string>& args) {
  std::vector<std::string> argv_strings = {ZEBRAGEO_BINARY};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& s : argv_strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int error =
      posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// True while run_state.json records `stage` as started, not complete.
bool StageInProgress(const std::string& results, const std::string& stage) {
  const std::string text = ReadWholeFile(results + "/run_state.json");
  if (!json::accept(text)) return false;
  const json state = json::parse(text);
  return state.contains("stages") && state["stages"].contains(stage) &&
         !state["stages"][stage].value("complete", true);
}

class RunResume : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    survey_ = folder_->Path("survey");
    reference_ = folder_->Path("reference");
    ASSERT_EQ(RunZebrageo("--log-level error simulate " +
                              SmallSurveyArguments() + " -o " + Quote(survey_),
                          folder_->Path("sim.out"), folder_->Path("sim.err")),
              0)
        << ReadWholeFile(folder_->Path("sim.err"));
    ASSERT_EQ(RunZebrageo("--log-level error run " + Quote(survey_) + " -o " +
                              Quote(reference_),
                          folder_->Path("ref.out"), folder_->Path("ref.err")),
              0)
        << ReadWholeFile(folder_->Path("ref.err"));
  }
  static void TearDownTestSuite() { delete folder_; }

  // Kills a run with SIGKILL `delay` after `stage` starts, reruns it, and
  // compares with the uninterrupted reference.
  void KillDuringStageThenRerun(const std::string& stage,
                                std::chrono::milliseconds delay) {
    const std::string results = folder_->Path("killed-in-" + stage);
    const pid_t pid =
        Spawn({"--log-level", "error", "run", survey_, "-o", results});
    ASSERT_GT(pid, 0);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (!StageInProgress(results, stage) &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    std::this_thread::sleep_for(delay);
    kill(pid, SIGKILL);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status))
        << "the run ended before the kill: the test did not interrupt "
        << stage;
    ASSERT_TRUE(StageInProgress(results, stage)) << "killed after " << stage;

    const std::string err = folder_->Path(stage + ".err");
    ASSERT_EQ(RunZebrageo("run " + Quote(survey_) + " -o " + Quote(results),
                          folder_->Path(stage + ".out"), err),
              0)
        << ReadWholeFile(err);
    ExpectSameResults(reference_, results);
    for (const std::string& file : FilesUnder(results)) {
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
    }
    const json report = json::parse(ReadWholeFile(results + "/report.json"));
    const json resumed = report.at("resumed_stages");
    EXPECT_EQ(std::find(resumed.begin(), resumed.end(), stage), resumed.end())
        << "the killed stage was redone";
    if (stage == "adjust") {
      EXPECT_NE(std::find(resumed.begin(), resumed.end(), "reconstruct"),
                resumed.end())
          << "the stages before were resumed: " << resumed.dump();
    }
  }

  static TemporaryFolder* folder_;
  static std::string survey_, reference_;
};

TemporaryFolder* RunResume::folder_ = nullptr;
std::string RunResume::survey_;
std::string RunResume::reference_;

TEST_F(RunResume, KilledDuringReconstructThenRerunGivesTheSameResults) {
  KillDuringStageThenRerun("reconstruct", std::chrono::milliseconds(300));
}

TEST_F(RunResume, KilledDuringAdjustThenRerunGivesTheSameResults) {
  KillDuringStageThenRerun("adjust", std::chrono::milliseconds(50));
}

// SIGINT while the adjust stage runs: the run stops at its next checkpoint
// (between solves), exits 6 ("cancelled"), leaves no file half-written and
// none of the stage's outputs; the rerun resumes to the reference results.
TEST_F(RunResume, CancelledDuringAdjustThenRerunGivesTheSameResults) {
  const std::string results = folder_->Path("cancelled");
  const pid_t pid =
      Spawn({"--log-level", "error", "run", survey_, "-o", results});
  ASSERT_GT(pid, 0);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (!StageInProgress(results, "adjust") &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal";
  ASSERT_EQ(WEXITSTATUS(status), 6) << "the run ended before the cancel";
  ASSERT_TRUE(StageInProgress(results, "adjust"));
  for (const std::string& file : FilesUnder(results)) {
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
  }
  for (const char* file :
       {"trajectory_corrected.csv", "poses.csv", "gcp_residuals.csv",
        "bands.geojson", "adjustment.json", "report.json"}) {
    EXPECT_FALSE(fs::exists(results + "/" + file)) << file;
  }
  const std::string err = folder_->Path("cancelled.err");
  ASSERT_EQ(RunZebrageo("run " + Quote(survey_) + " -o " + Quote(results),
                        folder_->Path("cancelled.out"), err),
            0)
      << ReadWholeFile(err);
  ExpectSameResults(reference_, results);
}

// The stages report.json lists as resumed.
std::vector<std::string> ResumedStages(const std::string& results) {
  const json report = json::parse(ReadWholeFile(results + "/report.json"));
  return report.at("resumed_stages").get<std::vector<std::string>>();
}

// One option changed through --options reruns the stages that read it
// (and those after them), and only those: an adjustment option resumes
// the reconstruction; the match stage runs again because the adjustment
// rewrote its matches.csv (pipeline/run_state.h). The same options again
// resume everything, and a report option reruns no stage.
TEST_F(RunResume, AChangedOptionRerunsTheStagesThatReadIt) {
  const std::string results = folder_->Path("options");
  fs::copy(reference_, results, fs::copy_options::recursive);
  const std::string options = folder_->Write(
      "sideslip.json",
      R"({"adjustment": {"vehicle_motion": {"sideslip_sigma_rad": 0.0035}}})");
  const std::string run = "run " + Quote(survey_) + " -o " + Quote(results);
  const std::string err = folder_->Path("options.err");
  ASSERT_EQ(RunZebrageo(run + " --options " + Quote(options),
                        folder_->Path("options.out"), err),
            0)
      << ReadWholeFile(err);
  EXPECT_EQ(ResumedStages(results), std::vector<std::string>{"reconstruct"});
  // The option reached the adjustment: another trajectory.
  EXPECT_NE(ReadWholeFile(results + "/trajectory_corrected.csv"),
            ReadWholeFile(reference_ + "/trajectory_corrected.csv"));

  ASSERT_EQ(RunZebrageo(run + " --options " + Quote(options),
                        folder_->Path("options.out"), err),
            0)
      << ReadWholeFile(err);
  EXPECT_EQ(ResumedStages(results),
            (std::vector<std::string>{"reconstruct", "match", "adjust"}));

  const std::string report_options =
      folder_->Write("report.json", R"({"adjustment": {"vehicle_motion":
         {"sideslip_sigma_rad": 0.0035}}, "report": {"max_sigma0": 1.5}})");
  ASSERT_EQ(RunZebrageo(run + " --options " + Quote(report_options),
                        folder_->Path("options.out"), err),
            0)
      << ReadWholeFile(err);
  EXPECT_EQ(ResumedStages(results),
            (std::vector<std::string>{"reconstruct", "match", "adjust"}));
}

// `run --print-options` prints every option, and an options file is
// checked before anything runs: a member it does not know, or a value out
// of range, is a usage error naming it.
TEST_F(RunResume, OptionsAreCheckedAndPrinted) {
  const std::string out = folder_->Path("print.out");
  const std::string err = folder_->Path("print.err");
  ASSERT_EQ(RunZebrageo("run --print-options", out, err), 0)
      << ReadWholeFile(err);
  const json printed = json::parse(ReadWholeFile(out));
  EXPECT_EQ(printed.at("adjustment").at("model").at("knot_spacing_s"), 1.0);
  EXPECT_TRUE(printed.at("lines").get<bool>());

  const std::string unknown =
      folder_->Write("unknown.json", R"({"adjustment": {"knots": 2}})");
  const std::string results = folder_->Path("refused");
  EXPECT_EQ(RunZebrageo("run " + Quote(survey_) + " -o " + Quote(results) +
                            " --options " + Quote(unknown),
                        out, err),
            2);
  EXPECT_NE(ReadWholeFile(err).find("adjustment.knots: not an option"),
            std::string::npos)
      << ReadWholeFile(err);
  EXPECT_FALSE(fs::exists(results));

  const std::string bad = folder_->Write(
      "bad.json", R"({"matching": {"max_drift_m": -1}, "lines": false})");
  ASSERT_EQ(
      RunZebrageo("run --print-options --no-rematch --options " + Quote(bad),
                  out, err),
      2);
  EXPECT_NE(ReadWholeFile(err).find("matching.max_drift_m = -1: must be > 0"),
            std::string::npos)
      << ReadWholeFile(err);
  // The flags apply over the file.
  const std::string lines_off =
      folder_->Write("lines.json", R"({"lines": false})");
  ASSERT_EQ(RunZebrageo("run --print-options --no-rematch --options " +
                            Quote(lines_off),
                        out, err),
            0);
  const json applied = json::parse(ReadWholeFile(out));
  EXPECT_FALSE(applied.at("lines").get<bool>());
  EXPECT_FALSE(applied.at("rematch").get<bool>());
}

}  // namespace
}  // namespace zebrageo
