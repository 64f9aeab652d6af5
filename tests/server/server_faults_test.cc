// Faults: the server killed with SIGKILL in the middle of three running
// jobs (and one queued) and started again finishes all of them, with
// results identical to uninterrupted CLI runs; a worker that crashes fails
// its job alone; a survey the CLI refuses fails with the CLI's words.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/server/server_test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// The pids of the processes whose command line holds `needle`.
std::vector<pid_t> ProcessesWith(const std::string& needle) {
  std::vector<pid_t> pids;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string command = ReadWholeFile(entry.path().string() + "/cmdline");
    for (char& c : command) {
      if (c == '\0') c = ' ';
    }
    if (command.find(needle) != std::string::npos &&
        command.find(" run ") != std::string::npos) {
      pids.push_back(std::stoi(name));
    }
  }
  return pids;
}

class ServerFaults : public ::testing::Test {
 protected:
  // Three small surveys (seeds 1-3) under the data root, and their CLI
  // results.
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    fs::create_directories(folder_->Path("root/surveys"));
    for (int seed = 1; seed <= 3; ++seed) {
      const std::string name = "s" + std::to_string(seed);
      CopySurvey(CachedSmallSurvey(seed, false),
                 folder_->Path("root/surveys/" + name));
      fs::create_directories(folder_->Path("reference"));
      fs::create_directory_symlink(CachedSmallSurvey(seed, true),
                                   folder_->Path("reference/" + name));
    }
  }
  static void TearDownTestSuite() { delete folder_; }
  static TemporaryFolder* folder_;
};

TemporaryFolder* ServerFaults::folder_ = nullptr;

