// One process running several surveys (pipeline/pipeline.h's RunContext):
// two runs side by side, each with its own log, give the results of one
// run alone; a run cancelled in the middle of its adjust stage stops there,
// leaves no file half-written and no output of that stage, and resumes to
// the same results. One small simulated survey (about 10 s of CPU per run).
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/pipeline.h"
#include "pipeline/run_state.h"
#include "simulator/simulator.h"
#include "survey/cancellation.h"
#include "survey/results.h"
#include "survey/run_log.h"
#include "survey/threads.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

std::string TextOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The results of the contract and the stage outputs that a resumed or
// cancelled run must reproduce. Numbers must be equal to 1e-9: the solver's
// threads change the last bits only.
const char* const kCompared[] = {
    kReconstructedBandsFile,  kMatchesFile, kCrossingDecisionsFile,
    kTrajectoryCorrectedFile, kPosesFile,   kGcpResidualsFile};

void ExpectSameNumbers(const std::string& a, const std::string& b) {
  for (const char* file : kCompared) {
    SCOPED_TRACE(file);
    std::istringstream in_a(TextOf(a + "/" + file));
    std::istringstream in_b(TextOf(b + "/" + file));
    std::string line_a, line_b;
    int line = 0;
    while (std::getline(in_a, line_a)) {
      ++line;
      ASSERT_TRUE(std::getline(in_b, line_b)) << "line " << line;
      if (line_a == line_b || line_a[0] == '#') continue;  // timings
      std::istringstream fa(line_a), fb(line_b);
      std::string ta, tb;
      while (std::getline(fa, ta, ',')) {
        ASSERT_TRUE(std::getline(fb, tb, ','));
        if (ta == tb) continue;
        EXPECT_NEAR(std::stod(ta), std::stod(tb),
                    1e-9 * std::max(1.0, std::abs(std::stod(ta))))
            << "line " << line;
      }
    }
    EXPECT_FALSE(std::getline(in_b, line_b)) << "more lines in " << b;
  }
}

class RunContextTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    SimulationOptions simulation;
    ASSERT_EQ(ApplyPreset("demo", &simulation), "");
    for (const char* knob :
         {"road_length_m=80", "num_crossings=2", "num_stale_crossings=0",
          "min_crossing_spacing_m=25", "image_width=640", "image_height=480",
          "focal_px=560", "supersampling=2", "exposure_spacing_m=4"}) {
      ASSERT_EQ(SetOption(knob, &simulation), "") << knob;
    }
    SimulateSurvey(simulation, folder_->Path("survey"), {});
    survey_ = new Survey(LoadSurvey(folder_->Path("survey")));
  }
  static void TearDownTestSuite() {
    delete survey_;
    delete folder_;
  }

  static RunOptions Options() {
    RunOptions options;
    options.tie_points = false;  // the adjust stage's solves, not the images
    options.threads = 1;
    options.reconstruction.threads = 1;
    options.adjustment.solver.num_threads = 1;
    return options;
  }

  static TemporaryFolder* folder_;
  static Survey* survey_;
};

TemporaryFolder* RunContextTest::folder_ = nullptr;
Survey* RunContextTest::survey_ = nullptr;

