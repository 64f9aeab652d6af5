// SimulateSurvey end to end on a small survey: the painted band edges land
// where the true corners project (sub-pixel), the files read back with the
// survey library, the output is deterministic, and the independent checker
// agrees.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "simulator/simulator.h"
#include "survey/exposures.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/survey.h"
#include "survey/trajectory.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// A small, fast survey: 640 x 480 images, ~12 exposures, 2 crossings.
SimulationOptions SmallSurvey(uint64_t seed) {
  SimulationOptions options;
  options.preset = "test";
  options.seed = seed;
  options.road_length_m = 55.0;
  options.num_crossings = 1;
  options.num_stale_crossings = 1;
  options.min_crossing_spacing_m = 15.0;
  options.max_band_length_m = 4.0;
  options.exposure_spacing_m = 3.5;
  options.image_width = 640;
  options.image_height = 480;
  options.focal_px = 560.0;
  options.skew_probability = 1.0;
  options.occluding_vehicle_probability = 0.0;
  options.threads = 2;
  return options;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Bilinear sample of a grey image (pixel centres at integers).
double Sample(const cv::Mat& image, double u, double v) {
  const int x = static_cast<int>(std::floor(u));
  const int y = static_cast<int>(std::floor(v));
  const double fx = u - x, fy = v - y;
  auto at = [&](int xx, int yy) {
    return static_cast<double>(image.at<uint8_t>(yy, xx));
  };
  return (1 - fy) * ((1 - fx) * at(x, y) + fx * at(x + 1, y)) +
         fy * ((1 - fx) * at(x, y + 1) + fx * at(x + 1, y + 1));
}

// Offsets (px) of the painted edge from the projected long sides of the
// true bands, measured across each side (the method of check_survey.py), in
// the images of the cameras whose name starts with `camera_prefix`, for
// the bands whose centre is min_range_m to 15 m from the camera.
std::vector<double> EdgeOffsets(const std::string& folder,
                                const std::string& camera_prefix = "",
                                double min_range_m = 0.0) {
  const Rig rig = ReadRig(folder + "/rig.yaml", "rig.yaml");
  const SurveyManifest manifest = ReadManifest(folder);
  const LocalFrame frame(*manifest.origin);
  const Trajectory truth(
      ReadTrajectorySamples(folder + "/truth/trajectory.csv", "truth"), frame);
  const RoadmarkDatabase bands =
      ReadRoadmarks(folder + "/truth/roadmarks.geojson", "truth");
  const ExposureTable table =
      ReadExposures(folder + "/exposures.csv", "exposures.csv", rig);
  std::vector<double> offsets;
  for (const ExposureImage& item : table.images) {
    Pose pose;
    if (!truth.InterpolatePose(item.time, &pose)) continue;
    const RigCamera& rc = rig.cameras[item.camera];
    if (rc.camera.name().rfind(camera_prefix, 0) != 0) continue;
    const Eigen::Isometry3d T_cam_enu =
        (pose.T_enu_body() * rc.T_body_cam).inverse();
    const cv::Mat image =
        cv::imread(folder + "/" + item.image, cv::IMREAD_GRAYSCALE);
    if (image.empty()) continue;
    for (const RoadmarkBand& band : bands.bands) {
      std::array<Eigen::Vector3d, 4> c;
      for (int k = 0; k < 4; ++k) c[k] = frame.EnuFromGeodetic(band.corners[k]);
      const Eigen::Vector3d centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
      const double range = (T_cam_enu * centre).norm();
      if (range > 15.0 || range < min_range_m) continue;
      for (int side = 0; side < 4; ++side) {
        const Eigen::Vector3d& a = c[side];
        const Eigen::Vector3d& b = c[(side + 1) % 4];
        if ((b - a).norm() < 1.5) continue;  // a short side
        for (double f : {0.25, 0.375, 0.5, 0.625, 0.75}) {
          const Eigen::Vector3d p = a + f * (b - a);
          const Eigen::Vector3d inward = (centre - p).normalized();
          Eigen::Vector2d uv, uv_along, uv_in;
          if (!rc.camera.Project(T_cam_enu * p, &uv) ||
              !rc.camera.Project(T_cam_enu * (p + 0.02 * (b - a).normalized()),
                                 &uv_along) ||
              !rc.camera.Project(T_cam_enu * (p + 0.2 * inward), &uv_in) ||
              !rc.camera.IsInImage(uv, 12.0)) {
            continue;
          }
          const Eigen::Vector2d t = (uv_along - uv).normalized();
          Eigen::Vector2d n(-t.y(), t.x());
          if (n.dot(uv_in - uv) < 0) n = -n;  // into the band
          const double h = std::min(5.0, 0.45 * (uv_in - uv).norm() * 2.5);
          if (h < 2.5) continue;
          std::vector<double> s, profile;
          for (double x = -h; x <= h + 1e-9; x += 0.125) {
            s.push_back(x);
            const Eigen::Vector2d q = uv + x * n;
            profile.push_back(Sample(image, q.x(), q.y()));
          }
          const size_t k = std::max<size_t>(2, s.size() / 5);
          double lo = 0, hi = 0;
          for (size_t i = 0; i < k; ++i) {
            lo += profile[i] / k;
            hi += profile[profile.size() - 1 - i] / k;
          }
          if (hi - lo < 20) continue;
          const double mid = 0.5 * (lo + hi);
          for (size_t i = 1; i < s.size(); ++i) {
            if (profile[i] >= mid) {
              offsets.push_back(s[i - 1] + (mid - profile[i - 1]) /
                                               (profile[i] - profile[i - 1]) *
                                               (s[i] - s[i - 1]));
              break;
            }
          }
        }
      }
    }
  }
  return offsets;
}

// One small survey checked several ways (generated once: under ctest every
// test runs in its own process).
TEST(SimulateSurvey, SmallSurveyMatchesItsTruthAndTheContract) {
  TemporaryFolder temporary;
  const std::string folder = temporary.Path("survey");
  const SimulationSummary summary =
      SimulateSurvey(SmallSurvey(3), folder, nullptr);

  // 1. Painted band edges land where the true corners project.
  const std::vector<double> offsets = EdgeOffsets(folder);
  ASSERT_GT(offsets.size(), 100u);
  std::vector<double> sorted = offsets;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double within =
      std::count_if(offsets.begin(), offsets.end(),
                    [](double o) { return std::abs(o) < 0.5; }) /
      static_cast<double>(offsets.size());
  EXPECT_LT(std::abs(median), 0.5);
  EXPECT_LT(std::abs(median), 0.15) << "sub-pixel exact edges expected";
  EXPECT_GT(within, 0.8) << offsets.size() << " samples, median " << median;

  // 2. The survey library loads it without warnings.
  const Survey survey = LoadSurvey(folder);
  EXPECT_EQ(survey.rig.cameras.size(), 2u);
  EXPECT_EQ(static_cast<int>(survey.exposures.images.size()),
            summary.num_images);
  EXPECT_EQ(summary.num_images, 2 * summary.num_exposures);
  EXPECT_EQ(summary.num_images_rendered, summary.num_images);
  EXPECT_TRUE(survey.warnings.empty());
  for (const ExposureImage& image : survey.exposures.images) {
    EXPECT_GE(image.exposure_id, 1000);
    const cv::Mat png =
        cv::imread(folder + "/" + image.image, cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(png.empty());
    EXPECT_EQ(png.cols, 640);
    EXPECT_EQ(png.rows, 480);
    EXPECT_EQ(png.type(), CV_8UC1);
  }

  // 3. truth/meta.json records the crossings and their faults.
  std::ifstream meta_file(folder + "/truth/meta.json");
  const nlohmann::json meta = nlohmann::json::parse(meta_file);
  EXPECT_EQ(meta["expect"], "ok");
  EXPECT_EQ(meta["seed"], 3);
  ASSERT_EQ(meta["crossings"].size(), 2u);
  int stale = 0;
  for (const auto& c : meta["crossings"]) {
    EXPECT_TRUE(c.contains("crossing_id"));
    EXPECT_TRUE(c.contains("db_offset_m"));
    EXPECT_TRUE(c.contains("num_bands"));
    EXPECT_TRUE(c.contains("skew_deg"));
    EXPECT_TRUE(c.contains("repainted"));
    stale += c["in_db"].get<bool>() && !c["in_street"].get<bool>();
  }
  EXPECT_EQ(stale, 1);
  EXPECT_EQ(meta["options"]["road_length_m"], 55.0);

  // 4. The independent checker (shares no code with us) agrees.
  const std::string python = "/usr/bin/python3";
  const std::string checker =
      std::string(ZEBRAGEO_SHARED_DIR) + "/tools/check_survey.py";
  if (fs::exists(python) && fs::exists(checker)) {
    const std::string log = temporary.Path("check.log");
    const std::string command =
        python + " " + checker + " " + folder + " > " + log + " 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << ReadFile(log);
  }
}

// A second stereo pair looking backwards: four cameras, two pairs in
// rig.yaml, and the rear images show the road already driven with its
// bands where the true corners project (the renderer draws the road in the
// direction each camera looks).
TEST(SimulateSurvey, RearPairSeesTheBandsBehindTheVehicle) {
  TemporaryFolder temporary;
  const std::string folder = temporary.Path("survey");
  SimulationOptions options = SmallSurvey(3);
  options.rear_pair = true;
  const SimulationSummary summary = SimulateSurvey(options, folder, nullptr);
  EXPECT_EQ(summary.num_images, 4 * summary.num_exposures);

  const Rig rig = ReadRig(folder + "/rig.yaml", "rig.yaml");
  ASSERT_EQ(rig.cameras.size(), 4u);
  ASSERT_EQ(rig.stereo_pairs.size(), 2u);
  EXPECT_EQ(rig.cameras[rig.stereo_pairs[1][0]].camera.name(), "rear_left");
  EXPECT_EQ(rig.cameras[rig.stereo_pairs[1][1]].camera.name(), "rear_right");
  for (int c : rig.stereo_pairs[1]) {
    const Eigen::Isometry3d& T = rig.cameras[c].T_body_cam;
    EXPECT_LT(T.linear().col(2).x(), -0.9);  // looks backwards
    EXPECT_NEAR(T.translation().x(), -options.rear_camera_back_m, 0.02);
  }
  // Seen from behind, the pair's left camera is on the body's right (+y).
  EXPECT_NEAR(
      rig.cameras[rig.stereo_pairs[1][0]].T_body_cam.translation().y() -
          rig.cameras[rig.stereo_pairs[1][1]].T_body_cam.translation().y(),
      options.stereo_baseline_m, 0.02);

  // Bands 12 m behind the camera and farther: beyond the stretch behind the
  // vehicle that a forward-looking camera's road covers.
  const std::vector<double> offsets = EdgeOffsets(folder, "rear_", 12.0);
  ASSERT_GT(offsets.size(), 20u) << "bands behind the vehicle not drawn";
  std::vector<double> sorted = offsets;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_LT(std::abs(sorted[sorted.size() / 2]), 0.15);
}

TEST(SimulateSurvey, SameSeedGivesIdenticalFilesAndAnotherSeedDiffers) {
  TemporaryFolder temporary;
  SimulationOptions options = SmallSurvey(3);
  options.image_width = 320;
  options.image_height = 240;
  options.focal_px = 280.0;
  SimulateSurvey(options, temporary.Path("a"), nullptr);
  options.threads = 1;  // the thread count must not matter
  SimulateSurvey(options, temporary.Path("b"), nullptr);
  options.seed = 4;
  options.render_images = false;
  SimulateSurvey(options, temporary.Path("c"), nullptr);
  const fs::path a = temporary.Path("a"), b = temporary.Path("b"),
                 c = temporary.Path("c");
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), a);
    if (relative == "truth/meta.json") continue;  // holds the thread count
    EXPECT_EQ(ReadFile(entry.path()), ReadFile(b / relative)) << relative;
    ++compared;
  }
  EXPECT_GT(compared, 20);
  EXPECT_NE(ReadFile(a / "trajectory.csv"), ReadFile(c / "trajectory.csv"));
  EXPECT_NE(ReadFile(a / "roadmarks.geojson"),
            ReadFile(c / "roadmarks.geojson"));
}

TEST(SimulateSurvey, GeometryOnlyWritesExposuresButNoImages) {
  TemporaryFolder folder;
  SimulationOptions options = SmallSurvey(9);
  options.render_images = false;
  const SimulationSummary summary =
      SimulateSurvey(options, folder.Path(), nullptr);
  EXPECT_EQ(summary.num_images_rendered, 0);
  EXPECT_GT(summary.num_images, 0);
  EXPECT_FALSE(fs::exists(folder.Path("images")));
  EXPECT_TRUE(fs::exists(folder.Path("exposures.csv")));
  EXPECT_TRUE(fs::exists(folder.Path("survey.yaml")));
}

TEST(SimulateSurvey, InvalidOptionsThrowBeforeWritingAnything) {
  TemporaryFolder folder;
  SimulationOptions options = SmallSurvey(1);
  options.road_width_m = 2.0;
  EXPECT_THROW(SimulateSurvey(options, folder.Path("out"), nullptr),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(folder.Path("out")));
}

}  // namespace
}  // namespace zebrageo