TEST_F(ServerFaults,
       KilledWithSigkillDuringThreeRunningJobsThenRestartedFinishesThemAll) {
  const std::string root = folder_->Path("root");
  ServerProcess first(root, 3);
  ASSERT_TRUE(first.Start()) << first.output();
  httplib::Client client = ClientFor(first.port());
  std::vector<std::pair<std::string, std::string>> jobs;  // id, survey
  for (const std::string survey : {"s1", "s2", "s3", "s1"}) {
    const httplib::Result created =
        FolderJob(client, {{"folder", "surveys/" + survey}});
    ASSERT_TRUE(created);
    ASSERT_EQ(created->status, 201) << created->body;
    jobs.emplace_back(JsonOf(created)["id"], survey);
  }
  // Three running, each past the start of its first stage; one queued.
  bool all_running = false;
  for (int i = 0; i < 3000 && !all_running; ++i) {
    all_running = true;
    for (int j = 0; j < 3; ++j) {
      const json job = JsonOf(client.Get("/jobs/" + jobs[j].first));
      all_running =
          all_running && job["state"] == "running" && job["stage"].is_string();
    }
    if (!all_running)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(all_running);
  EXPECT_EQ(JsonOf(client.Get("/jobs/" + jobs[3].first))["state"], "queued");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int status = first.Kill(SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  // The children die with their server (PR_SET_PDEATHSIG).
  for (int i = 0; i < 100 && !ProcessesWith(root + "/jobs/").empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(ProcessesWith(root + "/jobs/").empty());
  int interrupted = 0;
  for (int j = 0; j < 3; ++j) {
    interrupted +=
        !fs::exists(root + "/jobs/" + jobs[j].first + "/results/report.json");
  }
  EXPECT_EQ(interrupted, 3) << "a job ended before the kill";

  // An upload the killed server was extracting: a folder without a job.
  const std::string orphan = root + "/jobs/00000000000000aa";
  fs::create_directories(orphan + "/survey");
  std::ofstream(orphan + "/upload") << "half an archive";

  ServerProcess second(root, 3);
  ASSERT_TRUE(second.Start()) << second.output();
  EXPECT_FALSE(fs::exists(orphan));
  // One server per data root.
  const std::string twice = folder_->Path("twice.err");
  EXPECT_EQ(RunZebrageo("serve --port 0 --data-root " + Quote(root),
                        folder_->Path("twice.out"), twice),
            2);
  EXPECT_NE(ReadWholeFile(twice).find("another zebrageo serve uses it"),
            std::string::npos)
      << ReadWholeFile(twice);
  httplib::Client again = ClientFor(second.port());
  for (int j = 0; j < 4; ++j) {
    const auto& [id, survey] = jobs[j];
    SCOPED_TRACE(id + " " + survey);
    const json job = WaitForJob(again, id);
    ASSERT_EQ(job["state"], "done") << job.dump(1);
    EXPECT_EQ(job["attempts"], j < 3 ? 2 : 1);
    ExpectResultsEqualCli(again, id, folder_->Path("reference/" + survey));
    EXPECT_TRUE(FilesUnder(root + "/jobs/" + id + "/results").size() > 0);
    for (const std::string& file :
         FilesUnder(root + "/jobs/" + id + "/results")) {
      EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
    }
  }
  // The log tells of the restart.
  const httplib::Result log =
      again.Get("/jobs/" + jobs[0].first + "/log?tail=100000");
  EXPECT_NE(log->body.find("resumed on restart"), std::string::npos);
  EXPECT_NE(log->body.find("attempt 2"), std::string::npos);
  for (const auto& job : jobs) again.Delete("/jobs/" + job.first);
}

TEST_F(ServerFaults,
       AWorkerThatCrashesFailsItsJobAloneAndABadSurveyFailsInTheCliWords) {
  const std::string root = folder_->Path("root");
  // A survey the CLI refuses: its rig.yaml is not YAML.
  const std::string bad = root + "/surveys/bad";
  fs::copy(root + "/surveys/s2", bad, fs::copy_options::recursive);
  std::ofstream(bad + "/rig.yaml") << "cameras: [unclosed\n";
  ASSERT_EQ(RunZebrageo(
                "run " + Quote(bad) + " -o " + Quote(folder_->Path("bad-cli")),
                folder_->Path("bad.out"), folder_->Path("bad.err")),
            1);
  const std::string cli_error = ReadWholeFile(folder_->Path("bad.err"));

  ServerProcess server(root, 2);
  ASSERT_TRUE(server.Start()) << server.output();
  httplib::Client client = ClientFor(server.port());
  const std::string crash =
      JsonOf(FolderJob(client, {{"folder", "surveys/s1"}}))["id"];
  const std::string fine =
      JsonOf(FolderJob(client, {{"folder", "surveys/s2"}}))["id"];
  // The crash: the first job's worker gets SIGSEGV while it runs.
  std::vector<pid_t> pids;
  for (int i = 0; i < 3000 && pids.empty(); ++i) {
    pids = ProcessesWith(root + "/jobs/" + crash + "/results");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(pids.size(), 1u);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pids[0], SIGSEGV);
  const json crashed = WaitForJob(client, crash);
  EXPECT_EQ(crashed["state"], "failed");
  EXPECT_EQ(crashed["signal"], SIGSEGV);
  EXPECT_NE(crashed["error"].get<std::string>().find("SIGSEGV"),
            std::string::npos)
      << crashed.dump(1);
  const json done = WaitForJob(client, fine);
  EXPECT_EQ(done["state"], "done") << done.dump(1);
  ExpectResultsEqualCli(client, fine, folder_->Path("reference/s2"));

  const std::string refused =
      JsonOf(FolderJob(client, {{"folder", "surveys/bad"}}))["id"];
  const json failed = WaitForJob(client, refused);
  EXPECT_EQ(failed["state"], "failed");
  EXPECT_EQ(failed["exit_code"], 1);
  const std::string error = failed["error"];
  EXPECT_FALSE(error.empty());
  EXPECT_NE(cli_error.find(error), std::string::npos)
      << "server: " << error << "\nCLI: " << cli_error;
  EXPECT_TRUE(server.Alive());
  EXPECT_EQ(client.Get("/health")->status, 200);
  fs::remove_all(bad);
}

}  // namespace
}  // namespace zebrageo
