#include "survey/survey.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "survey/input_error.h"
#include "survey/yaml_document.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

const char kManifest[] =
    "name: test-survey\n"
    "rig: rig.yaml\n"
    "trajectory: trajectory.csv\n"
    "exposures: exposures.csv\n"
    "roadmarks: roadmarks.geojson\n";

const char kRig[] =
    "cameras:\n"
    "  - name: left\n"
    "    width: 64\n"
    "    height: 48\n"
    "    K: [50, 0, 31.5, 0, 50, 23.5, 0, 0, 1]\n"
    "    D: [0, 0, 0, 0, 0]\n"
    "    T_body_cam: [0, 0, 1, 1.5,  1, 0, 0, -0.3,  0, 1, 0, -1.2,  0, 0, "
    "0, 1]\n"
    "  - name: right\n"
    "    width: 64\n"
    "    height: 48\n"
    "    K: [50, 0, 31.5, 0, 50, 23.5, 0, 0, 1]\n"
    "    D: [0, 0, 0, 0, 0]\n"
    "    T_body_cam: [0, 0, 1, 1.5,  1, 0, 0, 0.3,  0, 1, 0, -1.2,  0, 0, "
    "0, 1]\n"
    "stereo_pairs:\n"
    "  - [left, right]\n";

// 10 Hz (the contract's lowest rate) from 100.0 to 101.0 s, heading east at
// 10 m/s.
const char kTrajectory[] =
    "# time span 100 .. 101 s\n"
    "time,lat,lon,h,roll,pitch,heading,sd_e,sd_n,sd_u,sd_roll,sd_pitch,"
    "sd_heading\n"
    "100.0,49.8941,2.2958,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.1,49.8941,2.295814,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.2,49.8941,2.295828,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.3,49.8941,2.295842,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.4,49.8941,2.295856,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.5,49.8941,2.29587,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.6,49.8941,2.295884,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.7,49.8941,2.295898,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.8,49.8941,2.295912,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "100.9,49.8941,2.295926,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n"
    "101.0,49.8941,2.29594,60,0,0,90,0.02,0.02,0.03,0.01,0.01,0.05\n";

// Ten stereo exposures between 100.1 and 101.0 s.
std::string Exposures(double first_time = 100.1) {
  std::string text = "exposure_id,time,camera,image\n";
  for (int i = 0; i < 10; ++i) {
    const std::string time = std::to_string(first_time + 0.1 * i);
    const std::string id = std::to_string(100 + i);
    text += id + "," + time + ",left,images/l" + id + ".png\n";
    text += id + "," + time + ",right,images/r" + id + ".png\n";
  }
  return text;
}

const char kRoadmarks[] =
    "{\"type\": \"FeatureCollection\", \"features\": [\n"
    "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
    "\"coordinates\": [[[2.2959, 49.8941, 60], [2.29591, 49.8941, 60], "
    "[2.29591, 49.89413, 60], [2.2959, 49.89413, 60], [2.2959, 49.8941, "
    "60]]]}, \"properties\": {\"crossing_id\": \"C1\", \"band\": 1, "
    "\"sigma_xy\": 0.05, \"sigma_z\": 0.1}}\n"
    "]}\n";

// A complete, valid survey in a temporary folder. Images only need to exist
// for LoadSurvey: they hold a few bytes.
class SurveyFolder {
 public:
  SurveyFolder() {
    folder_.Write("survey.yaml", kManifest);
    folder_.Write("rig.yaml", kRig);
    folder_.Write("trajectory.csv", kTrajectory);
    folder_.Write("exposures.csv", Exposures());
    folder_.Write("roadmarks.geojson", kRoadmarks);
    for (int i = 0; i < 10; ++i) {
      const std::string id = std::to_string(100 + i);
      folder_.Write("images/l" + id + ".png", "png");
      folder_.Write("images/r" + id + ".png", "png");
    }
  }
  const TemporaryFolder& folder() const { return folder_; }
  std::string path() const { return folder_.Path(); }

 private:
  TemporaryFolder folder_;
};

