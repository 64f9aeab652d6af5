// The adjust stage's files (pipeline/adjust_stage.h) on a synthetic survey:
// every contract output written once, readable by the survey's readers.
#include "pipeline/adjust_stage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "geodata/colmap_export.h"
#include "pipeline/adjustment_pass.h"
#include "survey/input_error.h"
#include "survey/results.h"
#include "tests/support/synthetic_survey.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

SyntheticSurveyOptions KilometreOptions() {
  SyntheticSurveyOptions options;
  options.num_exposures = 120;
  options.database_offset_m = 0.03;
  return options;
}

TEST(AdjustStage, WritesEveryContractOutputReadableByTheSurveyReaders) {
  const SyntheticSurvey survey = MakeSyntheticSurvey(KilometreOptions());
  TemporaryFolder folder;
  WriteSyntheticSurvey(survey, folder.Path("survey"), folder.Path("results"));
  SurveyLoadOptions load_options;
  load_options.require_images = false;
  const Survey loaded = LoadSurvey(folder.Path("survey"), load_options);
  StageResults results(folder.Path("results"));
  RunOptions options;
  options.tie_points = false;  // no images
  options.rematch = false;
  RunAdjustStage(loaded, &results, options);
  const auto poses =
      ReadCameraPoses(folder.Path("results/poses.csv"), "poses.csv");
  EXPECT_EQ(poses.size(), survey.exposures.images.size());
  const auto samples = ReadTrajectorySamples(
      folder.Path("results/trajectory_corrected.csv"), "trajectory_corrected");
  ASSERT_EQ(samples.size(), survey.measured_samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    ASSERT_EQ(samples[i].time, survey.measured_samples[i].time);
  }
  const auto gcps = ReadGcpResiduals(folder.Path("results/gcp_residuals.csv"),
                                     "gcp_residuals.csv");
  EXPECT_FALSE(gcps.empty());
  EXPECT_FALSE(
      ReadAdjustedBands(folder.Path("results/bands.geojson"), "bands.geojson")
          .empty());
  for (const char* name : {"adjustment.json", "colmap/cameras.txt",
                           "colmap/images.txt", "colmap/points3D.txt"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(
        folder.Path(std::string("results/") + name)))
        << name;
  }
  // The COLMAP model: each point's ERROR is its track's mean reprojection
  // error (it was written as 0), images.txt names the local frame's
  // origin.
  const ColmapModel colmap = ReadColmapModel(folder.Path("results/colmap"));
  std::vector<double> errors;
  for (const ColmapPoint3D& point : colmap.points) {
    if (point.track.empty()) continue;
    EXPECT_TRUE(std::isfinite(point.error));
    errors.push_back(point.error);
  }
  ASSERT_FALSE(errors.empty());
  std::sort(errors.begin(), errors.end());
  const double median_px = errors[errors.size() / 2];
  EXPECT_GT(median_px, 0.01);
  EXPECT_LT(median_px, 2.0);
  std::ifstream images(folder.Path("results/colmap/images.txt"));
  const std::string images_text((std::istreambuf_iterator<char>(images)),
                                std::istreambuf_iterator<char>());
  char origin[64];
  std::snprintf(origin, sizeof(origin), "latitude %.9f",
                loaded.frame.origin().lat_deg);
  EXPECT_NE(images_text.find(origin), std::string::npos)
      << images_text.substr(0, 400);
  // report.json is the report stage's.
  EXPECT_FALSE(std::filesystem::exists(folder.Path("results/report.json")));
}

// An exposure the reconstruction skipped because its right image is
// missing: only that image lacks a pose (SURVEY_FORMAT.md), its left
// camera keeps its own (issue 47: both were dropped).
TEST(AdjustStage, ExposureWithoutItsRightImageKeepsItsLeftPose) {
  const SyntheticSurvey survey = MakeSyntheticSurvey(KilometreOptions());
  TemporaryFolder folder;
  WriteSyntheticSurvey(survey, folder.Path("survey"), folder.Path("results"));
  SurveyLoadOptions load_options;
  load_options.require_images = false;
  const Survey loaded = LoadSurvey(folder.Path("survey"), load_options);
  const Exposure& exposure = loaded.exposures.exposures.at(10);
  const std::array<int, 2> pair = loaded.rig.stereo_pairs.at(0);
  const ExposureImage& left =
      loaded.exposures.images.at(exposure.image_of_camera[pair[0]]);
  const ExposureImage& right =
      loaded.exposures.images.at(exposure.image_of_camera[pair[1]]);
  // The left image is there and readable; the right one is not.
  const std::filesystem::path left_path =
      std::filesystem::path(folder.Path("survey")) / left.image;
  std::filesystem::create_directories(left_path.parent_path());
  ASSERT_TRUE(
      cv::imwrite(left_path.string(), cv::Mat(8, 8, CV_8UC1, cv::Scalar(0))));
  WriteSkippedExposures(
      {{exposure.exposure_id,
        "exposure " + std::to_string(exposure.exposure_id) + ": " +
            right.image + ": image file does not exist: exposure skipped"}},
      folder.Path("results/skipped_exposures.csv"));
  StageResults results(folder.Path("results"));
  RunOptions options;
  options.tie_points = false;
  options.rematch = false;
  RunAdjustStage(loaded, &results, options);
  std::set<std::string> cameras;
  size_t rows = 0;
  for (const CameraPose& pose :
       ReadCameraPoses(folder.Path("results/poses.csv"), "poses.csv")) {
    ++rows;
    if (pose.exposure_id == exposure.exposure_id) cameras.insert(pose.camera);
  }
  EXPECT_EQ(cameras,
            (std::set<std::string>{loaded.rig.cameras[pair[0]].camera.name()}));
  EXPECT_EQ(rows, loaded.exposures.images.size() - 1);
}

TEST(AdjustStage, MissingStageOutputsNameTheStageToRun) {
  const SyntheticSurvey survey = MakeSyntheticSurvey(KilometreOptions());
  TemporaryFolder folder;
  WriteSyntheticSurvey(survey, folder.Path("survey"), folder.Path("results"));
  std::filesystem::remove(folder.Path("results/matches.csv"));
  try {
    LoadAdjustmentData(folder.Path("survey"), folder.Path("results"));
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("zebrageo match"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace zebrageo
