// The server's parts without a server: paths confined to the data root,
// archive checks, the job store, the metrics text, and the OpenAPI file
// against the server's routes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "server/archive.h"
#include "server/confined_path.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/run_invocation.h"
#include "server/server.h"
#include "tests/server/server_test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

TEST(ConfinedPath, RelativePathsWithDotsOrRootsAreRefused) {
  EXPECT_EQ(RelativePathProblem("surveys/a"), "");
  EXPECT_EQ(RelativePathProblem("a/b/"), "");
  EXPECT_EQ(RelativePathProblem("images/cam0 000.png"), "");
  EXPECT_NE(RelativePathProblem(""), "");
  EXPECT_NE(RelativePathProblem("/etc"), "");
  EXPECT_NE(RelativePathProblem(".."), "");
  EXPECT_NE(RelativePathProblem("a/.."), "");
  EXPECT_NE(RelativePathProblem("a/../b"), "");
  EXPECT_NE(RelativePathProblem("./a"), "");
  EXPECT_NE(RelativePathProblem("a//b"), "");
  EXPECT_NE(RelativePathProblem("a\\..\\b"), "");
  EXPECT_NE(RelativePathProblem(std::string("a\0b", 3)), "");
  EXPECT_NE(RelativePathProblem("a\nb"), "");
  EXPECT_NE(RelativePathProblem(std::string(300, 'a')), "");
}

TEST(ConfinedPath, LinksOutOfTheRootAreFound) {
  TemporaryFolder folder;
  fs::create_directories(folder.Path("root/in/sub"));
  fs::create_directories(folder.Path("out"));
  folder.Write("root/in/sub/file", "x");
  folder.Write("out/secret", "x");
  const std::string root = fs::canonical(folder.Path("root")).string();
  std::string problem;
  EXPECT_TRUE(ResolveInside(root, "in/sub", &problem));
  EXPECT_FALSE(ResolveInside(root, "in/none", &problem));
  EXPECT_EQ(FolderEscapeProblem(root + "/in", root), "");
  fs::create_symlink(root + "/in/sub/file", root + "/in/inside-link");
  EXPECT_EQ(FolderEscapeProblem(root + "/in", root), "");
  fs::create_symlink(folder.Path("out/secret"), root + "/in/sub/leak");
  EXPECT_NE(
      FolderEscapeProblem(root + "/in", root).find("outside the data root"),
      std::string::npos);
  fs::create_directory_symlink(folder.Path("out"), root + "/out-link");
  EXPECT_FALSE(ResolveInside(root, "out-link", &problem));
  EXPECT_EQ(problem, "resolves outside the data root");
  EXPECT_FALSE(IsInside("/data/root", "/data/rootkit"));
  EXPECT_TRUE(IsInside("/data/root", "/data/root/a"));
}

TEST(Archive, AGoodArchiveExtractsAndABadOneIsRefusedBeforeAnyWrite) {
  TemporaryFolder folder;
  const ArchiveLimits limits;
  const std::string good = folder.Path("good.tar.gz");
  WriteTestArchive(good, "tar",
                   {{"./", AE_IFDIR, "", ""},
                    {"./s/", AE_IFDIR, "", ""},
                    {"./s/survey.yaml", AE_IFREG, "a: 1\n", ""}});
  EXPECT_EQ(ArchiveProblem(good, limits), "");
  ExtractArchive(good, folder.Path("out"), limits);
  EXPECT_EQ(ReadWholeFile(folder.Path("out/s/survey.yaml")), "a: 1\n");

  const std::string bad = folder.Path("bad.zip");
  WriteTestArchive(
      bad, "zip",
      {{"ok.txt", AE_IFREG, "x", ""}, {"../up.txt", AE_IFREG, "x", ""}});
  EXPECT_NE(ArchiveProblem(bad, limits).find("leaves its folder"),
            std::string::npos);
  EXPECT_THROW(ExtractArchive(bad, folder.Path("bad-out"), limits),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(folder.Path("up.txt")));

  ArchiveLimits tiny;
  tiny.max_total_bytes = 3;
  EXPECT_NE(ArchiveProblem(good, tiny).find("extracts to more than"),
            std::string::npos);
  tiny.max_total_bytes = 1 << 20;
  tiny.max_entries = 2;
  EXPECT_NE(ArchiveProblem(good, tiny).find("entries"), std::string::npos);
}

