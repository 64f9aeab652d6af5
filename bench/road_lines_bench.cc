// Road lines (issue 9): extraction time per image on one core, 1280 x 960
// simulated images of a street with lane lines, a stop line and a zebra
// crossing. Target: <= 50 ms per image (a stereo pair is two images: the
// counter ms_per_image is the pair's time halved).
//
// The survey is bench/bench_survey.h's, with a stop line.
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "bench/bench_survey.h"
#include "reconstruction/road_lines.h"

namespace zebrageo {
namespace {

// The shared bench survey with a stop line before its crossing, and the
// line extractor on its road plane.
struct Fixture {
  BenchSurvey survey{"road-lines-bench", [](SimulationOptions* options) {
                       options->stop_line_probability = 1.0;
                     }};
  std::unique_ptr<StereoLineExtractor> extractor;
  const std::vector<std::pair<cv::Mat, cv::Mat>>& images = survey.images;

  Fixture() {
    const Rig& rig = survey.survey->rig;
    extractor = std::make_unique<StereoLineExtractor>(
        rig.cameras[rig.stereo_pairs[0][0]],
        rig.cameras[rig.stereo_pairs[0][1]], survey.road, RoadLineOptions());
  }
};

// Destroyed at exit, which removes the simulated survey.
Fixture& TheFixture() {
  static Fixture fixture;
  return fixture;
}

// One stereo pair, all steps, one thread (CPU time of the thread).
void BM_RoadLinesStereoPair(benchmark::State& state) {
  Fixture& f = TheFixture();
  double seconds = 0.0;
  int64_t pairs = 0, lines = 0;
  size_t next = 0;
  for (auto _ : state) {
    const auto& [left, right] = f.images[next++ % f.images.size()];
    const PairLines result = f.extractor->Extract(left, right);
    seconds += result.seconds;
    lines += static_cast<int64_t>(result.lines.size());
    ++pairs;
  }
  const double n = static_cast<double>(pairs);
  state.counters["ms_per_image"] = 1e3 * seconds / n / 2.0;
  state.counters["lines_per_pair"] = lines / n;
  state.counters["image_width"] = f.images[0].first.cols;
}
BENCHMARK(BM_RoadLinesStereoPair)->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace
}  // namespace zebrageo

BENCHMARK_MAIN();
