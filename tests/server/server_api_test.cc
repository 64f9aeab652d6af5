// The real `zebrageo serve` on loopback, driven by a real HTTP client
// (cpp-httplib's): submit, watch, fetch, cancel, delete; bad requests get a
// 4xx JSON error and never bring the server down. The jobs' results equal
// the CLI's on the same survey.
#include <gtest/gtest.h>

#include <filesystem>
#include <mutex>

#include "tests/server/server_test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

class ServerApi : public ::testing::Test {
 protected:
  // One small survey, shared by the cases.
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    survey_ = folder_->Path("root/surveys/a");
    CopySurvey(CachedSmallSurvey(1, false), survey_);
    tar_ = folder_->Path("a.tar.gz");
    WriteTestArchive(tar_, "tar", SurveyEntries(survey_, "./a/"));
    zip_ = folder_->Path("a.zip");
    WriteTestArchive(zip_, "zip", SurveyEntries(survey_, ""));
  }
  static void TearDownTestSuite() { delete folder_; }

  // The CLI's results on the survey (the cases that need none run alone
  // under ASan, where a run is slow).
  static std::string Reference() { return CachedSmallSurvey(1, true); }

  // A server on the shared data root.
  std::unique_ptr<ServerProcess> StartServer(int workers) {
    auto server =
        std::make_unique<ServerProcess>(folder_->Path("root"), workers);
    EXPECT_TRUE(server->Start()) << server->output();
    return server;
  }

  static TemporaryFolder* folder_;
  static std::string survey_, tar_, zip_;
};

TemporaryFolder* ServerApi::folder_ = nullptr;
std::string ServerApi::survey_, ServerApi::tar_, ServerApi::zip_;

// A receiver of webhooks that refuses the first delivery (the server must
// retry) and records the rest.
class WebhookReceiver {
 public:
  WebhookReceiver() {
    server_.Post("/hook",
                 [this](const httplib::Request& req, httplib::Response& res) {
                   std::lock_guard<std::mutex> lock(mutex_);
                   if (++attempts_ == 1) {
                     res.status = 500;
                     return;
                   }
                   bodies_.push_back(json::parse(req.body, nullptr, false));
                 });
    port_ = server_.bind_to_any_port("127.0.0.1");
    thread_ = std::thread([this] { server_.listen_after_bind(); });
  }
  ~WebhookReceiver() {
    server_.stop();
    thread_.join();
  }
  std::string url() const {
    return "http://127.0.0.1:" + std::to_string(port_) + "/hook";
  }
  std::vector<json> bodies() {
    std::lock_guard<std::mutex> lock(mutex_);
    return bodies_;
  }

 private:
  httplib::Server server_;
  std::thread thread_;
  int port_ = 0;
  std::mutex mutex_;
  int attempts_ = 0;
  std::vector<json> bodies_;
};

