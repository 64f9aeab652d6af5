#include "registration/match_stage.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "survey/input_error.h"
#include "survey/survey.h"
#include "tests/registration/synthetic_scene.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::random_device device;
    path_ = fs::temp_directory_path() /
            ("zebrageo-match-" + std::to_string(device()));
    fs::create_directories(path_);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string Path(const std::string& name) const {
    return (path_ / name).string();
  }

 private:
  fs::path path_;
};

// Writes `scene` as a survey folder (the measured trajectory, empty image
// files) and its observations as reconstructed_bands.csv in `results`.
void WriteSceneSurvey(const SyntheticScene& scene, const std::string& survey,
                      const std::string& results) {
  fs::create_directories(survey + "/images");
  fs::create_directories(results);
  WriteRig(scene.rig, survey + "/rig.yaml");
  std::vector<TrajectorySample> samples;
  ExposureTable table;
  for (const ExposurePose& e : scene.exposures) {
    samples.push_back(SampleFromPose(e.time_s, e.pose, scene.frame,
                                     Eigen::Vector3d::Constant(0.05),
                                     Eigen::Vector3d::Constant(0.001)));
    for (int camera = 0; camera < 2; ++camera) {
      ExposureImage image;
      image.exposure_id = e.exposure_id;
      image.time = e.time_s;
      image.camera = camera;
      image.image = "images/" + std::to_string(e.exposure_id) + "_" +
                    std::to_string(camera) + ".png";
      std::ofstream(survey + "/" + image.image) << "";
      table.images.push_back(image);
    }
  }
  WriteTrajectorySamples(samples, survey + "/trajectory.csv");
  WriteExposures(table, scene.rig, survey + "/exposures.csv");
  WriteRoadmarks(scene.database, survey + "/roadmarks.geojson");
  SurveyManifest manifest;
  manifest.name = "synthetic";
  manifest.origin = scene.frame.origin();
  WriteManifest(manifest, survey + "/survey.yaml");
  std::vector<ReconstructedVertex> vertices;
  for (const CrossingObservation& obs : scene.observations) {
    for (const ObservedBand& band : obs.bands) {
      for (int k = 0; k < 4; ++k) {
        ReconstructedVertex v;
        v.exposure_id = obs.exposure_id;
        v.pair = band.pair;
        v.band_id = band.band_id;
        v.group_id = obs.group_id;
        v.vertex = band.vertex[k];
        v.p_body = band.p_body[k];
        v.covariance_body = Eigen::Matrix3d::Identity() * 2e-4;
        v.score = 0.9;
        vertices.push_back(v);
      }
    }
  }
  WriteReconstructedBands(vertices, {"synthetic"},
                          results + "/" + kReconstructedBandsFile);
}

TEST(MatchStage, WritesMatchesDecisionsEvidenceAndGeoJsonThatReadBack) {
  SyntheticSceneOptions options;
  options.seed = 21;
  options.crossings = RandomCrossings(3, 45.0, 21);
  const SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  const MatchResult result =
      RunMatchStage(survey, folder.Path("results"), MatchOptions());
  ASSERT_TRUE(result.summary.IsUsable());
  EXPECT_GT(result.summary.matched, 0);

  const std::vector<VertexMatch> matches =
      ReadMatches(folder.Path("results/matches.csv"), "matches.csv");
  EXPECT_EQ(matches.size(), result.matches.size());
  EXPECT_EQ(ScoreMatches(scene, matches).wrong, 0);
  const std::vector<CrossingDecision> decisions = ReadCrossingDecisions(
      folder.Path("results/crossing_decisions.csv"), "crossing_decisions.csv");
  EXPECT_EQ(decisions.size(), scene.observations.size());
  for (const CrossingDecision& d : decisions) {
    EXPECT_EQ(d.crossing_id.empty(), d.decision != Decision::kMatched);
    EXPECT_FALSE(d.reason.empty());
  }

  std::ifstream evidence_file(folder.Path("results/match_evidence.json"));
  const nlohmann::json evidence = nlohmann::json::parse(evidence_file);
  EXPECT_EQ(evidence["observations"].size(), scene.observations.size());
  EXPECT_EQ(evidence["summary"]["matched"].get<int>(), result.summary.matched);
  std::ifstream geojson_file(folder.Path("results/matches.geojson"));
  const nlohmann::json geojson = nlohmann::json::parse(geojson_file);
  EXPECT_EQ(geojson["type"], "FeatureCollection");
  EXPECT_GE(geojson["features"].size(), matches.size());
  // No temporary file is left behind.
  for (const auto& entry : fs::directory_iterator(folder.Path("results"))) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"),
              std::string::npos);
  }
}

TEST(MatchStage, FailsClearlyWithoutReconstructedBands) {
  SyntheticSceneOptions options;
  options.crossings = RandomCrossings(1, 45.0, 1);
  const SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  fs::remove(folder.Path("results/reconstructed_bands.csv"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  try {
    RunMatchStage(survey, folder.Path("results"), MatchOptions());
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("reconstructed_bands.csv"),
              std::string::npos);
  }
  EXPECT_FALSE(fs::exists(folder.Path("results/matches.csv")));
}

TEST(MatchStage, RejectsBandsOfAnExposureTheSurveyDoesNotHave) {
  SyntheticSceneOptions options;
  options.crossings = RandomCrossings(1, 45.0, 2);
  SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  ReconstructedVertex stray;
  stray.exposure_id = 999999;
  stray.band_id = 1;
  try {
    BuildObservations(survey, {stray}, "reconstructed_bands.csv", nullptr);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("exposure_id 999999"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace zebrageo
