// Helpers of the server's tests: the real `zebrageo serve` started on
// loopback in a temporary data root, an HTTP client, small simulated
// surveys and their CLI reference results, archives made to order.
#ifndef ZEBRAGEO_TESTS_SERVER_SERVER_TEST_UTIL_H_
#define ZEBRAGEO_TESTS_SERVER_SERVER_TEST_UTIL_H_

#include <archive.h>
#include <archive_entry.h>
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

extern char** environ;

namespace zebrageo {

using nlohmann::json;

// A `zebrageo serve` process on 127.0.0.1 and a free port.
class ServerProcess {
 public:
  ServerProcess(std::string data_root, int workers,
                std::vector<std::string> extra = {})
      : data_root_(std::move(data_root)),
        workers_(workers),
        extra_(std::move(extra)) {}
  ~ServerProcess() {
    if (pid_ > 0) Kill(SIGKILL);
  }

  // Starts it and waits until it listens; false (with the reason in
  // `output()`) when it does not.
  bool Start() {
    const std::string out =
        data_root_ + "/../serve-" + std::to_string(++starts_) + ".out";
    out_path_ = out;
    std::vector<std::string> args = {ZEBRAGEO_BINARY,
                                     "--log-level",
                                     "info",
                                     "serve",
                                     "--data-root",
                                     data_root_,
                                     "--port",
                                     "0",
                                     "--workers",
                                     std::to_string(workers_),
                                     "--cancel-grace",
                                     "3",
                                     "--webhook-retry-delay",
                                     "0.2"};
    args.insert(args.end(), extra_.begin(), extra_.end());
    std::vector<char*> argv;
    for (std::string& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int error =
        posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (error != 0) return false;
    const std::regex listening(R"(listening on http://127\.0\.0\.1:([0-9]+))");
    for (int i = 0; i < 600; ++i) {
      std::smatch match;
      const std::string text = output();
      if (std::regex_search(text, match, listening)) {
        port_ = std::stoi(match[1]);
        return true;
      }
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  // Sends `signal` and waits for the process to end; its exit status.
  int Kill(int signal) {
    if (pid_ <= 0) return -1;
    kill(pid_, signal);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return status;
  }
  // Whether the process is still running.
  bool Alive() {
    if (pid_ <= 0) return false;
    int status = 0;
    return waitpid(pid_, &status, WNOHANG) == 0;
  }
  std::string output() const { return ReadWholeFile(out_path_); }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }

 private:
  std::string data_root_;
  int workers_;
  std::vector<std::string> extra_;
  std::string out_path_;
  pid_t pid_ = -1;
  int port_ = 0;
  int starts_ = 0;
};

// Debian's cpp-httplib (0.11) sends without MSG_NOSIGNAL: a write to a
// connection the server has closed would raise SIGPIPE and kill the whole
// test process (seen once under ASan). As every network client does, the
// tests take EPIPE, an error the test reports, instead.
inline void IgnoreSigpipe() { signal(SIGPIPE, SIG_IGN); }

inline httplib::Client ClientFor(int port, const std::string& token = "") {
  IgnoreSigpipe();
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(60, 0);
  client.set_write_timeout(60, 0);
  if (!token.empty()) client.set_bearer_token_auth(token);
  return client;
}

// Sends `request` as is on a new connection to the server and returns what
// it answers until it closes the connection (or 10 s pass): for requests
// no HTTP client library would send.
inline std::string RawRequest(int port, const std::string& request) {
  IgnoreSigpipe();
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) !=
      0) {
    close(fd);
    return "";
  }
  timeval timeout{10, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  (void)!write(fd, request.data(), request.size());
  std::string answer;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof(buffer))) > 0;) {
    answer.append(buffer, static_cast<size_t>(n));
    if (answer.find("\r\n\r\n") != std::string::npos &&
        answer.find("}\n") != std::string::npos) {
      break;
    }
  }
  close(fd);
  return answer;
}

inline json JsonOf(const httplib::Result& result) {
  if (!result) return json();
  return json::parse(result->body, nullptr, false);
}

// Polls GET /jobs/{id} until the job has ended or `seconds` pass; the last
// job JSON seen.
inline json WaitForJob(httplib::Client& client, const std::string& id,
                       double seconds = 300) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  json job;
  while (std::chrono::steady_clock::now() < deadline) {
    job = JsonOf(client.Get("/jobs/" + id));
    const std::string state = job.value("state", "");
    if (state == "done" || state == "failed" || state == "cancelled") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return job;
}

