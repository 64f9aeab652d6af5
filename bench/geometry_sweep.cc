// `geometry_sweep [--seeds A-B] [--threads N] [--only KIND] [--max-length M]
//                 [--no-rematch] [--no-lines] [--no-never-worse]
//                 [--no-outage-readings] [--no-images] [--junctions N]
//                 [--avenues -1|0|1]
//                 [--verbose SEED -o DIR]`
//
// Issue 17's geometry sweep: for each seed, a random simulated survey in
// memory (the random preset, no images), a reconstruction and image
// evidence synthesised from its truth with realistic behaviour (recall
// falling with range, parked vehicles, noise growing with range), with the
// lane lines' points, then the matcher and the adjustment with zebra
// crossings and road lines as `zebrageo run` does, in process, scored as
// ../shared/tools/score_results.py scores a results folder. One line per
// survey, then a summary: medians, 95th percentiles and worst cases, wrong
// matches, runs worse than their input, unusable adjustments, crossings
// matched. Exit status 1 when the sweep misses the "Done when".
//
// --verbose SEED -o DIR writes that survey (images rendered) to DIR/survey
// and the synthetic reconstructed_bands.csv (and reconstructed_lines.csv),
// the sweep's matches.csv,
// crossing_decisions.csv and poses.csv to DIR/results, to be run through
// `zebrageo match DIR/survey -o DIR/results` and `zebrageo adjust` and
// inspected (the real match stage reads the rendered images for its paint
// probe, where the sweep emulates it from the truth).
#include "tests/support/geometry_sweep.h"

#include <glog/logging.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>

namespace zebrageo {
namespace {

bool ParseSeeds(const std::string& text, uint64_t* first, uint64_t* last) {
  const size_t dash = text.find('-');
  try {
    *first = std::stoull(text.substr(0, dash));
    *last =
        dash == std::string::npos ? *first : std::stoull(text.substr(dash + 1));
  } catch (const std::exception&) {
    return false;
  }
  return *first >= 1 && *last >= *first;
}

int Main(int argc, char** argv) {
  CLI::App app{
      "Issue 17's geometry sweep: random surveys in memory through "
      "match and adjust, scored against the truth."};
  std::string seeds = "1-100";
  int threads = 2;
  support::GeometrySweepOptions options;
  uint64_t verbose_seed = 0;
  std::string output;
  bool quiet = false;
  app.add_option("--seeds", seeds, "seeds A-B (or one seed)")
      ->capture_default_str();
  app.add_option("--threads", threads, "surveys run in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_option("--only", options.only_kind,
                 "only surveys of this kind of the random preset (drift, "
                 "db_faults, street_faults, multipath, jitter, outage, "
                 "mixed)");
  app.add_option("--preset", options.preset,
                 "a named preset instead of the random one (to compare with "
                 "`zebrageo run` on the same survey)");
  app.add_option("--set", options.sim_set,
                 "simulator option after the draw, key=value (as simulate "
                 "--set; repeat it)");
  app.add_option("--max-length", options.max_road_length_m,
                 "longest road drawn, metres (0: the preset's 1.5 km)")
      ->capture_default_str();
  app.add_option("--junctions", options.junctions,
                 "junctions per survey (issue 51): -1 drawn by the random "
                 "preset, 0 none, N exactly N")
      ->capture_default_str()
      ->check(CLI::Range(-1, 20));
  app.add_option("--avenues", options.avenues,
                 "avenues (issue 52): -1 drawn by the random preset, 0 "
                 "none, 1 every survey")
      ->capture_default_str()
      ->check(CLI::Range(-1, 1));
  app.add_option("--verbose", verbose_seed,
                 "dump this seed's survey and results to -o DIR");
  app.add_option("-o,--output", output, "folder of --verbose");
  app.add_flag("--quiet", quiet, "the summary only");
  app.add_flag("!--no-rematch", options.rematch,
               "match then adjust once (without the second registration "
               "pass of `zebrageo run`)");
  app.add_flag("!--no-lines", options.lines,
               "zebra crossings only (no synthesised road lines)");
  app.add_flag("!--no-images", options.dump_images,
               "--verbose: the survey without its images");
  bool never_worse = true;
  app.add_flag("!--no-never-worse", never_worse,
               "the adjustment without its outage readings and its guard "
               "(issue 43), to compare");
  app.add_flag("!--no-outage-readings", options.outage_readings,
               "the adjustment without its outage readings (the guard on)");
  int log_level = -1;
  app.add_option("--log", log_level,
                 "the stages' logs to stderr, with VLOG up to this level "
                 "(one seed at a time)");
  CLI11_PARSE(app, argc, argv);
  if (!never_worse) options.outage_readings = options.guard = false;
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = log_level < 0 ? google::GLOG_ERROR : google::GLOG_INFO;
  FLAGS_v = std::max(0, log_level);
  google::InitGoogleLogging(argv[0]);

  const std::string problem = options.Check();
  if (!problem.empty()) {
    std::cerr << "geometry_sweep: " << problem << "\n";
    return 2;
  }
  if (verbose_seed > 0) {
    if (output.empty()) {
      std::cerr << "geometry_sweep: --verbose needs -o DIR\n";
      return 2;
    }
    const support::GeometryRunResult result =
        support::RunGeometrySurvey(verbose_seed, options, output);
    std::cout << result.Line() << "\n"
              << "survey in " << output << "/survey, results in " << output
              << "/results:\n  zebrageo match " << output << "/survey -o "
              << output << "/results\n  zebrageo adjust " << output
              << "/survey -o " << output << "/results --no-tie-points"
              << (options.lines ? "" : " --no-lines") << "\n";
    return result.error.empty() ? 0 : 1;
  }
  uint64_t first = 0, last = 0;
  if (!ParseSeeds(seeds, &first, &last)) {
    std::cerr << "geometry_sweep: --seeds \"" << seeds
              << "\": expected A-B with 1 <= A <= B\n";
    return 2;
  }
  const auto results =
      support::RunGeometrySweep(first, last, threads, options,
                                [quiet](const support::GeometryRunResult& r) {
                                  if (!quiet)
                                    std::cout << r.Line() << std::endl;
                                });
  const support::GeometrySweepSummary summary = support::Summarise(results);
  std::cout << "\n" << summary.Report();
  const auto failures = summary.Failures();
  for (const std::string& f : failures) std::cout << "FAIL: " << f << "\n";
  return failures.empty() ? 0 : 1;
}

}  // namespace
}  // namespace zebrageo

int main(int argc, char** argv) { return zebrageo::Main(argc, argv); }
