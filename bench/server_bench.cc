// zebrageo serve under load: submits JOBS small simulated surveys at once to
// a real server with WORKERS workers on loopback, and while they run asks
// the API (GET /jobs/{id}, GET /jobs) as a watching client would, 20 times a
// second. Prints jobs per minute and the API's latency (median, p99, worst).
// Usage: server_bench ZEBRAGEO_BINARY [JOBS=20] [WORKERS=2]
#include <fcntl.h>
#include <httplib.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

int Run(const std::vector<std::string>& args, const std::string& out) {
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& s : copy) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t index =
      std::min(values.size() - 1, static_cast<size_t>(p * values.size()));
  return values[index];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: server_bench ZEBRAGEO_BINARY [JOBS] [WORKERS]\n";
    return 2;
  }
  const std::string zebrageo = argv[1];
  const int jobs = argc > 2 ? std::atoi(argv[2]) : 20;
  const int workers = argc > 3 ? std::atoi(argv[3]) : 2;
  const fs::path work = fs::temp_directory_path() /
                        ("zebrageo-server-bench-" + std::to_string(getpid()));
  fs::create_directories(work / "root" / "surveys");
  const std::string survey = (work / "root" / "surveys" / "a").string();
  // The small survey of the tests: 80 m, 2 crossings, 640x480 images.
  const int sim = Run({zebrageo,   "--log-level",
                       "error",    "simulate",
                       "--preset", "demo",
                       "--seed",   "1",
                       "--set",    "road_length_m=80",
                       "--set",    "num_crossings=2",
                       "--set",    "num_stale_crossings=0",
                       "--set",    "min_crossing_spacing_m=25",
                       "--set",    "image_width=640",
                       "--set",    "image_height=480",
                       "--set",    "focal_px=560",
                       "--set",    "supersampling=2",
                       "--set",    "exposure_spacing_m=4",
                       "-o",       survey},
                      (work / "sim.out").string());
  int status = 0;
  waitpid(sim, &status, 0);
  const std::string out = (work / "serve.out").string();
  const pid_t server =
      Run({zebrageo, "serve", "--data-root", (work / "root").string(), "--port",
           "0", "--workers", std::to_string(workers)},
          out);
  int port = 0;
  const std::regex listening(R"(listening on http://127\.0\.0\.1:([0-9]+))");
  for (int i = 0; i < 200 && port == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    std::ifstream in(out);
    std::stringstream text;
    text << in.rdbuf();
    std::smatch match;
    const std::string s = text.str();
    if (std::regex_search(s, match, listening)) port = std::stoi(match[1]);
  }
  if (port == 0) {
    std::cerr << "server_bench: the server did not start\n";
    return 1;
  }
  httplib::Client client("127.0.0.1", port);
  const auto start = Clock::now();
  std::vector<std::string> ids;
  for (int i = 0; i < jobs; ++i) {
    const auto created = client.Post(
        "/jobs", json{{"folder", "surveys/a"}}.dump(), "application/json");
    if (!created || created->status != 201) {
      std::cerr << "server_bench: POST /jobs failed\n";
      return 1;
    }
    ids.push_back(json::parse(created->body)["id"]);
  }
  std::vector<double> latency_ms;
  int done = 0;
  for (size_t tick = 0; done < jobs; ++tick) {
    const auto before = Clock::now();
    const std::string path =
        tick % 2 == 0 ? "/jobs/" + ids[tick / 2 % ids.size()] : "/jobs";
    const auto got = client.Get(path);
    latency_ms.push_back(
        std::chrono::duration<double, std::milli>(Clock::now() - before)
            .count());
    if (tick % 20 == 0 && got) {
      const json list = json::parse(client.Get("/jobs")->body)["jobs"];
      done = 0;
      for (const json& job : list) {
        if (job["state"] == "failed") {
          std::cerr << "server_bench: a job failed: " << job.dump() << "\n";
          return 1;
        }
        done += job["state"] == "done";
      }
    }
    std::this_thread::sleep_until(before + std::chrono::milliseconds(50));
  }
  const double minutes =
      std::chrono::duration<double>(Clock::now() - start).count() / 60.0;
  kill(server, SIGTERM);
  waitpid(server, &status, 0);
  fs::remove_all(work);
  std::printf(
      "server_bench: %d jobs (80 m surveys, 2 crossings), %d workers, %u "
      "cores: %.1f jobs/min (%.1f s in all)\n",
      jobs, workers, std::thread::hardware_concurrency(), jobs / minutes,
      minutes * 60.0);
  std::printf(
      "API while jobs run: %zu requests, latency median %.2f ms, p99 %.2f "
      "ms, worst %.2f ms\n",
      latency_ms.size(), Percentile(latency_ms, 0.5),
      Percentile(latency_ms, 0.99), Percentile(latency_ms, 1.0));
  return 0;
}
