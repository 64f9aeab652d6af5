// Road lines (issue 9): extraction time per image on one core, 1280 x 960
// simulated images of a street with lane lines, a stop line and a zebra
// crossing. Target: <= 50 ms per image (a stereo pair is two images: the
// counter ms_per_image is the pair's time halved).
//
// The survey is simulated once into a temporary folder (or taken from
// $ZEBRAGEO_BENCH_SURVEY); its images are decoded before timing.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "reconstruction/reconstruction.h"
#include "reconstruction/road_lines.h"
#include "survey/image_io.h"
#include "survey/survey.h"
#include "tools/simulator/simulator.h"

namespace zebrageo {
namespace {

struct Fixture {
  std::string folder;
  bool owns_folder = false;
  std::unique_ptr<Survey> survey;
  std::unique_ptr<StereoLineExtractor> extractor;
  std::vector<std::pair<cv::Mat, cv::Mat>> images;

  Fixture() {
    const char* given = std::getenv("ZEBRAGEO_BENCH_SURVEY");
    if (given != nullptr) {
      folder = given;
    } else {
      folder = (std::filesystem::temp_directory_path() /
                ("zebrageo-road-lines-bench-" + std::to_string(::getpid())))
                   .string();
      owns_folder = true;
      SimulationOptions options;
      ApplyPreset("urban", &options);
      options.seed = 3;
      options.road_length_m = 60.0;
      options.num_crossings = 1;
      options.num_stale_crossings = 0;
      options.num_missing_crossings = 0;
      options.num_missing_bands = 0;
      options.num_repainted_crossings = 0;
      options.min_crossing_spacing_m = 25.0;
      options.stop_line_probability = 1.0;
      SimulateSurvey(options, folder, nullptr);
    }
    SurveyLoadOptions load;
    load.load_roadmarks = false;
    survey = std::make_unique<Survey>(LoadSurvey(folder, load));
    // The road plane as the zebra stage estimates it.
    ReconstructionOptions options;
    options.threads = 1;
    Survey first = *survey;
    first.exposures.exposures.resize(
        std::min<size_t>(8, first.exposures.exposures.size()));
    std::vector<ReconstructedVertex> unused;
    const RoadPlane road =
        ReconstructSurvey(first, options, &unused).final_road_plane;
    const Rig& rig = survey->rig;
    extractor = std::make_unique<StereoLineExtractor>(
        rig.cameras[rig.stereo_pairs[0][0]],
        rig.cameras[rig.stereo_pairs[0][1]], road, RoadLineOptions());
    for (const Exposure& e : survey->exposures.exposures) {
      cv::Mat sides[2];
      for (int s = 0; s < 2; ++s) {
        const ExposureImage& image =
            survey->exposures.images[e.image_of_camera[rig.stereo_pairs[0][s]]];
        sides[s] = ReadGrayImage(survey->PathOf(image.image), image.image);
      }
      images.emplace_back(sides[0], sides[1]);
    }
  }
  ~Fixture() {
    if (owns_folder) {
      std::error_code ignored;
      std::filesystem::remove_all(folder, ignored);
    }
  }
};

Fixture& TheFixture() {
  static Fixture* fixture = new Fixture();
  return *fixture;
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
