#include "server/server.h"

#include <fcntl.h>
#include <glog/logging.h>
#include <limits.h>
#include <stdlib.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <regex>

#include "pipeline/exit_codes.h"
#include "pipeline/version.h"
#include "server/api_internal.h"
#include "server/child_process.h"
#include "server/run_invocation.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double NowSeconds() {
  return std::chrono::duration<double>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host == "::1" ||
         host.compare(0, 4, "127.") == 0;
}

using Handler = std::function<void(const ApiContext&, const httplib::Request&,
                                   httplib::Response&)>;

struct Route {
  std::string method;
  std::string path;  // as in openapi.json
  Handler handler;
};

void GetHealth(const ApiContext& context, const httplib::Request&,
               httplib::Response& res) {
  SendJson(res, 200,
           {{"status", "ok"},
            {"version", ZEBRAGEO_VERSION_STRING},
            {"workers", context.options.workers},
            {"uptime_s", NowSeconds() - context.started_at}});
}

void GetMetrics(const ApiContext& context, const httplib::Request&,
                httplib::Response& res) {
  context.runner->UpdateGauges();
  res.set_content(context.metrics->Render(),
                  "text/plain; version=0.0.4; charset=utf-8");
}

void GetOptions(const ApiContext&, const httplib::Request&,
                httplib::Response& res) {
  SendJson(res, 200, DefaultRunOptions());
}

void GetOpenApi(const ApiContext&, const httplib::Request&,
                httplib::Response& res) {
  res.set_content(OpenApiDocument(), "application/json");
}

// Every route but POST /jobs (which streams its body).
std::vector<Route> Routes() {
  return {{"GET", "/", GetPage},
          {"GET", "/app.js", GetPageScript},
          {"GET", "/health", GetHealth},
          {"GET", "/metrics", GetMetrics},
          {"GET", "/options", GetOptions},
          {"GET", "/openapi.json", GetOpenApi},
          {"GET", "/jobs", ListJobs},
          {"GET", "/jobs/{id}", GetJob},
          {"GET", "/jobs/{id}/log", GetLog},
          {"GET", "/jobs/{id}/results", ListResults},
          {"GET", "/jobs/{id}/results/{file}", GetResultFile},
          {"GET", "/jobs/{id}/results.zip", GetResultsZip},
          {"GET", "/jobs/{id}/report", GetReport},
          {"POST", "/jobs/{id}/cancel", CancelJob},
          {"DELETE", "/jobs/{id}", DeleteJob}};
}

// The route's path as the regular expression httplib matches: a job id is
// 16 lowercase hex digits, a file any rest of the path (checked by its
// handler).
std::string PathPattern(const std::string& path) {
  std::string pattern = std::regex_replace(path, std::regex(R"(\.)"), "\\.");
  pattern =
      std::regex_replace(pattern, std::regex(R"(\{id\})"), "([0-9a-f]{16})");
  return std::regex_replace(pattern, std::regex(R"(\{file\})"), "(.+)");
}

std::string ReadToken(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UsageError("--token-file " + path + ": cannot be read");
  std::string token;
  std::getline(in, token);
  while (!token.empty() && isspace(static_cast<unsigned char>(token.back()))) {
    token.pop_back();
  }
  if (token.size() < 16) {
    throw UsageError("--token-file " + path +
                     ": the token must have at least 16 characters");
  }
  return token;
}

// One server per data root: two would run the same jobs twice. The lock
// (flock, released by the kernel even when the server is killed) is held
// for the life of the process; the file holds the holder's pid.
void LockDataRoot(const std::string& root) {
  const std::string path = root + "/zebrageo-serve.lock";
  const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw UsageError("--data-root " + root + ": cannot be written");
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    std::ifstream in(path);
    std::string pid;
    std::getline(in, pid);
    close(fd);
    throw UsageError("--data-root " + root +
                     ": another zebrageo serve uses it (pid " + pid + ")");
  }
  const std::string pid = std::to_string(getpid()) + "\n";
  if (ftruncate(fd, 0) != 0 || write(fd, pid.data(), pid.size()) < 0) {
    LOG(WARNING) << path << ": cannot record the pid";
  }
  // Deliberately left open: the lock lasts as long as the process.
}

}  // namespace

