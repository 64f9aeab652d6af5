// Reconstruction (issue 5): time per stereo pair and per step on one core,
// 1280 x 960 images of a simulated street with a zebra crossing, parked
// vehicles and facades. Target: <= 200 ms per stereo pair.
//
// The survey is simulated once into a temporary folder (or taken from
// $ZEBRAGEO_BENCH_SURVEY); its images are decoded before timing (image
// reading is reported separately by `zebrageo reconstruct`).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "reconstruction/reconstruction.h"
#include "survey/image_io.h"
#include "survey/survey.h"
#include "tools/simulator/simulator.h"

namespace zebrageo {
namespace {

struct Fixture {
  std::string folder;
  bool owns_folder = false;
  std::unique_ptr<Survey> survey;
  std::unique_ptr<StereoPairReconstructor> pair;
  RoadPlane road;
  std::vector<std::pair<cv::Mat, cv::Mat>> images;

  Fixture() {
    const char* given = std::getenv("ZEBRAGEO_BENCH_SURVEY");
    if (given != nullptr) {
      folder = given;
    } else {
      folder = (std::filesystem::temp_directory_path() /
                ("zebrageo-reconstruction-bench-" + std::to_string(::getpid())))
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
      SimulateSurvey(options, folder, nullptr);
    }
    SurveyLoadOptions load;
    load.load_roadmarks = false;
    survey = std::make_unique<Survey>(LoadSurvey(folder, load));
    // The road plane as the survey run estimates it.
    ReconstructionOptions options;
    options.threads = 1;
    Survey first = *survey;
    first.exposures.exposures.resize(
        std::min<size_t>(8, first.exposures.exposures.size()));
    std::vector<ReconstructedVertex> unused;
    road = ReconstructSurvey(first, options, &unused).final_road_plane;
    const Rig& rig = survey->rig;
    pair = std::make_unique<StereoPairReconstructor>(
        rig.cameras[rig.stereo_pairs[0][0]],
        rig.cameras[rig.stereo_pairs[0][1]], road, options);
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
  const Rig& rig = f.survey->rig;
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