// One entry of an archive made to order.
struct TestEntry {
  std::string name;
  mode_t type = AE_IFREG;
  std::string content;  // a file's bytes
  std::string link;     // a symbolic or hard link's target
};

// Writes an archive ("tar" gzipped, or "zip") of `entries`.
inline void WriteTestArchive(const std::string& path, const std::string& format,
                             const std::vector<TestEntry>& entries) {
  archive* out = archive_write_new();
  if (format == "zip") {
    archive_write_set_format_zip(out);
  } else {
    archive_write_set_format_pax_restricted(out);
    archive_write_add_filter_gzip(out);
  }
  ASSERT_EQ(archive_write_open_filename(out, path.c_str()), ARCHIVE_OK);
  for (const TestEntry& e : entries) {
    archive_entry* entry = archive_entry_new();
    archive_entry_set_pathname(entry, e.name.c_str());
    if (!e.link.empty() && e.type == AE_IFREG) {
      archive_entry_set_hardlink(entry, e.link.c_str());
    } else {
      archive_entry_set_filetype(entry, e.type);
    }
    if (e.type == AE_IFLNK) archive_entry_set_symlink(entry, e.link.c_str());
    archive_entry_set_perm(entry, e.type == AE_IFDIR ? 0755 : 0644);
    archive_entry_set_size(entry,
                           e.type == AE_IFREG && e.link.empty()
                               ? static_cast<la_int64_t>(e.content.size())
                               : 0);
    if (e.type == AE_IFCHR) archive_entry_set_rdev(entry, makedev(1, 3));
    archive_write_header(out, entry);
    if (e.type == AE_IFREG && !e.content.empty() && e.link.empty()) {
      archive_write_data(out, e.content.data(), e.content.size());
    }
    archive_entry_free(entry);
  }
  archive_write_close(out);
  archive_write_free(out);
}

// The entries of the survey folder `folder` under `prefix`/.
inline std::vector<TestEntry> SurveyEntries(const std::string& folder,
                                            const std::string& prefix) {
  std::vector<TestEntry> entries;
  for (const std::string& name : FilesUnder(folder)) {
    entries.push_back(
        {prefix + name, AE_IFREG, ReadWholeFile(folder + "/" + name), ""});
  }
  return entries;
}

// POST /jobs with an archive file as 'survey' (and form fields).
inline httplib::Result UploadJob(
    httplib::Client& client, const std::string& archive_path,
    const std::vector<std::pair<std::string, std::string>>& fields = {}) {
  httplib::MultipartFormDataItems items = {
      {"survey", ReadWholeFile(archive_path),
       std::filesystem::path(archive_path).filename().string(),
       "application/octet-stream"}};
  for (const auto& [name, value] : fields)
    items.push_back({name, value, "", ""});
  return client.Post("/jobs", items);
}

inline httplib::Result FolderJob(httplib::Client& client, const json& body) {
  return client.Post("/jobs", body.dump(), "application/json");
}

// The result files compared between a job and the CLI (as run_resume_test:
// report.json and report.html hold timings).
inline const std::vector<std::string>& ComparedResults() {
  static const std::vector<std::string> kFiles = {"reconstructed_bands.csv",
                                                  "matches.csv",
                                                  "crossing_decisions.csv",
                                                  "trajectory_corrected.csv",
                                                  "poses.csv",
                                                  "gcp_residuals.csv",
                                                  "bands.geojson"};
  return kFiles;
}

// Numbers of a text file in order (comment lines skipped).
inline std::vector<std::string> ResultTokens(const std::string& text) {
  std::vector<std::string> tokens;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '#') continue;
    std::string token;
    for (char c : line + ",") {
      if (std::string(", []{}:").find(c) != std::string::npos) {
        if (!token.empty()) tokens.push_back(token);
        token.clear();
      } else {
        token += c;
      }
    }
  }
  return tokens;
}