TEST(Archive, ZipOfAFolderHoldsItsFiles) {
  TemporaryFolder folder;
  folder.Write("results/poses.csv", "t,x\n1,2\n");
  folder.Write("results/.zebrageo.lock", "1");
  WriteZipOfFolder(
      folder.Path("results"), "r",
      [](const std::string& name) { return name[0] != '.'; },
      folder.Path("r.zip"));
  ExtractArchive(folder.Path("r.zip"), folder.Path("back"), ArchiveLimits());
  EXPECT_EQ(ReadWholeFile(folder.Path("back/r/poses.csv")), "t,x\n1,2\n");
  EXPECT_FALSE(fs::exists(folder.Path("back/r/.zebrageo.lock")));
}

TEST(JobStore, JobsSurviveReopeningInOrder) {
  TemporaryFolder folder;
  const std::string path = folder.Path("jobs.sqlite");
  {
    JobStore store(path);
    for (const char* id : {"00000000000000b2", "00000000000000a1"}) {
      Job job;
      job.id = id;
      job.name = std::string("job ") + id;
      job.options = {{"lines", false}};
      store.Insert(job);
    }
    Job running = *store.Get("00000000000000a1");
    running.state = JobState::kRunning;
    running.attempts = 1;
    EXPECT_TRUE(store.Update(running));
    Job unknown;
    unknown.id = "ffffffffffffffff";
    EXPECT_FALSE(store.Update(unknown));
  }
  JobStore store(path);
  const std::vector<Job> jobs = store.List();
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].id, "00000000000000b2");  // insertion order, not id
  EXPECT_EQ(jobs[1].state, JobState::kRunning);
  EXPECT_EQ(jobs[1].attempts, 1);
  EXPECT_EQ(jobs[1].options["lines"], false);
  EXPECT_EQ(store.NextQueued()->id, "00000000000000b2");
  EXPECT_EQ(store.CountByState().at(JobState::kRunning), 1);
  EXPECT_TRUE(store.Remove("00000000000000b2"));
  EXPECT_FALSE(store.NextQueued());
}

TEST(Metrics, RendersThePrometheusTextFormat) {
  Metrics metrics;
  metrics.Declare("zebrageo_jobs", "Jobs.", "gauge");
  metrics.Declare("zebrageo_seconds", "Seconds.", "histogram", {1, 10});
  metrics.Set("zebrageo_jobs", {{"state", "do\"ne"}}, 3);
  metrics.Observe("zebrageo_seconds", {{"stage", "match"}}, 0.5);
  metrics.Observe("zebrageo_seconds", {{"stage", "match"}}, 5);
  const std::string text = metrics.Render();
  EXPECT_NE(text.find("# TYPE zebrageo_jobs gauge\n"), std::string::npos);
  EXPECT_NE(text.find("zebrageo_jobs{state=\"do\\\"ne\"} 3\n"),
            std::string::npos);
  EXPECT_NE(text.find("zebrageo_seconds_bucket{stage=\"match\",le=\"1\"} 1\n"),
            std::string::npos)
      << text;
  EXPECT_NE(
      text.find("zebrageo_seconds_bucket{stage=\"match\",le=\"+Inf\"} 2\n"),
      std::string::npos);
  EXPECT_NE(text.find("zebrageo_seconds_sum{stage=\"match\"} 5.5\n"),
            std::string::npos);
}