std::string ServerOptions::Check() const {
  if (data_root.empty()) return "--data-root: required";
  if (!fs::is_directory(data_root)) {
    return "--data-root " + data_root + ": not an existing folder";
  }
  if (port < 0 || port > 65535) return "--port: 0 to 65535";
  if (workers < 1 || workers > 256) return "--workers: 1 to 256";
  if (token_file.empty() && !IsLoopback(host)) {
    return "--bind " + host +
           " is not a loopback address: a --token-file is required";
  }
  if (max_upload_bytes < 1 || max_extracted_bytes < 1 || max_json_bytes < 1) {
    return "size limits must be positive";
  }
  if (http_threads < 1 || http_threads > 1024) {
    return "--http-threads: 1 to 1024";
  }
  if (!(cancel_grace_s >= 0)) return "--cancel-grace: must be >= 0";
  if (job_memory_limit_mb < 0) return "--job-memory-limit-mb: must be >= 0";
  if (webhook_attempts < 1) return "--webhook-attempts: must be >= 1";
  if (!(webhook_first_delay_s >= 0)) {
    return "--webhook-retry-delay: must be >= 0";
  }
  return "";
}

std::vector<RouteName> ServerRoutes() {
  std::vector<RouteName> names = {{"POST", "/jobs"}};
  for (const Route& route : Routes()) {
    names.push_back({route.method, route.path});
  }
  return names;
}

void SendJson(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(1) + "\n", "application/json");
}

void SendError(httplib::Response& res, int status, const std::string& message) {
  SendJson(res, status, {{"error", message}, {"status", status}});
}

bool Authorized(const ApiContext& context, const httplib::Request& req) {
  if (context.token.empty()) return true;
  std::string given;
  const std::string header = req.get_header_value("Authorization");
  if (header.compare(0, 7, "Bearer ") == 0) {
    given = header.substr(7);
  } else if (req.method == "GET" || req.method == "HEAD") {
    // The web page's cookie; never for a request that changes anything.
    static const std::regex kCookie(R"((^|;\s*)zebrageo_token=([^;]*))");
    std::smatch match;
    const std::string cookies = req.get_header_value("Cookie");
    if (std::regex_search(cookies, match, kCookie)) given = match[2];
  }
  // Compared in constant time: the token is a password.
  unsigned char difference = given.size() == context.token.size() ? 0 : 1;
  for (size_t i = 0; i < context.token.size(); ++i) {
    difference |= static_cast<unsigned char>(context.token[i] ^
                                             (i < given.size() ? given[i] : 0));
  }
  return difference == 0;
}

class Server::Impl {
 public:
  explicit Impl(const ServerOptions& options);
  void Configure();
  // Size, framing and token checks before a request is routed.
  httplib::Server::HandlerResponse Admit(const httplib::Request& req,
                                         httplib::Response& res);

  ApiContext context;
  std::unique_ptr<JobStore> store;
  Metrics metrics;
  std::unique_ptr<JobRunner> runner;
  httplib::Server http;
  int port = 0;
};

Server::Impl::Impl(const ServerOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError(problem);
  context.options = options;
  char resolved[PATH_MAX];
  if (realpath(options.data_root.c_str(), resolved) == nullptr) {
    throw UsageError("--data-root " + options.data_root + ": cannot resolve");
  }
  context.root = resolved;
  if (!options.token_file.empty())
    context.token = ReadToken(options.token_file);
  LockDataRoot(context.root);
  fs::create_directories(context.root + "/jobs");
  store = std::make_unique<JobStore>(context.root + "/zebrageo-jobs.sqlite");
  RunnerOptions runner_options;
  runner_options.data_root = context.root;
  runner_options.executable =
      options.executable.empty() ? SelfExecutable() : options.executable;
  runner_options.workers = options.workers;
  runner_options.cancel_grace_s = options.cancel_grace_s;
  runner_options.job_memory_limit_mb = options.job_memory_limit_mb;
  runner_options.webhook.attempts = options.webhook_attempts;
  runner_options.webhook.first_delay_s = options.webhook_first_delay_s;
  runner = std::make_unique<JobRunner>(store.get(), &metrics, runner_options);
  context.store = store.get();
  context.runner = runner.get();
  context.metrics = &metrics;
  context.started_at = NowSeconds();
  metrics.Declare("zebrageo_http_requests_total",
                  "HTTP requests answered, by method and status.", "counter");
  metrics.Declare("zebrageo_build_info", "The server's version.", "gauge");
  metrics.Set("zebrageo_build_info", {{"version", ZEBRAGEO_VERSION_STRING}}, 1);
  Configure();
}