// Two runs in two threads, each with its own RunLog: each log holds its
// own run's lines (and its stages' worker threads'), none of the other's,
// and both give the same results.
TEST_F(RunContextTest, TwoRunsSideBySideKeepTheirLogsApart) {
  const std::string a = folder_->Path("side_a");
  const std::string b = folder_->Path("side_b");
  std::vector<std::string> lines_a, lines_b;
  RunLog log_a([&](int, const std::string& line) { lines_a.push_back(line); });
  RunLog log_b([&](int, const std::string& line) { lines_b.push_back(line); });
  auto run = [](const std::string& results, RunLog* log) {
    RunContext context;
    context.log = log;
    RunSurveyPipeline(*survey_, results, Options(), context);
  };
  std::thread thread_a(run, a, &log_a);
  std::thread thread_b(run, b, &log_b);
  thread_a.join();
  thread_b.join();
  auto holds = [](const std::vector<std::string>& lines,
                  const std::string& text) {
    for (const std::string& line : lines) {
      if (line.find(text) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(holds(lines_a, "-> " + a));
  EXPECT_FALSE(holds(lines_a, "-> " + b));
  EXPECT_TRUE(holds(lines_b, "-> " + b));
  EXPECT_FALSE(holds(lines_b, "-> " + a));
  for (const auto* lines : {&lines_a, &lines_b}) {
    EXPECT_TRUE(holds(*lines, "reconstruct: "));
    EXPECT_TRUE(holds(*lines, "match: "));
    EXPECT_TRUE(holds(*lines, "adjust: "));
  }
  ExpectSameNumbers(a, b);
  // A worker thread of ParallelFor logs to its caller's run log.
  std::vector<std::string> worker_lines;
  RunLog worker_log(
      [&](int, const std::string& line) { worker_lines.push_back(line); });
  {
    const ScopedRunLog scope(&worker_log);
    ParallelFor(4, 2, [](int k) { LOG(INFO) << "worker item " << k; });
  }
  EXPECT_EQ(worker_lines.size(), 4u);
}

// Cancelled while the adjust stage solves: CancelledError, the stage is
// recorded incomplete, none of its files (and no temporary file) is in the
// folder, and the stages before it are whole; the rerun resumes them and
// gives the results of an uninterrupted run.
TEST_F(RunContextTest, ACancelledRunLeavesNothingHalfWrittenAndResumes) {
  const std::string reference = folder_->Path("reference");
  RunSurveyPipeline(*survey_, reference, Options());
  const std::string results = folder_->Path("cancelled");
  RunContext context;
  context.cancel = CancellationToken::Cancellable();
  std::atomic<int> solves{0};
  context.progress = [&](const ProgressEvent& event) {
    // The first solve of the first adjustment is done: cancel during the
    // next ones.
    if (event.step == "adjust" &&
        event.kind == ProgressEvent::Kind::kAdvanced && ++solves == 1) {
      context.cancel.Cancel();
    }
  };
  EXPECT_THROW(RunSurveyPipeline(*survey_, results, Options(), context),
               CancelledError);
  EXPECT_EQ(solves.load(), 1);
  const nlohmann::json state =
      nlohmann::json::parse(TextOf(results + "/" + kRunStateFile));
  EXPECT_TRUE(state["stages"]["match"]["complete"].get<bool>());
  EXPECT_FALSE(state["stages"]["adjust"]["complete"].get<bool>());
  for (const char* file :
       {kTrajectoryCorrectedFile, kPosesFile, kGcpResidualsFile,
        kBandsGeoJsonFile, "adjustment.json", "report.json"}) {
    EXPECT_FALSE(fs::exists(results + "/" + file)) << file;
  }
  for (const auto& entry : fs::directory_iterator(results)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos)
        << entry.path();
  }
  // The stages before it are whole (their readers accept them).
  EXPECT_FALSE(ReadReconstructedBands(results + "/" + kReconstructedBandsFile,
                                      kReconstructedBandsFile)
                   .empty());
  EXPECT_FALSE(ReadMatches(results + "/" + kMatchesFile, kMatchesFile).empty());

  const RunSummary resumed = RunSurveyPipeline(*survey_, results, Options());
  ASSERT_EQ(resumed.timings.size(), 3u);
  EXPECT_TRUE(resumed.timings[0].resumed);   // reconstruct
  EXPECT_FALSE(resumed.timings[2].resumed);  // adjust
  ExpectSameNumbers(reference, results);
}

TEST(Cancellation, ATokenOnlyItsOwnerCancels) {
  const CancellationToken never;
  never.Cancel();
  EXPECT_FALSE(never.IsCancelled());
  EXPECT_NO_THROW(never.ThrowIfCancelled());
  const CancellationToken token = CancellationToken::Cancellable();
  const CancellationToken copy = token;
  EXPECT_FALSE(copy.IsCancelled());
  token.Cancel();
  EXPECT_TRUE(copy.IsCancelled());
  EXPECT_THROW(copy.ThrowIfCancelled(), CancelledError);
}

// ParallelFor stops handing out items after a worker throws, and rethrows.
TEST(Cancellation, ParallelForStopsAndRethrows) {
  std::atomic<int> ran{0};
  EXPECT_THROW(
      ParallelFor(1000, 2,
                  [&](int k) {
                    ++ran;
                    if (k == 3) throw CancelledError();
                    std::this_thread::sleep_for(std::chrono::microseconds(200));
                  }),
      CancelledError);
  EXPECT_LT(ran.load(), 1000);
}

}  // namespace
}  // namespace zebrageo
