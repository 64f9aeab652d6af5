// `zebrageo serve --data-root DIR --port N [--workers K] [--token-file F]`:
// the georeferencing service (server/server.h; docs/server.md).
#include <glog/logging.h>
#include <signal.h>

#include <iostream>
#include <memory>
#include <thread>

#include "pipeline/exit_codes.h"
#include "server/server.h"
#include "tools/commands.h"

namespace zebrageo {
namespace {

struct ServeArguments {
  ServerOptions options;
  double max_upload_mb = 16384;
  double max_extracted_mb = 65536;
};

void Serve(const ServeArguments& args) {
  ServerOptions options = args.options;
  for (const double mb : {args.max_upload_mb, args.max_extracted_mb}) {
    if (!(mb > 0 && mb < 1e9)) {
      throw UsageError("--max-upload-mb and --max-extracted-mb: from 0 to 1e9");
    }
  }
  options.max_upload_bytes = static_cast<int64_t>(args.max_upload_mb * 1048576);
  options.max_extracted_bytes =
      static_cast<int64_t>(args.max_extracted_mb * 1048576);
  // SIGINT and SIGTERM stop the server cleanly from one thread of its own;
  // every other thread (and so every worker) inherits them blocked.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);

  Server server(options);
  const int port = server.Start();
  std::thread stopper([&server, stop_signals] {
    int received = 0;
    sigwait(&stop_signals, &received);
    LOG(INFO) << "serve: signal " << received << ", stopping";
    server.Stop();
  });
  std::cout << "zebrageo serve: listening on http://" << options.host << ":"
            << port << " (data root " << options.data_root << ", "
            << options.workers << " workers)" << std::endl;
  server.Serve();
  // Serve returns after Stop(); should it return otherwise, wake the
  // stopper so that it ends.
  kill(getpid(), SIGTERM);
  stopper.join();
}

}  // namespace

void AddServeCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<ServeArguments>();
  CLI::App* serve = app->add_subcommand(
      "serve",
      "The georeferencing service: an HTTP job API (docs/server.md) whose "
      "jobs run `zebrageo run` in child processes and survive restarts.");
  ServerOptions& options = args->options;
  serve
      ->add_option("--data-root", options.data_root,
                   "folder of the jobs, their database and folder surveys")
      ->required();
  serve->add_option("--port", options.port, "TCP port (0: any free one)")
      ->capture_default_str();
  serve
      ->add_option("--bind", options.host,
                   "address to listen on (not loopback: --token-file needed)")
      ->capture_default_str();
  serve->add_option("--workers", options.workers, "jobs run at once")
      ->capture_default_str();
  serve->add_option("--token-file", options.token_file,
                    "file holding the bearer token clients must send");
  serve
      ->add_option("--max-upload-mb", args->max_upload_mb,
                   "largest survey archive accepted")
      ->capture_default_str();
  serve
      ->add_option("--max-extracted-mb", args->max_extracted_mb,
                   "largest extracted survey accepted")
      ->capture_default_str();
  serve
      ->add_option("--http-threads", options.http_threads,
                   "requests served at once")
      ->capture_default_str();
  serve
      ->add_option("--cancel-grace", options.cancel_grace_s,
                   "seconds between SIGTERM and SIGKILL of a cancelled run")
      ->capture_default_str();
  serve
      ->add_option("--job-memory-limit-mb", options.job_memory_limit_mb,
                   "address-space limit of each run (0: none)")
      ->capture_default_str();
  serve
      ->add_option("--webhook-attempts", options.webhook_attempts,
                   "deliveries tried per webhook")
      ->capture_default_str();
  serve
      ->add_option("--webhook-retry-delay", options.webhook_first_delay_s,
                   "seconds before the second delivery (doubled after)")
      ->capture_default_str();
  commands->push_back({serve, [args] { Serve(*args); }});
}

}  // namespace zebrageo