std::string ErrorOfLoad(const std::string& folder,
                        const SurveyLoadOptions& options = {}) {
  try {
    LoadSurvey(folder, options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

TEST(Survey, LoadsAValidSurvey) {
  const SurveyFolder survey_folder;
  const Survey survey = LoadSurvey(survey_folder.path());
  EXPECT_EQ(survey.manifest.name, "test-survey");
  EXPECT_EQ(survey.rig.cameras.size(), 2u);
  EXPECT_EQ(survey.trajectory.size(), 11);
  EXPECT_EQ(survey.exposures.images.size(), 20u);
  EXPECT_EQ(survey.exposures.exposures.size(), 10u);
  EXPECT_EQ(survey.roadmarks.bands.size(), 1u);
  EXPECT_TRUE(survey.warnings.empty());
  // Without `origin`, the ENU origin is the first trajectory sample.
  EXPECT_EQ(survey.frame.origin().lat_deg, 49.8941);
  EXPECT_EQ(survey.frame.origin().lon_deg, 2.2958);
  EXPECT_EQ(survey.frame.origin().h_m, 60.0);
  EXPECT_EQ(survey.PathOf("images/l100.png"),
            (std::filesystem::path(survey_folder.path()) / "images/l100.png")
                .string());
}

TEST(Survey, UsesTheManifestsOrigin) {
  const SurveyFolder survey_folder;
  survey_folder.folder().Write(
      "survey.yaml", std::string(kManifest) + "origin: [49.9, 2.3, 55.5]\n");
  const Survey survey = LoadSurvey(survey_folder.path());
  EXPECT_EQ(survey.frame.origin().lat_deg, 49.9);
  EXPECT_EQ(survey.frame.origin().lon_deg, 2.3);
  EXPECT_EQ(survey.frame.origin().h_m, 55.5);
}

TEST(Survey, SkipsRoadmarksWhenNotAskedFor) {
  const SurveyFolder survey_folder;
  survey_folder.folder().Write("roadmarks.geojson", "not json");
  SurveyLoadOptions options;
  options.load_roadmarks = false;
  EXPECT_TRUE(
      LoadSurvey(survey_folder.path(), options).roadmarks.bands.empty());
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("roadmarks.geojson:1: malformed JSON"));
}

TEST(Survey, RejectsAManifestNamingAMissingFile) {
  const SurveyFolder survey_folder;
  std::filesystem::remove(survey_folder.folder().Path("trajectory.csv"));
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:3: 'trajectory' names trajectory.csv, "
                        "which does not exist"));
}

TEST(Survey, RejectsBadManifests) {
  const SurveyFolder survey_folder;
  const TemporaryFolder& folder = survey_folder.folder();
  folder.Write("survey.yaml", "name: x\nrig: rig.yaml\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:1: missing key 'trajectory'"));
  folder.Write("survey.yaml", "name: [x\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:2: malformed YAML"));
  folder.Write("survey.yaml", std::string(kManifest) + "origin: [49.9, 2.3]\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:6: 'origin' must be [lat, lon, h]"));
  folder.Write("survey.yaml",
               std::string(kManifest) + "origin: [149.9, 2.3, .nan]\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:6: 'origin' must be 3 finite numbers"));
  folder.Write("survey.yaml",
               std::string(kManifest) + "origin: [149.9, 2.3, 50]\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:6: 'origin' latitude 149.9 is outside"));
  std::filesystem::remove(folder.Path("survey.yaml"));
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml: cannot open"));
}

TEST(Survey, RejectsExposuresOutsideTheTrajectorySpan) {
  const SurveyFolder survey_folder;
  survey_folder.folder().Write("exposures.csv", Exposures(100.2));
  // The last exposure, at 101.1 s, is on lines 20 and 21.
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("exposures.csv:20: exposure 109 at time 101.1 is "
                        "outside the trajectory's span [100, 101] of "
                        "trajectory.csv"));
}

TEST(Survey, ReportsAFewMissingImagesAsWarnings) {
  const SurveyFolder survey_folder;
  std::filesystem::remove(survey_folder.folder().Path("images/r103.png"));
  const Survey survey = LoadSurvey(survey_folder.path());
  ASSERT_EQ(survey.warnings.size(), 1u);
  EXPECT_THAT(survey.warnings[0],
              HasSubstr("exposures.csv:9: image images/r103.png does not "
                        "exist"));
}

TEST(Survey, RejectsASurveyWithTooManyMissingImages) {
  const SurveyFolder survey_folder;
  for (int i = 0; i < 5; ++i) {
    std::filesystem::remove(
        survey_folder.folder().Path("images/l10" + std::to_string(i) + ".png"));
  }
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("exposures.csv: 5 of 20 images are missing (more than "
                        "max_missing_image_fraction = 0.2); first: "
                        "exposures.csv:2: image images/l100.png does not "
                        "exist"));
  SurveyLoadOptions lenient;
  lenient.max_missing_image_fraction = 0.5;
  EXPECT_EQ(LoadSurvey(survey_folder.path(), lenient).warnings.size(), 5u);
}

