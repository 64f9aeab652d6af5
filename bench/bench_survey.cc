#include "bench/bench_survey.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "reconstruction/reconstruction.h"
#include "survey/image_io.h"

namespace zebrageo {

BenchSurvey::BenchSurvey(
    const std::string& name,
    const std::function<void(SimulationOptions*)>& customise) {
  const char* given = std::getenv("ZEBRAGEO_BENCH_SURVEY");
  if (given != nullptr) {
    folder = given;
  } else {
    folder = (std::filesystem::temp_directory_path() /
              ("zebrageo-" + name + "-" + std::to_string(::getpid())))
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
    if (customise) customise(&options);
    SimulateSurvey(options, folder, nullptr);
  }
  SurveyLoadOptions load;
  load.load_roadmarks = false;
  survey = std::make_unique<Survey>(LoadSurvey(folder, load));
  ReconstructionOptions options;
  options.threads = 1;
  Survey first = *survey;
  first.exposures.exposures.resize(
      std::min<size_t>(8, first.exposures.exposures.size()));
  std::vector<ReconstructedVertex> unused;
  road = ReconstructSurvey(first, options, &unused).final_road_plane;
  const Rig& rig = survey->rig;
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

BenchSurvey::~BenchSurvey() {
  if (owns_folder) {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  }
}

}  // namespace zebrageo