httplib::Server::HandlerResponse Server::Impl::Admit(
    const httplib::Request& req, httplib::Response& res) {
  using Outcome = httplib::Server::HandlerResponse;
  const bool upload = req.method == "POST" && req.path == "/jobs";
  const bool chunked =
      req.get_header_value("Transfer-Encoding").find("chunked") !=
      std::string::npos;
  if (chunked && !upload) {
    res.set_header("Connection", "close");
    SendError(res, 411, "a body of this request needs a Content-Length");
    return Outcome::Handled;
  }
  if (!req.has_header("Content-Length") && !chunked) {
    // RFC 9112 6.3: a request with neither Content-Length nor chunked
    // framing has no body; httplib 0.11 would read one until the client
    // closes, so the length is made explicit.
    const_cast<httplib::Request&>(req).set_header("Content-Length", "0");
  }
  const auto length =
      std::strtoll(req.get_header_value("Content-Length").c_str(), nullptr, 10);
  if (upload && length > context.options.max_upload_bytes + (1 << 20)) {
    res.set_header("Connection", "close");
    SendError(res, 413,
              "the upload is larger than the server's limit of " +
                  std::to_string(context.options.max_upload_bytes) + " bytes");
    return Outcome::Handled;
  }
  if (!upload && length > context.options.max_json_bytes) {
    res.set_header("Connection", "close");
    SendError(res, 413,
              "the body is larger than " +
                  std::to_string(context.options.max_json_bytes) + " bytes");
    return Outcome::Handled;
  }
  const bool open =
      req.path == "/health" || req.path == "/" || req.path == "/app.js";
  if (!open && !Authorized(context, req)) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"zebrageo\"");
    SendError(res, 401,
              req.has_header("Authorization") ? "wrong token"
                                              : "a bearer token is required");
    return Outcome::Handled;
  }
  return Outcome::Unhandled;
}

void Server::Impl::Configure() {
  const int threads = context.options.http_threads;
  http.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  http.set_payload_max_length(
      static_cast<size_t>(context.options.max_upload_bytes) + (1 << 20));
  http.set_read_timeout(30, 0);
  http.set_write_timeout(30, 0);
  http.set_keep_alive_timeout(5);
  http.set_default_headers({{"Cache-Control", "no-store"}});
  // A client that asks before sending its body ("Expect: 100-continue",
  // as curl does for large ones) gets a refusal without sending it.
  http.set_expect_100_continue_handler(
      [this](const httplib::Request& req, httplib::Response& res) {
        return Admit(req, res) == httplib::Server::HandlerResponse::Handled
                   ? res.status
                   : 100;
      });
  http.set_pre_routing_handler(
      [this](const httplib::Request& req, httplib::Response& res) {
        return Admit(req, res);
      });
  // Every error is JSON; a handler's own error body is kept.
  http.set_error_handler(httplib::Server::HandlerWithResponse(
      [](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty() || res.content_length_ > 0) {
          return httplib::Server::HandlerResponse::Unhandled;
        }
        std::string message = "HTTP status " + std::to_string(res.status);
        if (res.status == 400) message = "bad request";
        if (res.status == 404)
          message = "no route " + req.method + " " + req.path;
        if (res.status == 413) message = "the request is larger than allowed";
        SendError(res, res.status, message);
        return httplib::Server::HandlerResponse::Handled;
      }));
  http.set_exception_handler([](const httplib::Request&, httplib::Response& res,
                                std::exception_ptr e) {
    std::string message = "internal error";
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& error) {
      message += std::string(": ") + error.what();
    } catch (...) {
    }
    LOG(ERROR) << message;
    SendError(res, 500, message);
  });
  http.set_logger(
      [this](const httplib::Request& req, const httplib::Response& res) {
        metrics.Add(
            "zebrageo_http_requests_total",
            {{"method", req.method}, {"status", std::to_string(res.status)}});
      });
  for (const Route& route : Routes()) {
    const std::string pattern = PathPattern(route.path);
    const Handler handler = route.handler;
    auto bound = [this, handler](const httplib::Request& req,
                                 httplib::Response& res) {
      handler(context, req, res);
    };
    if (route.method == "GET") http.Get(pattern, bound);
    if (route.method == "POST") http.Post(pattern, bound);
    if (route.method == "DELETE") http.Delete(pattern, bound);
  }
  http.Post("/jobs", [this](const httplib::Request& req, httplib::Response& res,
                            const httplib::ContentReader& reader) {
    CreateJob(context, req, res, reader);
  });
}

Server::Server(const ServerOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}

Server::~Server() { Stop(); }

int Server::Start() {
  const ServerOptions& options = impl_->context.options;
  if (options.port == 0) {
    impl_->port = impl_->http.bind_to_any_port(options.host);
  } else if (impl_->http.bind_to_port(options.host, options.port)) {
    impl_->port = options.port;
  } else {
    impl_->port = -1;
  }
  if (impl_->port <= 0) {
    throw std::runtime_error("cannot listen on " + options.host + ":" +
                             std::to_string(options.port));
  }
  impl_->runner->Start();
  return impl_->port;
}

void Server::Serve() { impl_->http.listen_after_bind(); }

void Server::Stop() {
  if (!impl_) return;
  impl_->http.stop();
  impl_->runner->Stop();
}

}  // namespace zebrageo
