// bal_bench: our solver core against COLMAP's `colmap bundle_adjuster` on
// Bundle Adjustment in the Large problems, same reduced problem, same
// threads, one run; prints time and final cost side by side.
//
//   bal_bench [--threads N] [--datasets DIR] [problem.txt.bz2 ...]
//
// Default problems: problem-21-11315 and problem-16-22106 from
// ../shared/datasets/bal. COLMAP first drops the observations of points
// behind a camera and the points seen by fewer than three images; both
// solvers get that same reduced problem (ReduceLikeColmap), exported exactly
// to a COLMAP text model (ColmapModelOf, geodata/colmap_export.h). COLMAP's
// final cost is recomputed here from the model it writes, with the same cost
// function.
//
// COLMAP is optional: install it with `apt-get install colmap` (Debian 12:
// COLMAP 3.8). Without it the COLMAP column is skipped with a message.
// `colmap bundle_adjuster` has no thread option (it uses every core once a
// problem has 50k residuals), so with --threads N it is pinned to N cores
// with `taskset`.
#include <glog/logging.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "adjustment/bal/bal_adjuster.h"
#include "adjustment/bal/bal_problem.h"
#include "geodata/colmap_export.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

double Now() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool CommandExists(const std::string& name) {
  return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

struct ColmapRun {
  bool ok = false;
  std::string error;
  double final_cost = 0.0;
  double ceres_time_s = 0.0;  // "Time" line of COLMAP's report
  double wall_time_s = 0.0;   // the bundle_adjuster process
  int iterations = 0;
  long residuals = 0;
};

// Runs a shell command, output to `log`; returns its exit status.
int Run(const std::string& command, const std::string& log) {
  const int status = std::system((command + " >" + log + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

ColmapRun RunColmap(const BalProblem& problem, int threads,
                    const std::string& work) {
  ColmapRun run;
  const std::string input = work + "/colmap_in";
  const std::string output = work + "/colmap_out";
  const std::string text = work + "/colmap_out_txt";
  for (const std::string& f : {input, output, text}) {
    fs::remove_all(f);
    fs::create_directories(f);
  }
  WriteColmapModel(ColmapModelOf(problem), input);
  std::string cpus = "0";
  for (int i = 1; i < threads; ++i) cpus += "," + std::to_string(i);
  const std::string pin =
      CommandExists("taskset") ? "taskset -c " + cpus + " " : "";
  const std::string log = work + "/colmap_ba.log";
  const double start = Now();
  const int status = Run(pin + "colmap bundle_adjuster --input_path " + input +
                             " --output_path " + output,
                         log);
  run.wall_time_s = Now() - start;
  if (status != 0) {
    run.error = "colmap bundle_adjuster failed (exit " +
                std::to_string(status) + "), see " + log;
    return run;
  }
  if (Run("colmap model_converter --input_path " + output + " --output_path " +
              text + " --output_type TXT",
          work + "/colmap_convert.log") != 0) {
    run.error = "colmap model_converter failed";
    return run;
  }
  std::ifstream in(log);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string report = buffer.str();
  std::smatch m;
  if (std::regex_search(report, m, std::regex(R"(Time\s*:\s*([0-9.eE+-]+))"))) {
    run.ceres_time_s = std::stod(m[1]);
  }
  if (std::regex_search(report, m,
                        std::regex(R"(Iterations\s*:\s*([0-9]+))"))) {
    run.iterations = std::stoi(m[1]);
  }
  if (std::regex_search(report, m, std::regex(R"(Residuals\s*:\s*([0-9]+))"))) {
    run.residuals = std::stol(m[1]);
  }
  const BalProblem adjusted = BalProblemOf(ReadColmapModel(text));
  run.final_cost = BalCost(adjusted);
  run.ok = true;
  return run;
}

int Main(int argc, char** argv) {
  int threads = 1;
  std::string datasets = std::string(ZEBRAGEO_SHARED_DIR) + "/datasets";
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::atoi(argv[++i]);
    } else if (arg == "--datasets" && i + 1 < argc) {
      datasets = argv[++i];
    } else if (arg == "-h" || arg == "--help") {
      std::cout << "usage: bal_bench [--threads N] [--datasets DIR] "
                   "[problem.txt(.bz2) ...]\n";
      return 0;
    } else {
      files.push_back(arg);
    }
  }
  if (files.empty()) {
    for (const char* name :
         {"problem-21-11315-pre.txt.bz2", "problem-16-22106-pre.txt.bz2"}) {
      files.push_back(datasets + "/bal/" + name);
    }
  }
  const bool have_colmap = CommandExists("colmap");
  if (!have_colmap) {
    std::cout << "COLMAP is not installed: the COLMAP column is skipped "
                 "(install it with `apt-get install colmap`).\n";
  }
  const std::string work =
      (fs::temp_directory_path() / ("bal_bench-" + std::to_string(getpid())))
          .string();
  fs::create_directories(work);

  std::printf("%-22s %7s %10s | %12s %8s %5s | %12s %8s %8s %5s | %6s\n",
              "problem", "threads", "residuals", "ours cost", "ours s", "iter",
              "colmap cost", "colmap s", "wall s", "iter", "ratio");
  int failures = 0;
  for (const std::string& file : files) {
    if (!fs::exists(file)) {
      std::cout << file
                << ": not found (../shared/datasets absent?), skipped\n";
      continue;
    }
    BalReduction reduction;
    const BalProblem original = ReadBalProblem(file);
    BalProblem problem = ReduceLikeColmap(original, 3, &reduction);
    VLOG(1) << file << ": dropped " << reduction.dropped_behind
            << " observations behind cameras, " << reduction.dropped_short_track
            << " in short tracks";

    ColmapRun colmap;
    if (have_colmap) colmap = RunColmap(problem, threads, work);

    BalAdjusterOptions options;
    options.solver.num_threads = threads;
    const double start = Now();
    const BalAdjusterSummary ours = AdjustBalProblem(options, &problem);
    const double ours_wall = Now() - start;
    if (!ours.IsUsable()) ++failures;

    const std::string name = fs::path(file).filename().string();
    if (colmap.ok) {
      std::printf(
          "%-22s %7d %10d | %12.6e %8.3f %5d | %12.6e %8.3f %8.3f %5d | "
          "%5.2fx\n",
          name.substr(0, 22).c_str(), threads, ours.num_residuals,
          ours.final_cost, ours_wall, ours.iterations, colmap.final_cost,
          colmap.ceres_time_s, colmap.wall_time_s, colmap.iterations,
          colmap.ceres_time_s / ours_wall);
      std::printf(
          "%-22s relative cost difference %+.2e (ours - colmap), "
          "COLMAP residuals %ld\n",
          "", (ours.final_cost - colmap.final_cost) / colmap.final_cost,
          colmap.residuals);
    } else {
      std::printf("%-22s %7d %10d | %12.6e %8.3f %5d | %s\n",
                  name.substr(0, 22).c_str(), threads, ours.num_residuals,
                  ours.final_cost, ours_wall, ours.iterations,
                  have_colmap ? colmap.error.c_str() : "(no COLMAP)");
    }
  }
  fs::remove_all(work);
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace zebrageo

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  return zebrageo::Main(argc, argv);
}
