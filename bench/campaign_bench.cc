// campaign_bench: issue 46's geometry-level campaign, time and peak memory
// against its size.
//
//   campaign_bench [--exposures 10000,100000,1000000] [--survey-length-m L]
//                  [--block-length-m B] [--overlap-m O] [--jobs J]
//                  [--threads N]
//
// A fleet's campaign without images: surveys of the `large` preset (10 km
// roads with crossings every ~120 m, drift, an outage, database faults;
// render_images off) of --survey-length-m each, seeds 1, 2, ..., as many as
// make the number of exposures asked. Each survey is simulated in memory,
// its bands and lane lines synthesised from the truth as the geometry sweep
// does (tests/support/synthetic_reconstruction.h, synthetic_lines.h), then
// goes through the campaign's steps with the campaign library's own code:
// plan (PlanSurveyBlocks: blocks, overlaps), per block match (BuildObservations
// + MatchBands on the block's exposures) and adjust (AdjustWithRoadLines on
// the block's trajectory, as `run-block` runs it), and merge
// (BlendBlockPoses). The merged trajectory is scored against the truth at
// the exposures (horizontal RMS before and after).
//
// Surveys are processed --jobs at a time and dropped once merged (a
// cluster's merge job does the same survey by survey): memory is bounded by
// --jobs surveys, not by the campaign. Each size runs in a child process
// of its own, so its peak memory (the child's maximum resident set) is its
// own. Prints one line per size: surveys, blocks, exposures, wall and CPU
// seconds, peak MB, per-exposure cost; then the growth between sizes.
#include <glog/logging.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "campaign/merge.h"
#include "campaign/plan.h"
#include "pipeline/adjustment_pass.h"
#include "registration/band_matcher.h"
#include "registration/observations.h"
#include "registration/roadmark_index.h"
#include "simulator/simulated_survey.h"
#include "survey/math_util.h"
#include "tests/support/synthetic_lines.h"
#include "tests/support/synthetic_reconstruction.h"

