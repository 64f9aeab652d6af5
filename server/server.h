// `zebrageo serve`: the georeferencing service. A REST API (JSON) over
// cpp-httplib, documented in server/openapi.json (served at /openapi.json),
// jobs in SQLite (server/job_store.h), each job a `zebrageo run` child
// (server/job_runner.h), a small web page at /. See docs/server.md.
#ifndef ZEBRAGEO_SERVER_SERVER_H_
#define ZEBRAGEO_SERVER_SERVER_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace zebrageo {

struct ServerOptions {
  std::string data_root;  // the jobs, the database and the folder surveys
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port (printed when listening)
  int workers = 2;  // jobs run at once
  // A file holding the bearer token; required unless `host` is loopback.
  std::string token_file;
  int64_t max_upload_bytes = int64_t{16} << 30;
  int64_t max_extracted_bytes = int64_t{64} << 30;
  int64_t max_json_bytes = int64_t{1} << 20;  // any other request body
  int max_queued_jobs = 10000;                // POST /jobs answers 503 beyond
  int http_threads = 8;                       // requests served at once
  double cancel_grace_s = 10.0;
  long job_memory_limit_mb = 0;  // RLIMIT_AS of each run; 0: none
  int webhook_attempts = 5;
  double webhook_first_delay_s = 2.0;
  // The zebrageo binary the jobs run (default: this executable).
  std::string executable;

  // "" or the first problem, in the CLI's words.
  std::string Check() const;
};

// Every route of the server, as the OpenAPI file names it ("GET",
// "/jobs/{id}"): the test checks each against server/openapi.json.
struct RouteName {
  std::string method;
  std::string path;
};
std::vector<RouteName> ServerRoutes();

// server/openapi.json as built into the program.
const std::string& OpenApiDocument();

class Server {
 public:
  // Opens the data root (creating its database and jobs/ folder). Throws
  // UsageError for bad options, std::runtime_error when the data root or
  // the database cannot be used.
  explicit Server(const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds, then recovers the jobs of a previous server and starts the
  // workers; returns the port (the chosen one for port 0). Requests wait
  // until Serve(). Throws std::runtime_error when the address cannot be
  // bound.
  int Start();
  // Serves requests until Stop(). Call Start() first.
  void Serve();
  // From any thread (a signal handler's thread): stops serving and the
  // workers; running jobs stay running in the store and resume next time.
  void Stop();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_SERVER_H_
