// The server's refusals: archives whose entries leave their folder or link
// out of it, folder jobs that name a path outside the data root or hold a
// link out of it, result names that climb, uploads over the limit, and
// requests without the token. Nothing is written outside the data root.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/server/server_test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

class ServerSecurity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new TemporaryFolder();
    survey_ = folder_->Path("root/surveys/a");
    CopySurvey(CachedSmallSurvey(1, false), survey_);
    server_ = new ServerProcess(folder_->Path("root"), 1);
    ASSERT_TRUE(server_->Start()) << server_->output();
  }
  static void TearDownTestSuite() {
    delete server_;
    delete folder_;
  }
  void TearDown() override {
    // Refused jobs leave nothing behind, and the server stays up.
    EXPECT_EQ(FilesUnder(folder_->Path("root/jobs")).size(), 0u);
    EXPECT_TRUE(server_->Alive());
    EXPECT_FALSE(fs::exists(folder_->Path("evil")));
    EXPECT_FALSE(fs::exists(folder_->Path("root/evil")));
  }

  static TemporaryFolder* folder_;
  static ServerProcess* server_;
  static std::string survey_;
};

TemporaryFolder* ServerSecurity::folder_ = nullptr;
ServerProcess* ServerSecurity::server_ = nullptr;
std::string ServerSecurity::survey_;

void ExpectRefused(const httplib::Result& result, int status,
                   const std::string& words) {
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, status) << result->body;
  const json body = JsonOf(result);
  ASSERT_TRUE(body.is_object()) << result->body;
  EXPECT_NE(body.value("error", "").find(words), std::string::npos)
      << body.dump();
}

TEST_F(ServerSecurity, ArchivesWithEntriesOutOfTheirFolderAreRefusedWhole) {
  httplib::Client client = ClientFor(server_->port());
  std::vector<TestEntry> survey = SurveyEntries(survey_, "");
  struct Case {
    std::string format;
    TestEntry bad;
    std::string words;
  };
  const std::vector<Case> cases = {
      {"tar", {"../evil", AE_IFREG, "x", ""}, "leaves its folder"},
      {"zip", {"../evil", AE_IFREG, "x", ""}, "leaves its folder"},
      {"tar", {"a/../../evil", AE_IFREG, "x", ""}, "leaves its folder"},
      {"tar", {"/tmp/evil", AE_IFREG, "x", ""}, "is absolute"},
      {"zip", {"/tmp/evil", AE_IFREG, "x", ""}, "is absolute"},
      {"tar", {"link", AE_IFLNK, "", "/etc"}, "a symbolic link"},
      {"zip", {"link", AE_IFLNK, "", "../../.."}, "a symbolic link"},
      {"tar", {"hard", AE_IFREG, "", "/etc/passwd"}, "a hard link"},
      {"tar", {"null", AE_IFCHR, "", ""}, "device"},
      {"tar", {"fifo", AE_IFIFO, "", ""}, "device"},
      {"tar", {"a\\..\\..\\evil", AE_IFREG, "x", ""}, "backslash"},
      {"tar", {"survey.yaml", AE_IFREG, "twice", ""}, "twice"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.format + " " + c.bad.name);
    std::vector<TestEntry> entries = survey;
    // The bad entry after good ones: nothing may be extracted before it.
    entries.push_back(c.bad);
    const std::string archive = folder_->Path("bad." + c.format);
    WriteTestArchive(archive, c.format, entries);
    ExpectRefused(UploadJob(client, archive), 400, c.words);
  }
}

TEST_F(ServerSecurity, FolderJobsOutsideTheDataRootAreRefused) {
  httplib::Client client = ClientFor(server_->port());
  // A survey outside the root, reached through a link inside it.
  fs::copy(survey_, folder_->Path("outside"), fs::copy_options::recursive);
  fs::create_directory_symlink(folder_->Path("outside"),
                               folder_->Path("root/surveys/linked"));
  // A survey inside the root whose image links out of it.
  fs::copy(survey_, folder_->Path("root/surveys/leaky"),
           fs::copy_options::recursive);
  const std::string image =
      FilesUnder(folder_->Path("root/surveys/leaky/images"))[0];
  fs::remove(folder_->Path("root/surveys/leaky/images/" + image));
  fs::create_symlink(folder_->Path("outside/images/" + image),
                     folder_->Path("root/surveys/leaky/images/" + image));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"../outside", "leaves its folder"},
      {"surveys/../../outside", "leaves its folder"},
      {"/etc", "is absolute"},
      {folder_->Path("outside"), "is absolute"},
      {"surveys/linked", "outside the data root"},
      {"surveys/leaky", "outside the data root"},
      {"jobs", "not a survey folder"},
      {"surveys/./a", "\".\""},
      {"surveys//a", "empty component"},
  };
  for (const auto& [folder, words] : cases) {
    SCOPED_TRACE(folder);
    ExpectRefused(FolderJob(client, {{"folder", folder}}), 400, words);
  }
}