TEST(Survey, RejectsAStereoPairWithoutAnyCompleteExposure) {
  const SurveyFolder survey_folder;
  std::string text = "exposure_id,time,camera,image\n";
  for (int i = 0; i < 10; ++i) {
    text += std::to_string(i) + ",100.5," + (i % 2 ? "left" : "right") +
            ",images/l10" + std::to_string(i) + ".png\n";
  }
  survey_folder.folder().Write("exposures.csv", text);
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("exposures.csv: stereo pair 0 (left, right): no "
                        "exposure has existing images of both cameras"));
}

TEST(Survey, RefusesFilesOutsideTheSurveyFolder) {
  const SurveyFolder survey_folder;
  const TemporaryFolder& folder = survey_folder.folder();
  // A valid image and a valid trajectory beside the survey: refused, unread.
  folder.Write("../" +
                   std::filesystem::path(folder.Path()).filename().string() +
                   "-outside.png",
               "png");
  const std::string outside =
      folder.Path() + "-outside.png";  // the sibling just written
  std::string exposures = Exposures();
  exposures.replace(exposures.find("images/l100.png"), 15,
                    "../" + std::filesystem::path(outside).filename().string());
  folder.Write("exposures.csv", exposures);
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              AllOf(HasSubstr("exposures.csv:2: image ../"),
                    HasSubstr(", outside the survey folder")));
  SurveyLoadOptions trusted;
  trusted.paths.allow_outside_paths = true;
  EXPECT_EQ(LoadSurvey(survey_folder.path(), trusted).warnings.size(), 0u);
  std::filesystem::remove(outside);

  folder.Write("exposures.csv", Exposures());
  folder.Write("survey.yaml",
               "name: x\nrig: /etc/passwd\ntrajectory: trajectory.csv\n"
               "exposures: exposures.csv\nroadmarks: roadmarks.geojson\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:2: 'rig' names /etc/passwd, which is an "
                        "absolute path"));
  folder.Write("survey.yaml",
               "name: x\nrig: rig.yaml\ntrajectory: ../../../../etc/shadow\n"
               "exposures: exposures.csv\nroadmarks: roadmarks.geojson\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:3: 'trajectory' names "
                        "../../../../etc/shadow, which resolves to "
                        "/etc/shadow, outside the survey folder"));
}

TEST(Survey, NamesAFolderOrALoopWhereAFileIsExpected) {
  const SurveyFolder survey_folder;
  const TemporaryFolder& folder = survey_folder.folder();
  folder.Write("survey.yaml",
               "name: x\nrig: rig.yaml\ntrajectory: images\n"
               "exposures: exposures.csv\nroadmarks: roadmarks.geojson\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:3: 'trajectory' names images, which is "
                        "a folder, not a file"));
  folder.Write("survey.yaml", kManifest);
  std::filesystem::remove(folder.Path("images/l101.png"));
  std::filesystem::create_directory(folder.Path("images/l101.png"));
  std::filesystem::remove(folder.Path("images/r101.png"));
  std::filesystem::create_symlink("r101.png", folder.Path("images/r101.png"));
  const Survey survey = LoadSurvey(survey_folder.path());
  ASSERT_EQ(survey.warnings.size(), 2u);
  EXPECT_EQ(survey.warnings[0],
            "exposures.csv:4: image images/l101.png is a folder, not a file");
  EXPECT_THAT(survey.warnings[1],
              HasSubstr("exposures.csv:5: image images/r101.png is a loop of "
                        "symbolic links"));
}

TEST(Survey, RefusesAKeyGivenTwice) {
  const SurveyFolder survey_folder;
  survey_folder.folder().Write(
      "survey.yaml", std::string(kManifest) + "trajectory: rig.yaml\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:6: duplicate key 'trajectory' (first on "
                        "line 3)"));
}

TEST(Survey, AcceptsUtf8ByteOrderMarks) {
  const SurveyFolder survey_folder;
  const TemporaryFolder& folder = survey_folder.folder();
  const std::string bom = "\xEF\xBB\xBF";
  folder.Write("survey.yaml", bom + kManifest);
  folder.Write("rig.yaml", bom + kRig);
  folder.Write("trajectory.csv", bom + kTrajectory);
  folder.Write("exposures.csv", bom + Exposures());
  const Survey survey = LoadSurvey(survey_folder.path());
  EXPECT_EQ(survey.trajectory.size(), 11);
  EXPECT_EQ(survey.exposures.images.size(), 20u);
  EXPECT_EQ(survey.rig.cameras.size(), 2u);
}

