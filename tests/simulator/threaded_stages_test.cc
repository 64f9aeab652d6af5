// The threaded stages on a tiny survey, for ThreadSanitizer (scripts/test.sh
// runs this suite in build-tsan): the simulator's render workers, and the
// reconstruction's ParallelFor over exposures. Each must give the same bytes
// (images) and the same vertices with one thread and with two.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "reconstruction/reconstruction.h"
#include "simulator/simulator.h"
#include "survey/survey.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// 40 m of road, one crossing, small images: a few seconds under TSan.
SimulationOptions TinySurvey(int threads) {
  SimulationOptions options;
  EXPECT_EQ(ApplyPreset("demo", &options), "");
  options.seed = 5;
  options.road_length_m = 40.0;
  options.num_crossings = 1;
  options.num_stale_crossings = 0;
  options.min_crossing_spacing_m = 15.0;
  options.exposure_spacing_m = 4.0;
  options.image_width = 480;
  options.image_height = 360;
  options.focal_px = 420.0;
  options.supersampling = 1;
  options.parked_vehicles_per_100m = 0.0;
  options.threads = threads;
  EXPECT_EQ(options.Check(), "");
  return options;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(ThreadedStages, RenderWorkersAndReconstructionMatchOneThread) {
  TemporaryFolder folder;
  const SimulationSummary two =
      SimulateSurvey(TinySurvey(2), folder.Path("two"), nullptr);
  SimulateSurvey(TinySurvey(1), folder.Path("one"), nullptr);
  ASSERT_GE(two.num_images_rendered, 8);
  int images = 0;
  for (const auto& entry :
       fs::directory_iterator(fs::path(folder.Path("two")) / "images")) {
    const fs::path other =
        fs::path(folder.Path("one")) / "images" / entry.path().filename();
    EXPECT_EQ(ReadFile(entry.path()), ReadFile(other))
        << entry.path().filename();
    ++images;
  }
  EXPECT_EQ(images, two.num_images_rendered);

  SurveyLoadOptions load;
  load.load_roadmarks = false;
  const Survey survey = LoadSurvey(folder.Path("two"), load);
  ReconstructionOptions options;
  std::vector<ReconstructedVertex> one_thread, two_threads;
  options.threads = 1;
  const ReconstructionSummary first =
      ReconstructSurvey(survey, options, &one_thread);
  options.threads = 2;
  int calls = 0;
  const ReconstructionSummary second = ReconstructSurvey(
      survey, options, &two_threads, [&](int done, int total) {
        ++calls;  // called under the stage's lock
        EXPECT_LE(done, total);
      });
  ASSERT_TRUE(first.IsUsable()) << first.message;
  ASSERT_TRUE(second.IsUsable()) << second.message;
  EXPECT_EQ(calls, second.exposures);
  EXPECT_GT(two_threads.size(), 0u) << "no band reconstructed";
  ASSERT_EQ(one_thread.size(), two_threads.size());
  for (size_t k = 0; k < one_thread.size(); ++k) {
    EXPECT_EQ(one_thread[k].band_id, two_threads[k].band_id);
    EXPECT_EQ(one_thread[k].p_body, two_threads[k].p_body);
  }
}

}  // namespace
}  // namespace zebrageo
