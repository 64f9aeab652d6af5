// Reconstruction (issues 5, 46): CPU per stereo pair and per step,
// 1280 x 960 images of a simulated street with a zebra crossing, parked
// vehicles and facades, on one and two threads. Target (issue 46): <= 50
// ms of CPU per stereo pair, 2 threads at least 1.8x one.
//
// The survey is bench/bench_survey.h's; decoding its images is timed
// apart (BM_ReadPair).
#include <benchmark/benchmark.h>

#include <memory>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "bench/bench_survey.h"
#include "reconstruction/reconstruction.h"
#include "survey/image_io.h"

namespace zebrageo {
namespace {

// The shared bench survey, and the pair reconstructor on its road plane.
struct Fixture {
  BenchSurvey survey{"reconstruction-bench"};
  std::unique_ptr<StereoPairReconstructor> pair;
  const RoadPlane& road = survey.road;
  const std::vector<std::pair<cv::Mat, cv::Mat>>& images = survey.images;

  Fixture() {
    cv::setNumThreads(1);  // as zebrageo runs: its own workers only
    ReconstructionOptions options;
    options.threads = 1;
    const Rig& rig = survey.survey->rig;
    pair = std::make_unique<StereoPairReconstructor>(
        rig.cameras[rig.stereo_pairs[0][0]],
        rig.cameras[rig.stereo_pairs[0][1]], road, options);
  }
};

// Destroyed at exit, which removes the simulated survey.
Fixture& TheFixture() {
  static Fixture fixture;
  return fixture;
}

// One stereo pair, all steps, as a worker of the zebra stage runs them
// (one workspace per thread, reused from pair to pair); counters give the
// per-step profile in milliseconds of the worker's CPU per pair. The CPU
// column is the whole process's (OpenCV's own threads included). With
// /threads:2 two workers run pairs at once: items_per_second against
// /threads:1 is the scaling with threads.
void BM_StereoPair(benchmark::State& state) {
  Fixture& f = TheFixture();
  const SearchVolumeOptions search;
  StepTimings total;
  int64_t pairs = 0, bands = 0;
  size_t next = static_cast<size_t>(state.thread_index());
  PairWorkspace workspace;
  for (auto _ : state) {
    const auto& [left, right] = f.images[next % f.images.size()];
    next += static_cast<size_t>(state.threads());
    const PairReconstruction result = f.pair->Reconstruct(
        left, right, f.road, search.slab_half_thickness_m,
        search.tolerance_angle_rad, 1, false, "", &workspace);
    total.Add(result.timings);
    bands += static_cast<int64_t>(result.bands.size());
    ++pairs;
  }
  const double n = static_cast<double>(pairs);
  const auto per_pair = benchmark::Counter::kAvgThreads;
  state.counters["rectify_ms"] = {1e3 * total.rectify_s / n, per_pair};
  state.counters["edges_ms"] = {1e3 * total.edges_s / n, per_pair};
  state.counters["matching_ms"] = {1e3 * total.matching_s / n, per_pair};
  state.counters["road_plane_ms"] = {1e3 * total.road_plane_s / n, per_pair};
  state.counters["monoplot_ms"] = {1e3 * total.monoplot_s / n, per_pair};
  state.counters["long_sides_ms"] = {1e3 * total.long_sides_s / n, per_pair};
  state.counters["bands_ms"] = {1e3 * total.bands_s / n, per_pair};
  state.counters["steps_ms"] = {1e3 * total.Total() / n, per_pair};
  state.counters["bands_per_pair"] = {bands / n, per_pair};
  state.SetItemsProcessed(pairs);
}
BENCHMARK(BM_StereoPair)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(5.0)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Threads(1)
    ->Threads(2);

// Decoding a stereo pair's two images from their files (the zebra stage's
// "read" step; not in BM_StereoPair, whose images are decoded up front).
void BM_ReadPair(benchmark::State& state) {
  Fixture& f = TheFixture();
  const Survey& survey = *f.survey.survey;
  const Rig& rig = survey.rig;
  size_t next = 0;
  for (auto _ : state) {
    const Exposure& e =
        survey.exposures.exposures[next++ % survey.exposures.exposures.size()];
    for (int s = 0; s < 2; ++s) {
      const ExposureImage& image =
          survey.exposures.images[e.image_of_camera[rig.stereo_pairs[0][s]]];
      benchmark::DoNotOptimize(
          ReadGrayImage(survey.PathOf(image.image), image.image));
    }
  }
}
BENCHMARK(BM_ReadPair)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// Building the rectification tables of a pair (once per survey).
void BM_BuildRectification(benchmark::State& state) {
  Fixture& f = TheFixture();
  const Rig& rig = f.survey.survey->rig;
  for (auto _ : state) {
    RoadRectification rectification;
    std::string error;
    benchmark::DoNotOptimize(
        rectification.Build(rig.cameras[rig.stereo_pairs[0][0]],
                            rig.cameras[rig.stereo_pairs[0][1]], f.road,
                            RectificationOptions(), &error));
  }
}
BENCHMARK(BM_BuildRectification)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace zebrageo

BENCHMARK_MAIN();