namespace zebrageo {
namespace {

struct BenchOptions {
  double survey_length_m = 10000.0;
  PlanOptions plan;
  int threads = 1;
  int jobs = 2;  // surveys in parallel
};

struct SizeFigures {
  int surveys = 0;
  int blocks = 0;
  long exposures = 0;
  int usable_blocks = 0;
  double h_before_sq = 0.0, h_after_sq = 0.0;  // sums over exposures
  long scored = 0;
  void Add(const SizeFigures& o) {
    surveys += o.surveys;
    blocks += o.blocks;
    exposures += o.exposures;
    usable_blocks += o.usable_blocks;
    h_before_sq += o.h_before_sq;
    h_after_sq += o.h_after_sq;
    scored += o.scored;
  }
};

// The block's survey: the trajectory samples and exposures of `block`, the
// rig, frame and database of `survey` (what WriteBlockSurvey writes).
Survey BlockSurvey(const Survey& survey, const CampaignBlock& block) {
  Survey s;
  s.folder = survey.folder;
  s.manifest = survey.manifest;
  s.rig = survey.rig;
  s.frame = survey.frame;
  s.roadmarks = survey.roadmarks;
  const std::vector<TrajectorySample>& samples = survey.trajectory.samples();
  s.trajectory = Trajectory(
      std::vector<TrajectorySample>(samples.begin() + block.first_sample,
                                    samples.begin() + block.last_sample + 1),
      survey.frame);
  for (const Exposure& e : survey.exposures.exposures) {
    if (e.time < block.start_time || e.time > block.end_time) continue;
    Exposure copy = e;
    for (int& image : copy.image_of_camera) {
      if (image < 0) continue;
      s.exposures.images.push_back(survey.exposures.images[image]);
      image = static_cast<int>(s.exposures.images.size()) - 1;
    }
    s.exposures.exposures.push_back(copy);
  }
  return s;
}

template <typename Row>
std::vector<Row> OfExposures(const std::vector<Row>& rows,
                             const std::set<int64_t>& exposures) {
  std::vector<Row> kept;
  for (const Row& r : rows) {
    if (exposures.count(r.exposure_id)) kept.push_back(r);
  }
  return kept;
}

// Match and adjust of one block; its corrected poses at its samples (the
// input's where the adjustment is not usable).
std::vector<Pose> RunBlock(const Survey& block_survey,
                           const std::vector<ReconstructedVertex>& all_vertices,
                           const std::vector<ReconstructedLinePoint>& all_lines,
                           const support::TruthPaintProbe& probe,
                           const BenchOptions& options, bool* usable) {
  std::set<int64_t> ids;
  for (const Exposure& e : block_survey.exposures.exposures) {
    ids.insert(e.exposure_id);
  }
  const std::vector<ReconstructedVertex> vertices =
      OfExposures(all_vertices, ids);
  const std::vector<ReconstructedLinePoint> lines = OfExposures(all_lines, ids);
  MatchInput input;
  int incomplete = 0;
  input.observations = BuildObservations(block_survey, vertices,
                                         kReconstructedBandsFile, &incomplete);
  input.exposures = ExposurePoses(block_survey);
  const RoadmarkIndex index(block_survey.roadmarks, block_survey.frame);
  input.index = &index;
  input.rig = &block_survey.rig;
  input.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                               const BandCornersEnu& band,
                               const std::vector<BandCornersEnu>& seen) {
    return probe.Classify(exposure_id, pose, band, seen);
  };
  const MatchResult match = MatchBands(input, MatchOptions());
  AdjustmentOptions adjustment;
  adjustment.solver.num_threads = options.threads;
  adjustment.log_warnings = false;
  const AdjustmentData data =
      AdjustmentDataOf(block_survey, vertices, match.matches);
  const AdjustmentPass pass = AdjustWithRoadLines(
      data, data.Input(), adjustment, LineRegistrationOptions(), &lines);
  *usable = pass.result.summary.IsUsable() &&
            pass.result.corrected_samples.size() ==
                static_cast<size_t>(block_survey.trajectory.size());
  if (!*usable) return block_survey.trajectory.poses();
  return Trajectory(pass.result.corrected_samples, block_survey.frame).poses();
}

// One survey of the campaign through plan, match and adjust per block and
// merge; adds its figures.
void RunSurvey(uint64_t seed, const BenchOptions& options,
               SizeFigures* figures) {
  SimulationOptions simulation;
  simulation.seed = seed;
  const std::string problem = ApplyPreset("large", &simulation);
  CHECK(problem.empty()) << problem;
  simulation.road_length_m = options.survey_length_m;
  simulation.num_crossings =
      std::max(2, static_cast<int>(options.survey_length_m / 10000.0 * 80.0));
  simulation.render_images = false;
  const sim::SimulatedSurvey simulated = sim::MakeSimulatedSurvey(simulation);
  const Survey survey = sim::ToSurvey(simulated, "");
  const support::ReconstructionModel model;
  const support::SyntheticReconstruction reconstruction =
      support::SynthesiseReconstruction(simulated, model, seed);
  const std::vector<ReconstructedLinePoint> lines =
      support::SynthesiseLinePoints(simulated, model, seed);
  const support::TruthPaintProbe probe(simulated, model, seed);

  // Plan.
  Campaign campaign;
  campaign.surveys.emplace_back();
  PlanSurveyBlocks(survey, 0, options.plan, &campaign);

  // Match and adjust per block.
  std::vector<std::vector<Pose>> corrected(campaign.blocks.size());
  for (size_t k = 0; k < campaign.blocks.size(); ++k) {
    bool usable = false;
    corrected[k] =
        RunBlock(BlockSurvey(survey, campaign.blocks[k]),
                 reconstruction.vertices, lines, probe, options, &usable);
    figures->usable_blocks += usable;
  }

  // Merge.
  std::vector<BlockPoses> views;
  for (size_t k = 0; k < campaign.blocks.size(); ++k) {
    BlockPoses view;
    view.block = &campaign.blocks[k];
    view.poses = &corrected[k];
    for (const CampaignOverlap& o : campaign.overlaps) {
      if (o.after == static_cast<int>(k)) view.before_overlap_end = &o.end_time;
      if (o.before == static_cast<int>(k)) {
        view.after_overlap_start = &o.start_time;
      }
    }
    views.push_back(view);
  }
  std::vector<double> times;
  for (const TrajectorySample& s : survey.trajectory.samples()) {
    times.push_back(s.time);
  }
  std::vector<int> dominant;
  const std::vector<Pose> merged_poses =
      BlendBlockPoses(times, views, &dominant);
  std::vector<TrajectorySample> merged_samples;
  for (size_t i = 0; i < times.size(); ++i) {
    merged_samples.push_back(
        SampleFromPose(times[i], merged_poses[i], survey.frame,
                       Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
  }
  const Trajectory merged(std::move(merged_samples), survey.frame);

  // Score at the exposures: the body positions against the truth.
  const Trajectory truth(simulated.motion.truth, simulated.frame);
  for (const Exposure& e : survey.exposures.exposures) {
    Pose t, before, after;
    if (!truth.InterpolatePose(e.time, &t) ||
        !survey.trajectory.InterpolatePose(e.time, &before) ||
        !merged.InterpolatePose(e.time, &after)) {
      continue;
    }
    figures->h_before_sq += (before.p_enu - t.p_enu).head<2>().squaredNorm();
    figures->h_after_sq += (after.p_enu - t.p_enu).head<2>().squaredNorm();
    ++figures->scored;
  }
  ++figures->surveys;
  figures->blocks += static_cast<int>(campaign.blocks.size());
  figures->exposures += static_cast<long>(survey.exposures.exposures.size());
}

double CpuSeconds(const rusage& usage) {
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Runs the surveys that make about `exposures` (options.jobs at a time,
// seeds 1, 2, ...); prints the size's line.
void RunSize(long exposures, const BenchOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SizeFigures figures;
  std::mutex mutex;
  // Surveys of the simulator's exposure spacing: the campaign's size in
  // whole surveys.
  const double per_survey =
      options.survey_length_m / SimulationOptions().exposure_spacing_m;
  const uint64_t surveys = std::max<uint64_t>(
      1, static_cast<uint64_t>(std::llround(exposures / per_survey)));
  uint64_t next_seed = 1;
  std::vector<std::thread> workers;
  for (int j = 0; j < options.jobs; ++j) {
    workers.emplace_back([&] {
      for (;;) {
        uint64_t seed = 0;
        {
          std::lock_guard<std::mutex> lock(mutex);
          if (next_seed > surveys) return;
          seed = next_seed++;
        }
        SizeFigures one;
        RunSurvey(seed, options, &one);
        std::lock_guard<std::mutex> lock(mutex);
        figures.Add(one);
        const double wall = std::chrono::duration<double>(
                                std::chrono::steady_clock::now() - start)
                                .count();
        std::fprintf(stderr, "  %ld / %ld exposures, %d surveys, %.0f s\n",
                     figures.exposures, exposures, figures.surveys, wall);
      }
    });
  }
  for (std::thread& w : workers) w.join();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double n = std::max<long>(1, figures.scored);
  std::printf(
      "exposures %ld  surveys %d  blocks %d (%d adjusted)  wall %.1f s  "
      "cpu %.1f s  peak %.0f MB  cpu/exposure %.2f ms  H before %.1f cm "
      "after %.1f cm (RMS)\n",
      figures.exposures, figures.surveys, figures.blocks, figures.usable_blocks,
      wall, CpuSeconds(usage), usage.ru_maxrss / 1024.0,
      1e3 * CpuSeconds(usage) / figures.exposures,
      100.0 * std::sqrt(figures.h_before_sq / n),
      100.0 * std::sqrt(figures.h_after_sq / n));
  std::fflush(stdout);
}

std::vector<long> ParseSizes(const std::string& text) {
  std::vector<long> sizes;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      sizes.push_back(std::stol(item));
    } catch (const std::exception&) {
      return {};
    }
    if (sizes.back() <= 0) return {};
  }
  return sizes;
}

int Main(int argc, char** argv) {
  CLI::App app{
      "Issue 46's geometry-level campaign: plan, match and adjust per block, "
      "merge; time and peak memory per campaign size."};
  std::string sizes_text = "10000,100000,1000000";
  BenchOptions options;
  options.plan.block_length_m = 500.0;
  options.plan.overlap_m = 150.0;
  app.add_option("--exposures", sizes_text, "campaign sizes, comma-separated")
      ->capture_default_str();
  app.add_option("--survey-length-m", options.survey_length_m,
                 "length of each survey (a vehicle's day in a real fleet)")
      ->capture_default_str()
      ->check(CLI::Range(1000.0, 200000.0));
  app.add_option("--block-length-m", options.plan.block_length_m)
      ->capture_default_str();
  app.add_option("--overlap-m", options.plan.overlap_m)->capture_default_str();
  app.add_option("--jobs", options.jobs, "surveys run in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_option("--threads", options.threads, "adjustment threads")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  CLI11_PARSE(app, argc, argv);
  const std::vector<long> sizes = ParseSizes(sizes_text);
  if (sizes.empty()) {
    std::fprintf(stderr, "--exposures: positive integers, comma-separated\n");
    return 2;
  }
  const std::string problem = options.plan.Check();
  if (!problem.empty()) {
    std::fprintf(stderr, "%s\n", problem.c_str());
    return 2;
  }
  for (long size : sizes) {
    std::fflush(stdout);
    const pid_t child = ::fork();
    if (child < 0) {
      std::perror("fork");
      return 1;
    }
    if (child == 0) {
      RunSize(size, options);
      std::_Exit(0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "size %ld failed (status %d)\n", size, status);
      return 1;
    }
  }
  return 0;
}

}  // namespace
}  // namespace zebrageo

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_minloglevel = 1;
  return zebrageo::Main(argc, argv);
}