TEST(Survey, RunsThePlausibilityChecks) {
  const SurveyFolder survey_folder;
  // An origin 112 km from the trajectory: an error on its line.
  survey_folder.folder().Write(
      "survey.yaml", std::string(kManifest) + "origin: [50.9, 2.2958, 60]\n");
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("survey.yaml:6: 'origin' (50.900000, 2.295800) is 112 "
                        "km from the nearest sample of trajectory.csv"));
}

TEST(Survey, WithoutRequiredImagesAnyShareMayBeMissing) {
  const SurveyFolder survey_folder;
  std::filesystem::remove_all(survey_folder.folder().Path("images"));
  EXPECT_THAT(ErrorOfLoad(survey_folder.path()),
              HasSubstr("20 of 20 images are missing"));
  SurveyLoadOptions geometry;
  geometry.require_images = false;
  EXPECT_EQ(LoadSurvey(survey_folder.path(), geometry).warnings.size(), 20u);
}

TEST(Survey, OptionsCheckNamesTheFieldAndValue) {
  SurveyLoadOptions options;
  EXPECT_EQ(options.Check(), "");
  options.max_missing_image_fraction = 1.5;
  EXPECT_EQ(options.Check(),
            "max_missing_image_fraction = 1.5: must be in [0, 1]");
  const SurveyFolder survey_folder;
  EXPECT_THROW(LoadSurvey(survey_folder.path(), options),
               std::invalid_argument);
}

TEST(Manifest, WriteThenReadIsExact) {
  const SurveyFolder survey_folder;
  SurveyManifest manifest;
  manifest.name = "amiens: demo #1";
  manifest.origin = Geodetic{49.894123456789012, 2.2958 / 3.0, 60.0 / 7.0};
  WriteManifest(manifest, survey_folder.folder().Path("survey.yaml"));
  const SurveyManifest read = ReadManifest(survey_folder.path());
  EXPECT_EQ(read.name, manifest.name);
  EXPECT_EQ(read.rig, "rig.yaml");
  EXPECT_EQ(read.trajectory, "trajectory.csv");
  EXPECT_EQ(read.exposures, "exposures.csv");
  EXPECT_EQ(read.roadmarks, "roadmarks.geojson");
  ASSERT_TRUE(read.origin.has_value());
  EXPECT_EQ(read.origin->lat_deg, manifest.origin->lat_deg);
  EXPECT_EQ(read.origin->lon_deg, manifest.origin->lon_deg);
  EXPECT_EQ(read.origin->h_m, manifest.origin->h_m);
}

// Names YAML would read as something else are quoted, and read back as
// written: booleans, numbers, nulls, colons, quotes.
TEST(Manifest, NamesYamlWouldMisreadRoundTrip) {
  for (const char* name_text :
       {"yes", "Off", "null", "1", "3.5", "a: b", "say \"hi\"", "back\\slash",
        "data/roadmarks.geojson", "-x", ""}) {
    const std::string name = name_text;
    SCOPED_TRACE(name);
    TemporaryFolder folder;
    SurveyManifest manifest;
    manifest.name = name;
    manifest.roadmarks = "data/roadmarks.geojson";
    WriteManifest(manifest, folder.Path("survey.yaml"));
    std::ifstream in(folder.Path("survey.yaml"));
    const std::string text((std::istreambuf_iterator<char>(in)),
                           std::istreambuf_iterator<char>());
    // File names with a '/' stay plain (readable by hand).
    EXPECT_NE(text.find("roadmarks: data/roadmarks.geojson\n"),
              std::string::npos);
    if (name.empty()) continue;  // no survey has an empty name
    // Python's YAML 1.1 reader (the shared checker's) would read these as
    // booleans, null or numbers: quoted.
    if (name == "yes" || name == "Off" || name == "null" || name == "1") {
      EXPECT_NE(text.find("name: \"" + name + "\"\n"), std::string::npos);
    }
    const YAML::Node node = YAML::Load(text);
    EXPECT_EQ(node["name"].as<std::string>(), name);
  }
}

TEST(Manifest, WriteLeavesNoTemporaryAndFailsCleanly) {
  TemporaryFolder folder;
  WriteManifest(SurveyManifest(), folder.Path("survey.yaml"));
  EXPECT_EQ(folder.CountEntries(), 1);
  EXPECT_ANY_THROW(WriteManifest(SurveyManifest(), folder.Path("a/b.yaml")));
  EXPECT_EQ(folder.CountEntries(), 1);
}

}  // namespace
}  // namespace zebrageo