// What the server reads of a run: its stage and progress from
// run_state.json and the log's progress lines, its error from the log.
TEST(RunInvocation, ProgressAndErrorAreReadFromTheRunsFiles) {
  TemporaryFolder folder;
  const JobFiles files{folder.Path()};
  EXPECT_EQ(ReadRunProgress(files).fraction, 0.0);
  folder.Write("results/run_state.json",
               R"({"stages": {"reconstruct": {"complete": true},
                              "match": {"complete": false}}})");
  folder.Write(
      "log.txt",
      "I1207 01:00:00.0 1 progress.cc:43] reconstruct: 4/20 (20%), 1 s\n"
      "I1207 01:00:01.0 1 progress.cc:57] reconstruct: done in 2 s\n"
      "I1207 01:00:02.0 1 progress.cc:43] match: 10/20 (50%), 0.1 s\n"
      "I1207 01:00:03.0 1 progress.cc:43] match: 5/20 (20%), 0.1 s\n");
  RunProgress progress = ReadRunProgress(files);
  EXPECT_EQ(progress.stage, "match");
  EXPECT_EQ(progress.step, "match");
  EXPECT_DOUBLE_EQ(progress.fraction, (1 + 0.5) / 4.0);  // never back
  // The console's format of `zebrageo --log-level info` (issue 47).
  folder.Write("log.txt",
               "01:00:02 match: 10/20 (50%), 0.1 s, ~0.1 s left\n"
               "01:00:03 warning: a warning\n"
               "01:00:03 match: 16/20 (80%), 0.2 s, ~0.1 s left\n");
  progress = ReadRunProgress(files);
  EXPECT_EQ(progress.step, "match");
  EXPECT_DOUBLE_EQ(progress.fraction, (1 + 0.8) / 4.0);
  folder.Write("results/run_state.json",
               R"({"stages": {"reconstruct": {"complete": true},
                   "match": {"complete": true}, "adjust": {"complete": true}}})");
  progress = ReadRunProgress(files);
  EXPECT_EQ(progress.stage, "report");
  EXPECT_DOUBLE_EQ(progress.fraction, 0.75);

  folder.Write("log.txt",
               "zebrageo serve: attempt 1\nzebrageo: error: first\nline\n"
               "zebrageo: error: rig.yaml, line 1: not YAML\nlast\n");
  EXPECT_EQ(RunErrorFromLog(files.Log()), "rig.yaml, line 1: not YAML");
  EXPECT_EQ(LogTail(files.Log(), 2),
            "zebrageo: error: rig.yaml, line 1: not YAML\nlast\n");
  EXPECT_EQ(LogTail(files.Log(), 100).substr(0, 9), "zebrageo ");
}

// A job's options are checked as `zebrageo run --options FILE` checks
// them, and GET /options gives what `zebrageo run --print-options` prints.
TEST(RunInvocation, JobOptionsAreCheckedAsTheClisOptionsFile) {
  EXPECT_EQ(RunOptionsProblem(json::object()), "");
  EXPECT_EQ(
      RunOptionsProblem({{"rematch", false},
                         {"adjustment", {{"solver", {{"num_threads", 1}}}}}}),
      "");
  EXPECT_NE(RunOptionsProblem(json::array()), "");
  const std::string unknown = RunOptionsProblem({{"colour", "red"}});
  EXPECT_NE(unknown.find("colour"), std::string::npos) << unknown;
  const std::string refused = RunOptionsProblem({{"threads", -1}});
  EXPECT_NE(refused.find("threads"), std::string::npos) << refused;
  const std::string wrong_type =
      RunOptionsProblem({{"adjustment", {{"solver", {{"num_threads", "x"}}}}}});
  EXPECT_NE(wrong_type.find("adjustment.solver.num_threads"), std::string::npos)
      << wrong_type;
  const json defaults = DefaultRunOptions();
  ASSERT_TRUE(defaults.is_object());
  EXPECT_TRUE(defaults.contains("adjustment")) << defaults.dump(1);
  EXPECT_TRUE(defaults.contains("reconstruction"));
  EXPECT_EQ(RunOptionsProblem(defaults), "");  // the defaults read back
}

// Every route the server has is in server/openapi.json, and every path
// and method there is a route: the document is the API.
TEST(OpenApi, DocumentsEveryRouteAndNoOther) {
  const nlohmann::json document = nlohmann::json::parse(OpenApiDocument());
  EXPECT_EQ(document["openapi"].get<std::string>().substr(0, 2), "3.");
  EXPECT_EQ(OpenApiDocument(), ReadWholeFile(std::string(ZEBRAGEO_SOURCE_DIR) +
                                             "/server/openapi.json"));
  std::set<std::string> documented;
  for (const auto& [path, item] : document["paths"].items()) {
    for (const auto& [method, operation] : item.items()) {
      if (method == "parameters") continue;
      std::string upper = method;
      for (char& c : upper) c = static_cast<char>(toupper(c));
      documented.insert(upper + " " + path);
    }
  }
  std::set<std::string> routes;
  for (const RouteName& route : ServerRoutes()) {
    routes.insert(route.method + " " + route.path);
  }
  EXPECT_EQ(routes, documented);
  EXPECT_GE(routes.size(), 16u);
}

}  // namespace
}  // namespace zebrageo
