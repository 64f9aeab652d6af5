// Load: 20 small surveys submitted at once (from 20 client threads, half as
// uploads, half as folders) to a server with 2 workers all finish, and each
// job's results equal the CLI's on its survey. Five surveys (seeds 1-5),
// four jobs each: the CLI's reference runs stay few.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/server/server_test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

TEST(ServerLoad, TwentySurveysAtOnceWithTwoWorkersAllFinishEqualToTheCli) {
  TemporaryFolder folder;
  constexpr int kSurveys = 5;
  constexpr int kJobs = 20;
  fs::create_directories(folder.Path("root/surveys"));
  for (int seed = 1; seed <= kSurveys; ++seed) {
    const std::string name = "s" + std::to_string(seed);
    CopySurvey(CachedSmallSurvey(seed, false),
               folder.Path("root/surveys/" + name));
    fs::create_directories(folder.Path("reference"));
    fs::create_directory_symlink(CachedSmallSurvey(seed, true),
                                 folder.Path("reference/" + name));
    WriteTestArchive(folder.Path(name + ".tar.gz"), "tar",
                     SurveyEntries(folder.Path("root/surveys/" + name), ""));
  }
  ServerProcess server(folder.Path("root"), 2);
  ASSERT_TRUE(server.Start()) << server.output();

  std::vector<std::string> ids(kJobs);
  std::vector<std::thread> clients;
  for (int i = 0; i < kJobs; ++i) {
    clients.emplace_back([&, i] {
      httplib::Client client = ClientFor(server.port());
      const std::string name = "s" + std::to_string(1 + i % kSurveys);
      const httplib::Result created =
          i % 2 == 0 ? UploadJob(client, folder.Path(name + ".tar.gz"))
                     : FolderJob(client, {{"folder", "surveys/" + name}});
      if (created && created->status == 201) ids[i] = JsonOf(created)["id"];
    });
  }
  for (std::thread& client : clients) client.join();
  httplib::Client client = ClientFor(server.port());
  for (int i = 0; i < kJobs; ++i) {
    ASSERT_FALSE(ids[i].empty()) << "job " << i << " was not accepted";
  }
  // Never more than two running at once.
  int most_running = 0;
  for (bool pending = true; pending;) {
    const json jobs = JsonOf(client.Get("/jobs"))["jobs"];
    int running = 0;
    pending = false;
    for (const json& job : jobs) {
      running += job["state"] == "running";
      pending =
          pending || job["state"] == "queued" || job["state"] == "running";
    }
    most_running = std::max(most_running, running);
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  EXPECT_EQ(most_running, 2);
  for (int i = 0; i < kJobs; ++i) {
    SCOPED_TRACE("job " + std::to_string(i));
    const json job = JsonOf(client.Get("/jobs/" + ids[i]));
    ASSERT_EQ(job["state"], "done") << job.dump(1);
    ExpectResultsEqualCli(
        client, ids[i],
        folder.Path("reference/s" + std::to_string(1 + i % kSurveys)));
  }
  const std::string metrics = client.Get("/metrics")->body;
  EXPECT_NE(metrics.find("zebrageo_jobs_finished_total{state=\"done\"} 20"),
            std::string::npos)
      << metrics;
}

}  // namespace
}  // namespace zebrageo
