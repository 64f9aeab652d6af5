// Reconstruction (issue 5): time per stereo pair and per step on one core,
// 1280 x 960 images of a simulated street with a zebra crossing, parked
// vehicles and facades. Target: <= 200 ms per stereo pair.
//
// The survey is bench/bench_survey.h's (image reading is reported
// separately by `zebrageo reconstruct`).
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "bench/bench_survey.h"
#include "reconstruction/reconstruction.h"

namespace zebrageo {
namespace {

// The shared bench survey, and the pair reconstructor on its road plane.
struct Fixture {
  BenchSurvey survey{"reconstruction-bench"};
  std::unique_ptr<StereoPairReconstructor> pair;
  const RoadPlane& road = survey.road;
  const std::vector<std::pair<cv::Mat, cv::Mat>>& images = survey.images;

  Fixture() {
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

// One stereo pair, all steps, one thread; counters give the per-step
// profile in milliseconds per pair.
void BM_StereoPair(benchmark::State& state) {
  Fixture& f = TheFixture();
  const SearchVolumeOptions search;
  StepTimings total;
  int64_t pairs = 0, bands = 0;
  size_t next = 0;
  for (auto _ : state) {
    const auto& [left, right] = f.images[next++ % f.images.size()];
    const PairReconstruction result =
        f.pair->Reconstruct(left, right, f.road, search.slab_half_thickness_m,
                            search.tolerance_angle_rad, 1, false, "");
    total.Add(result.timings);
    bands += static_cast<int64_t>(result.bands.size());
    ++pairs;
  }
  const double n = static_cast<double>(pairs);
  state.counters["rectify_ms"] = 1e3 * total.rectify_s / n;
  state.counters["edges_ms"] = 1e3 * total.edges_s / n;
  state.counters["matching_ms"] = 1e3 * total.matching_s / n;
  state.counters["road_plane_ms"] = 1e3 * total.road_plane_s / n;
  state.counters["long_sides_ms"] = 1e3 * total.long_sides_s / n;
  state.counters["bands_ms"] = 1e3 * total.bands_s / n;
  state.counters["bands_per_pair"] = bands / n;
}
BENCHMARK(BM_StereoPair)->Unit(benchmark::kMillisecond)->MinTime(5.0);

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