// "" when `a` and `b` (a file's text) hold the same tokens, numbers equal
// to 1e-9 + 1e-11 relative (the threaded solver's last bits); otherwise the
// first difference.
inline std::string ResultDifference(const std::string& a,
                                    const std::string& b) {
  const std::vector<std::string> ta = ResultTokens(a);
  const std::vector<std::string> tb = ResultTokens(b);
  if (ta.empty()) return "empty";
  if (ta.size() != tb.size()) {
    return std::to_string(ta.size()) + " vs " + std::to_string(tb.size()) +
           " tokens";
  }
  for (size_t i = 0; i < ta.size(); ++i) {
    if (ta[i] == tb[i]) continue;
    char* end_a = nullptr;
    char* end_b = nullptr;
    const double va = std::strtod(ta[i].c_str(), &end_a);
    const double vb = std::strtod(tb[i].c_str(), &end_b);
    if (*end_a == '\0' && *end_b == '\0' &&
        std::abs(va - vb) <= 1e-9 + 1e-11 * std::abs(va)) {
      continue;
    }
    return "token " + std::to_string(i) + ": " + ta[i] + " vs " + tb[i];
  }
  return "";
}

// Expects the job's results, fetched over HTTP, to equal the CLI's in
// `reference` (a results folder).
inline void ExpectResultsEqualCli(httplib::Client& client,
                                  const std::string& id,
                                  const std::string& reference) {
  for (const std::string& file : ComparedResults()) {
    SCOPED_TRACE(id + " " + file);
    const httplib::Result result =
        client.Get("/jobs/" + id + "/results/" + file);
    ASSERT_TRUE(result);
    ASSERT_EQ(result->status, 200);
    EXPECT_EQ(
        ResultDifference(ReadWholeFile(reference + "/" + file), result->body),
        "");
  }
}

// The small survey of cli_util.h simulated with `seed`, and (`reference`)
// the CLI's results on it, made once for all the server's tests: ctest
// runs each case in a process of its own. Cached in the build tree
// (build/test-cache/zebrageo-server-<binary stamp>/), under a lock so that
// parallel tests wait for the first; older builds' caches are removed.
inline std::string CachedSmallSurvey(int seed, bool reference) {
  namespace fs = std::filesystem;
  const fs::path cache =
      fs::path(ZEBRAGEO_BINARY).parent_path().parent_path() / "test-cache";
  fs::create_directories(cache);
  const auto size = fs::file_size(ZEBRAGEO_BINARY);
  const auto time = fs::last_write_time(ZEBRAGEO_BINARY);
  const std::string prefix = "zebrageo-server-";
  const fs::path folder =
      cache / (prefix + std::to_string(size) + "-" +
               std::to_string(time.time_since_epoch().count()));
  const fs::path survey = folder / ("s" + std::to_string(seed));
  const fs::path results = folder / ("s" + std::to_string(seed) + "-cli");
  const fs::path wanted = reference ? results : survey;
  const int lock = ::open((cache / "zebrageo-server.lock").c_str(),
                          O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  EXPECT_GE(lock, 0);
  EXPECT_EQ(::flock(lock, LOCK_EX), 0);
  if (!fs::exists(folder)) {
    for (const auto& entry : fs::directory_iterator(cache)) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0) {
        fs::remove_all(entry.path());
      }
    }
    fs::create_directories(folder);
  }
  const std::string log = (folder / "log").string();
  if (!fs::exists(survey.string() + ".complete")) {
    std::string arguments =
        std::regex_replace(SmallSurveyArguments(), std::regex("--seed 1"),
                           "--seed " + std::to_string(seed));
    fs::remove_all(survey);
    EXPECT_EQ(RunZebrageo("--log-level error simulate " + arguments + " -o " +
                              Quote(survey.string()),
                          log + ".out", log),
              0)
        << ReadWholeFile(log);
    std::ofstream(survey.string() + ".complete") << "ok\n";
  }
  if (reference && !fs::exists(results.string() + ".complete")) {
    fs::remove_all(results);
    EXPECT_EQ(RunZebrageo("--log-level error run " + Quote(survey.string()) +
                              " -o " + Quote(results.string()),
                          log + ".out", log),
              0)
        << ReadWholeFile(log);
    std::ofstream(results.string() + ".complete") << "ok\n";
  }
  ::close(lock);
  return wanted.string();
}

// A copy of a cached survey at `to` (its files hard links: no job writes
// in a survey).
inline void CopySurvey(const std::string& from, const std::string& to) {
  std::filesystem::create_directories(std::filesystem::path(to).parent_path());
  std::filesystem::copy(from, to,
                        std::filesystem::copy_options::recursive |
                            std::filesystem::copy_options::create_hard_links);
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_SERVER_SERVER_TEST_UTIL_H_