TEST_F(ServerApi,
       SubmitWatchAndFetchUploadsAndAFolderWithResultsEqualToTheCli) {
  auto server = StartServer(2);
  httplib::Client client = ClientFor(server->port());
  WebhookReceiver hook;

  std::vector<std::string> ids;
  for (const std::string& archive : {tar_, zip_}) {
    const httplib::Result created = UploadJob(
        client, archive, {{"name", "upload"}, {"webhook", hook.url()}});
    ASSERT_TRUE(created);
    ASSERT_EQ(created->status, 201) << created->body;
    const json job = JsonOf(created);
    EXPECT_EQ(job["state"], "queued");
    EXPECT_EQ(created->get_header_value("Location"),
              "/jobs/" + job["id"].get<std::string>());
    ids.push_back(job["id"]);
  }
  // Options as `zebrageo run --options` reads them (here the defaults,
  // given: the results must still equal the CLI's).
  const httplib::Result folder_job =
      FolderJob(client, {{"folder", "surveys/a"},
                         {"options", {{"lines", true}, {"rematch", true}}}});
  ASSERT_TRUE(folder_job);
  ASSERT_EQ(folder_job->status, 201) << folder_job->body;
  ids.push_back(JsonOf(folder_job)["id"]);

  // Watch the first: running with a stage and a growing fraction, then done.
  std::set<std::string> stages;
  double last_progress = 0.0;
  bool monotonic = true;
  json job;
  for (int i = 0; i < 3000; ++i) {
    job = JsonOf(client.Get("/jobs/" + ids[0]));
    if (job["state"] == "running" && job["stage"].is_string()) {
      stages.insert(job["stage"].get<std::string>());
      monotonic = monotonic && job["progress"].get<double>() >= last_progress;
      last_progress = job["progress"];
    }
    if (job["state"] == "done" || job["state"] == "failed") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(job["state"], "done") << job.dump(1);
  EXPECT_FALSE(stages.empty()) << "no stage seen while running";
  EXPECT_TRUE(monotonic);
  EXPECT_EQ(job["progress"], 1.0);
  EXPECT_TRUE(job["timings"].contains("reconstruct")) << job.dump(1);

  for (const std::string& id : ids) {
    const json done = WaitForJob(client, id);
    ASSERT_EQ(done["state"], "done") << done.dump(1);
    EXPECT_EQ(done["attempts"], 1);
    ExpectResultsEqualCli(client, id, Reference());
  }

  // The files of a job.
  const json files = JsonOf(client.Get("/jobs/" + ids[0] + "/results"));
  std::set<std::string> names;
  for (const json& f : files["files"])
    names.insert(f["name"].get<std::string>());
  EXPECT_EQ(names.count("poses.csv"), 1u) << files.dump(1);
  EXPECT_EQ(names.count(".zebrageo.lock"), 0u);
  const httplib::Result report = client.Get("/jobs/" + ids[0] + "/report");
  ASSERT_TRUE(report);
  EXPECT_EQ(report->status, 200);
  EXPECT_NE(report->body.find("<html"), std::string::npos);
  const httplib::Result zip = client.Get("/jobs/" + ids[2] + "/results.zip");
  ASSERT_TRUE(zip);
  ASSERT_EQ(zip->status, 200);
  const std::string zip_path = folder_->Path("results.zip");
  std::ofstream(zip_path, std::ios::binary) << zip->body;
  archive* in = archive_read_new();
  archive_read_support_format_zip(in);
  ASSERT_EQ(archive_read_open_filename(in, zip_path.c_str(), 1 << 16),
            ARCHIVE_OK);
  archive_entry* entry = nullptr;
  std::string poses;
  while (archive_read_next_header(in, &entry) == ARCHIVE_OK) {
    if (std::string(archive_entry_pathname(entry)) ==
        "results-" + ids[2] + "/poses.csv") {
      poses.resize(static_cast<size_t>(archive_entry_size(entry)));
      archive_read_data(in, poses.data(), poses.size());
    }
  }
  archive_read_free(in);
  EXPECT_EQ(ResultDifference(ReadWholeFile(Reference() + "/poses.csv"), poses),
            "");

  // The log: the server's lines and the run's.
  const httplib::Result log = client.Get("/jobs/" + ids[0] + "/log?tail=1000");
  ASSERT_TRUE(log);
  EXPECT_NE(log->body.find("zebrageo serve: attempt 1"), std::string::npos);
  // The run's closing line (tools/run_command.cc).
  EXPECT_NE(log->body.find("done: "), std::string::npos) << log->body;
  EXPECT_NE(log->body.find("(report.html): "), std::string::npos);
  const httplib::Result tail = client.Get("/jobs/" + ids[0] + "/log?tail=2");
  ASSERT_TRUE(tail);
  EXPECT_EQ(std::count(tail->body.begin(), tail->body.end(), '\n'), 2);

  // The list, the state filter, the metrics.
  EXPECT_EQ(JsonOf(client.Get("/jobs"))["jobs"].size(), 3u);
  EXPECT_EQ(JsonOf(client.Get("/jobs?state=done"))["jobs"].size(), 3u);
  EXPECT_EQ(JsonOf(client.Get("/jobs?state=queued"))["jobs"].size(), 0u);
  const httplib::Result metrics = client.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find("zebrageo_jobs{state=\"done\"} 3"),
            std::string::npos)
      << metrics->body;
  EXPECT_NE(metrics->body.find(
                "zebrageo_stage_duration_seconds_count{stage=\"adjust\"} 3"),
            std::string::npos)
      << metrics->body;
  // Parsed by Prometheus' own Python parser, when it is installed.
  const std::string metrics_file = folder_->Path("metrics.txt");
  std::ofstream(metrics_file) << metrics->body;
  const int parsed = std::system(
      ("python3 -c 'import sys\ntry:\n from prometheus_client.parser import "
       "text_string_to_metric_families as p\nexcept ImportError:\n "
       "sys.exit(77)\nn = len(list(p(open(sys.argv[1]).read())))\nsys.exit(0 "
       "if n >= 8 else 1)' " +
       Quote(metrics_file))
          .c_str());
  EXPECT_TRUE(WEXITSTATUS(parsed) == 0 || WEXITSTATUS(parsed) == 77);

  // GET /options: what `zebrageo run --print-options` prints; the folder
  // job ran with its options file.
  const std::string printed = folder_->Path("print-options.json");
  ASSERT_EQ(std::system((Quote(ZEBRAGEO_BINARY) + " run --print-options > " +
                         Quote(printed))
                            .c_str()),
            0);
  std::ifstream printed_in(printed);
  EXPECT_EQ(JsonOf(client.Get("/options")), json::parse(printed_in));
  const json folder_options = json::parse(
      std::ifstream(folder_->Path("root/jobs/" + ids[2] + "/options.json")),
      nullptr, false);
  EXPECT_EQ(folder_options, json({{"lines", true}, {"rematch", true}}));

  // The webhooks: each upload's job, once, after a refused first attempt.
  for (int i = 0; i < 100 && hook.bodies().size() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::set<std::string> hooked;
  for (const json& body : hook.bodies()) {
    EXPECT_EQ(body["state"], "done");
    hooked.insert(body["id"].get<std::string>());
  }
  EXPECT_EQ(hooked, (std::set<std::string>{ids[0], ids[1]}));

  // Delete: the job and its folder go; a folder job's survey stays.
  for (const std::string& id : ids) {
    const httplib::Result deleted = client.Delete("/jobs/" + id);
    ASSERT_TRUE(deleted);
    EXPECT_EQ(deleted->status, 200);
    EXPECT_EQ(client.Get("/jobs/" + id)->status, 404);
    EXPECT_FALSE(fs::exists(folder_->Path("root/jobs/" + id)));
  }
  EXPECT_TRUE(fs::is_regular_file(survey_ + "/survey.yaml"));
  EXPECT_TRUE(server->Alive());
}

// A run cancelled in the middle leaves only complete files: each one there
// equals the CLI's, no temporary is left, the contract's outputs are absent.
TEST_F(ServerApi, CancelRunningAndQueuedJobsThenDeleteThem) {
  auto server = StartServer(1);
  httplib::Client client = ClientFor(server->port());
  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i) {
    const httplib::Result created =
        FolderJob(client, {{"folder", "surveys/a"}});
    ASSERT_TRUE(created);
    ASSERT_EQ(created->status, 201) << created->body;
    ids.push_back(JsonOf(created)["id"]);
  }
  // The first is running one stage after another: cancel it in "match" or
  // later, when reconstruct's files are complete.
  json running;
  for (int i = 0; i < 3000; ++i) {
    running = JsonOf(client.Get("/jobs/" + ids[0]));
    if (running["state"] != "queued" && running["stage"] != "reconstruct" &&
        running["stage"].is_string()) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(running["state"], "running") << running.dump(1);
  EXPECT_EQ(JsonOf(client.Get("/jobs/" + ids[1]))["state"], "queued");

  const httplib::Result queued_cancel =
      client.Post("/jobs/" + ids[1] + "/cancel");
  ASSERT_TRUE(queued_cancel);
  EXPECT_EQ(queued_cancel->status, 200);
  EXPECT_EQ(JsonOf(queued_cancel)["state"], "cancelled");
  const httplib::Result cancel = client.Post("/jobs/" + ids[0] + "/cancel");
  ASSERT_TRUE(cancel);
  EXPECT_EQ(cancel->status, 200);
  const json cancelled = WaitForJob(client, ids[0], 60);
  EXPECT_EQ(cancelled["state"], "cancelled") << cancelled.dump(1);
  EXPECT_EQ(cancelled["error"], "cancelled");

  // The third starts once the worker is free; DELETE cancels it running.
  // Asked at once, before the first job's files are read: the small survey
  // runs in seconds, and a loaded machine reads them slowly.
  json third;
  for (int i = 0; i < 6000; ++i) {
    third = JsonOf(client.Get("/jobs/" + ids[2]));
    if (third["state"] != "queued") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(third["state"], "running") << third.dump(1);
  const httplib::Result third_deleted = client.Delete("/jobs/" + ids[2]);
  ASSERT_TRUE(third_deleted);
  EXPECT_EQ(third_deleted->status, 200) << third_deleted->body;
  EXPECT_EQ(client.Get("/jobs/" + ids[2])->status, 404);

  const std::string results = folder_->Path("root/jobs/" + ids[0] + "/results");
  int compared = 0;
  for (const std::string& file : FilesUnder(results)) {
    EXPECT_EQ(file.find(".tmp"), std::string::npos) << file;
  }
  for (const std::string& file : ComparedResults()) {
    if (!fs::exists(results + "/" + file)) continue;
    ++compared;
    EXPECT_EQ(ResultDifference(ReadWholeFile(Reference() + "/" + file),
                               ReadWholeFile(results + "/" + file)),
              "")
        << file;
  }
  EXPECT_GE(compared, 1) << "reconstruct's outputs were complete";
  EXPECT_FALSE(fs::exists(results + "/poses.csv") &&
               !fs::exists(results + "/report.json"));

  for (const std::string& id : {ids[0], ids[1]}) {
    const httplib::Result deleted = client.Delete("/jobs/" + id);
    ASSERT_TRUE(deleted);
    EXPECT_EQ(deleted->status, 200) << deleted->body;
  }
  EXPECT_EQ(JsonOf(client.Get("/jobs"))["jobs"].size(), 0u);
  // Every child has ended: the worker takes a new job at once.
  EXPECT_TRUE(server->Alive());
}

// Every bad request gets a 4xx and a JSON {"error"}; the server stays up.
TEST_F(ServerApi, BadRequestsGetA4xxJsonErrorAndNeverACrash) {
  auto server = StartServer(1);
  httplib::Client client = ClientFor(server->port());
  const std::string unknown = "/jobs/0123456789abcdef";
  const std::string not_archive =
      folder_->Write("not-an-archive.tar.gz", "hello");
  const std::string empty = folder_->Path("empty.tar.gz");
  WriteTestArchive(empty, "tar", {});
  const std::string no_survey = folder_->Path("no-survey.zip");
  WriteTestArchive(no_survey, "zip", {{"readme.txt", AE_IFREG, "x", ""}});

  struct Case {
    std::string what;
    std::function<httplib::Result()> request;
    int status;
  };
  const std::vector<Case> cases = {
      {"unknown route", [&] { return client.Get("/nothing"); }, 404},
      {"malformed id", [&] { return client.Get("/jobs/ZZZ"); }, 404},
      {"unknown job", [&] { return client.Get(unknown); }, 404},
      {"unknown job's log", [&] { return client.Get(unknown + "/log"); }, 404},
      {"unknown job's file",
       [&] { return client.Get(unknown + "/results/poses.csv"); }, 404},
      {"unknown job's cancel", [&] { return client.Post(unknown + "/cancel"); },
       404},
      {"unknown job's delete", [&] { return client.Delete(unknown); }, 404},
      {"wrong method", [&] { return client.Put("/jobs", "", "text/plain"); },
       404},
      {"text body",
       [&] { return client.Post("/jobs", "folder=a", "text/plain"); }, 415},
      {"malformed JSON",
       [&] { return client.Post("/jobs", "{\"folder\":", "application/json"); },
       400},
      {"JSON array",
       [&] { return client.Post("/jobs", "[1]", "application/json"); }, 400},
      {"unknown field",
       [&] {
         return FolderJob(client, {{"folder", "surveys/a"}, {"colour", "red"}});
       },
       400},
      {"folder not a string",
       [&] {
         return FolderJob(client, {{"folder", 3}});
       },
       400},
      {"no survey",
       [&] {
         return FolderJob(client, {{"name", "x"}});
       },
       400},
      {"missing folder",
       [&] {
         return FolderJob(client, {{"folder", "surveys/none"}});
       },
       400},
      {"folder without survey.yaml",
       [&] {
         return FolderJob(client, {{"folder", "surveys"}});
       },
       400},
      {"options not an object",
       [&] {
         return FolderJob(
             client, {{"folder", "surveys/a"}, {"options", json::array()}});
       },
       400},
      {"bad options",
       [&] {
         return FolderJob(
             client, {{"folder", "surveys/a"}, {"options", {{"threads", -1}}}});
       },
       400},
      {"webhook not http",
       [&] {
         return FolderJob(client, {{"folder", "surveys/a"},
                                   {"webhook", "file:///etc/passwd"}});
       },
       400},
      {"name with a newline",
       [&] {
         return FolderJob(client, {{"folder", "surveys/a"}, {"name", "a\nb"}});
       },
       400},
      {"not an archive", [&] { return UploadJob(client, not_archive); }, 400},
      {"empty archive", [&] { return UploadJob(client, empty); }, 400},
      {"archive without survey.yaml",
       [&] { return UploadJob(client, no_survey); }, 400},
      {"unknown form field",
       [&] {
         return UploadJob(client, tar_, {{"colour", "red"}});
       },
       400},
      {"upload and folder",
       [&] {
         return UploadJob(client, tar_, {{"folder", "surveys/a"}});
       },
       400},
      {"bad state filter", [&] { return client.Get("/jobs?state=sleeping"); },
       400},
      {"bad tail", [&] { return client.Get(unknown + "/log?tail=-3"); }, 404},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const httplib::Result result = c.request();
    ASSERT_TRUE(result) << httplib::to_string(result.error());
    EXPECT_EQ(result->status, c.status) << result->body;
    const json body = JsonOf(result);
    EXPECT_TRUE(body.is_object() && body["error"].is_string()) << result->body;
    EXPECT_EQ(body.value("status", 0), result->status);
  }
  // Bodies refused before they are read: over the size limit, chunked
  // where no upload is expected, and the same asked with 100-continue.
  const std::string host = "Host: 127.0.0.1\r\n";
  for (const auto& [request, status] :
       std::vector<std::pair<std::string, std::string>>{
           {"POST " + unknown + "/cancel HTTP/1.1\r\n" + host +
                "Content-Length: 2097152\r\n\r\n",
            "413"},
           {"POST " + unknown + "/cancel HTTP/1.1\r\n" + host +
                "Content-Length: 2097152\r\nExpect: 100-continue\r\n\r\n",
            "413"},
           {"DELETE " + unknown + " HTTP/1.1\r\n" + host +
                "Transfer-Encoding: chunked\r\n\r\n",
            "411"},
           {"POST /jobs HTTP/1.1\r\n" + host +
                "Content-Type: application/json\r\n"
                "Content-Length: 99999999999\r\nExpect: 100-continue\r\n\r\n",
            "413"}}) {
    SCOPED_TRACE(request);
    const std::string answer = RawRequest(server->port(), request);
    EXPECT_EQ(answer.substr(0, 12), "HTTP/1.1 " + status) << answer;
    EXPECT_NE(answer.find("\"error\""), std::string::npos) << answer;
  }
  // A job's own bad requests.
  const httplib::Result created = FolderJob(client, {{"folder", "surveys/a"}});
  ASSERT_EQ(created->status, 201);
  const std::string id = JsonOf(created)["id"];
  EXPECT_EQ(client.Get("/jobs/" + id + "/log?tail=abc")->status, 400);
  const httplib::Result zip = client.Get("/jobs/" + id + "/results.zip");
  EXPECT_EQ(zip->status, 409) << "not ended yet: " << zip->body;
  client.Delete("/jobs/" + id);
  // Nothing of the refused jobs is left in the data root.
  EXPECT_EQ(FilesUnder(folder_->Path("root/jobs")).size(), 0u);
  EXPECT_TRUE(server->Alive());
  EXPECT_EQ(client.Get("/health")->status, 200);
}

}  // namespace
}  // namespace zebrageo