TEST_F(ServerSecurity, ResultNamesThatClimbAreRefused) {
  httplib::Client client = ClientFor(server_->port());
  const httplib::Result created = FolderJob(client, {{"folder", "surveys/a"}});
  ASSERT_EQ(created->status, 201) << created->body;
  const std::string id = JsonOf(created)["id"];
  for (const std::string name :
       {"..%2F..%2Fzebrageo-jobs.sqlite", "../../zebrageo-jobs.sqlite",
        "%2Fetc%2Fpasswd", "..%2Flog.txt", "results%00x", ".zebrageo.lock"}) {
    SCOPED_TRACE(name);
    const httplib::Result result =
        client.Get("/jobs/" + id + "/results/" + name);
    ASSERT_TRUE(result);
    EXPECT_TRUE(result->status == 400 || result->status == 404)
        << result->status << " " << result->body;
    EXPECT_TRUE(JsonOf(result).contains("error"));
  }
  EXPECT_EQ(client.Delete("/jobs/" + id)->status, 200);
}

TEST_F(ServerSecurity, UploadsOverTheLimitsAreRefused) {
  TemporaryFolder root;
  ServerProcess small(root.Path(), 1,
                      {"--max-upload-mb", "0.05", "--max-extracted-mb", "0.2"});
  ASSERT_TRUE(small.Start()) << small.output();
  httplib::Client client = ClientFor(small.port());
  // Larger than 50 KB compressed.
  std::string noise(200000, '\0');
  uint32_t state = 1;
  for (char& c : noise) {
    state = state * 1664525u + 1013904223u;
    c = static_cast<char>(state >> 24);
  }
  const std::string big = folder_->Path("big.zip");
  WriteTestArchive(big, "zip", {{"survey.yaml", AE_IFREG, noise, ""}});
  ExpectRefused(UploadJob(client, big), 413, "larger than");
  // Small compressed, over 200 KB extracted.
  const std::string bomb = folder_->Path("bomb.tar.gz");
  WriteTestArchive(bomb, "tar",
                   {{"survey.yaml", AE_IFREG, std::string(1 << 20, 'a'), ""}});
  ExpectRefused(UploadJob(client, bomb), 400, "extracts to more than");
  // A chunked body over the limit (no Content-Length to refuse it by).
  size_t sent = 0;
  const httplib::Result chunked = client.Post(
      "/jobs",
      [&](size_t, httplib::DataSink& sink) {
        const std::string part =
            sent == 0
                ? "--b\r\nContent-Disposition: form-data; name=\"survey\"; "
                  "filename=\"s.zip\"\r\n\r\n"
                : std::string(16384, 'z');
        sent += part.size();
        sink.write(part.data(), part.size());
        if (sent > 400000) sink.done();
        return true;
      },
      "multipart/form-data; boundary=b");
  if (chunked) {
    EXPECT_GE(chunked->status, 400);
  }
  EXPECT_TRUE(small.Alive());
  EXPECT_EQ(FilesUnder(root.Path("jobs")).size(), 0u);
}

TEST_F(ServerSecurity, RequestsWithoutTheTokenAreRefused) {
  TemporaryFolder root;
  const std::string token = "s3cret-token-0123456789";
  const std::string token_file = root.Write("token", token + "\n");
  fs::create_directory(root.Path("data"));
  ServerProcess secured(root.Path("data"), 1, {"--token-file", token_file});
  ASSERT_TRUE(secured.Start()) << secured.output();
  httplib::Client anonymous = ClientFor(secured.port());
  httplib::Client wrong = ClientFor(secured.port(), "not-the-token-at-all");
  httplib::Client right = ClientFor(secured.port(), token);
  for (const std::string path : {"/jobs", "/metrics", "/options",
                                 "/openapi.json", "/jobs/0123456789abcdef"}) {
    SCOPED_TRACE(path);
    ExpectRefused(anonymous.Get(path), 401, "token");
    ExpectRefused(wrong.Get(path), 401, "wrong token");
  }
  ExpectRefused(anonymous.Post("/jobs", "{}", "application/json"), 401,
                "token");
  ExpectRefused(wrong.Delete("/jobs/0123456789abcdef"), 401, "token");
  EXPECT_EQ(right.Get("/jobs")->status, 200);
  EXPECT_EQ(anonymous.Get("/health")->status, 200);
  // The page's cookie serves GET requests, never a cancel or a delete.
  httplib::Headers cookie = {{"Cookie", "zebrageo_token=" + token}};
  EXPECT_EQ(anonymous.Get("/jobs", cookie)->status, 200);
  ExpectRefused(anonymous.Post("/jobs/0123456789abcdef/cancel", cookie, "", ""),
                401, "token");
  // Without a token, the page asks for it and shows no job.
  const httplib::Result page = anonymous.Get("/");
  ASSERT_TRUE(page);
  EXPECT_NE(page->body.find("id='login'"), std::string::npos);
  EXPECT_EQ(page->body.find("<tbody"), std::string::npos);

  // Not on loopback without a token: refused before anything listens.
  const int status = RunZebrageo(
      "serve --bind 0.0.0.0 --port 0 --data-root " + Quote(root.Path("data")),
      root.Path("open.out"), root.Path("open.err"));
  EXPECT_EQ(status, 2);
  EXPECT_NE(
      ReadWholeFile(root.Path("open.err")).find("--token-file is required"),
      std::string::npos);
  const std::string short_token = root.Write("short", "abc\n");
  EXPECT_EQ(RunZebrageo("serve --port 0 --token-file " + Quote(short_token) +
                            " --data-root " + Quote(root.Path("data")),
                        root.Path("short.out"), root.Path("short.err")),
            2);
}

}  // namespace
}  // namespace zebrageo
