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

  // Stage i's fingerprint: fingerprints[i].
  std::vector<PipelineStage> Stages() {
    std::vector<PipelineStage> stages;
    for (int i = 0; i < 3; ++i) {
      const std::string name = "stage" + std::to_string(i);
      PipelineStage stage;
      stage.name = name;
      stage.fingerprint = fingerprints[i];
      stage.outputs = {name + ".txt"};
      if (i == 2 && stage2_rewrites_stage1) stage.rewrites = {"stage1"};
      stage.run = [this, i, name](const auto& progress) {
        ++runs[i];
        if (fail_at == i) throw std::runtime_error("killed");
        progress(1, 1);
        std::ofstream(folder + "/" + name + ".txt") << runs[i];
        return std::vector<std::string>{name + " warning"};
      };
      stages.push_back(stage);
    }
    return stages;
  }

  std::string folder;
  std::string fingerprints[3] = {"a", "b", "c"};
  bool stage2_rewrites_stage1 = false;
  int runs[3] = {0, 0, 0};
  int fail_at = -1;
};

TEST(Pipeline, RunsEveryStageOnceThenResumesEverything) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  PipelineRun run = RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(run.timings.size(), 3u);
  EXPECT_EQ(run.warnings.size(), 3u);
  run = RunPipeline(folder.Path(), fake.Stages(), {});
  for (int i = 0; i < 3; ++i) EXPECT_EQ(fake.runs[i], 1);
  for (const StageTiming& t : run.timings) EXPECT_TRUE(t.resumed);
  // Warnings of resumed stages are kept for the report.
  EXPECT_EQ(run.warnings.size(), 3u);
}

TEST(Pipeline, AKilledStageIsRedoneAndEarlierOnesResumed) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  fake.fail_at = 1;
  EXPECT_THROW(RunPipeline(folder.Path(), fake.Stages(), {}),
               std::runtime_error);
  fake.fail_at = -1;
  const PipelineRun run = RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 1);
  EXPECT_TRUE(run.timings[0].resumed);
  EXPECT_FALSE(run.timings[1].resumed);
}

TEST(Pipeline, FromStageRedoesThatStageAndTheLaterOnes) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  RunPipeline(folder.Path(), fake.Stages(), {});
  RunPipeline(folder.Path(), fake.Stages(), {"stage1"});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 2);
  EXPECT_THROW(RunPipeline(folder.Path(), fake.Stages(), {"nope"}), UsageError);
}

TEST(Pipeline, AChangedFingerprintRerunsThatStageAndTheLaterOnes) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  RunPipeline(folder.Path(), fake.Stages(), {});
  fake.fingerprints[1] = "b2";
  RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 2);
  std::filesystem::remove(folder.Path("stage2.txt"));
  RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 3);
}

// A stage that rewrites an earlier one's outputs (adjust: matches.csv)
// cannot run again on them: the earlier stage runs first.
TEST(Pipeline, ARewrittenStageRunsAgainBeforeTheStageThatRewroteIt) {
  TemporaryFolder folder;
  FakeStages fake(folder.Path());
  fake.stage2_rewrites_stage1 = true;
  RunPipeline(folder.Path(), fake.Stages(), {});
  RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[1], 1);
  fake.fingerprints[2] = "c2";
  RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 2);
  EXPECT_EQ(fake.runs[2], 2);
  // Killed during stage 2: stage 1's outputs may be rewritten already,
  // so stage 1 runs again (runs 3, then 4) before stage 2.
  fake.fail_at = 2;
  fake.fingerprints[2] = "c3";
  EXPECT_THROW(RunPipeline(folder.Path(), fake.Stages(), {}),
               std::runtime_error);
  fake.fail_at = -1;
  RunPipeline(folder.Path(), fake.Stages(), {});
  EXPECT_EQ(fake.runs[0], 1);
  EXPECT_EQ(fake.runs[1], 4);
  EXPECT_EQ(fake.runs[2], 4);
}

TEST(Pipeline, FingerprintChangesWithInputsAndSettings) {
  TemporaryFolder folder;
  const std::string file = folder.Write("a.csv", "1\n");
  const std::string f1 =
      StageFingerprint().AddFileContents(file).Add("x").Hex();
  EXPECT_EQ(StageFingerprint().AddFileContents(file).Add("x").Hex(), f1);
  EXPECT_NE(StageFingerprint().AddFileContents(file).Add("y").Hex(), f1);
  folder.Write("a.csv", "2\n");
  EXPECT_NE(StageFingerprint().AddFileContents(file).Add("x").Hex(), f1);
  // Text boundaries count.
  EXPECT_NE(StageFingerprint().Add("ab").Add("c").Hex(),
            StageFingerprint().Add("a").Add("bc").Hex());
}

}  // namespace
}  // namespace zebrageo
