#include "pipeline/run_state.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/exit_codes.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

// Three stages that each write one file and count their runs.
struct FakeStages {
  explicit FakeStages(std::string folder) : folder(std::move(folder)) {}

  std::vector<PipelineStage> Stages() {
    std::vector<PipelineStage> stages;
    for (int i = 0; i < 3; ++i) {
      const std::string name = "stage" + std::to_string(i);
      stages.push_back(
          {name, {name + ".txt"}, [this, i, name](const auto& progress) {
             ++runs[i];
             if (fail_at == i) throw std::runtime_error("killed");
             progress(1, 1);
             std::ofstream(folder + "/" + name + ".txt") << runs[i];
             return std::vector<std::string>{name + " warning"};
           }});
    }
    return stages;
  }

  std::string folder;
  int runs[3] = {0, 0, 0};
  int fail_at = -1;
};

TEST(Pipeline, RunsEveryStageOnceThenResumesEverything) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  PipelineRun run = RunPipeline(folder.Path(), "f1", fake.Stages(), {});
  EXPECT_EQ(run.timings.size(), 3u);
  EXPECT_EQ(run.warnings.size(), 3u);
  run = RunPipeline(folder.Path(), "f1", fake.Stages(), {});
  for (int i = 0; i < 3; ++i) EXPECT_EQ(fake.runs[i], 1);
  for (const StageTiming& t : run.timings) EXPECT_TRUE(t.resumed);
  // Warnings of resumed stages are kept for the report.
  EXPECT_EQ(run.warnings.size(), 3u);
}

TEST(Pipeline, AKilledStageIsRedoneAndEarlierOnesResumed) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  fake.fail_at = 1;
  EXPECT_THROW(RunPipeline(folder.Path(), "f1", fake.Stages(), {}),
               std::runtime_error);
  fake.fail_at = -1;
  const PipelineRun run = RunPipeline(folder.Path(), "f1", fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 1);
  EXPECT_TRUE(run.timings[0].resumed);
  EXPECT_FALSE(run.timings[1].resumed);
}

TEST(Pipeline, FromStageRedoesThatStageAndTheLaterOnes) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  RunPipeline(folder.Path(), "f1", fake.Stages(), {});
  RunPipeline(folder.Path(), "f1", fake.Stages(), {"stage1"});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 2);
  EXPECT_THROW(RunPipeline(folder.Path(), "f1", fake.Stages(), {"nope"}),
               UsageError);
}

TEST(Pipeline, ChangedInputsOrMissingOutputsRunAgain) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  RunPipeline(folder.Path(), "f1", fake.Stages(), {});
  RunPipeline(folder.Path(), "f2", fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 2);
  std::filesystem::remove(folder.Path("stage2.txt"));
  RunPipeline(folder.Path(), "f2", fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 2);
  EXPECT_EQ(fake.runs[2], 3);
}

TEST(Pipeline, FingerprintChangesWithInputsAndSettings) {
  TemporaryFolder folder;
  const std::string file = folder.Write("a.csv", "1\n");
  const std::string f1 = InputFingerprint({file}, "x");
  EXPECT_EQ(InputFingerprint({file}, "x"), f1);
  EXPECT_NE(InputFingerprint({file}, "y"), f1);
  folder.Write("a.csv", "12\n");
  EXPECT_NE(InputFingerprint({file}, "x"), f1);
}

}  // namespace
}  // namespace zebrageo
