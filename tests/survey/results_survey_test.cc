// A stage file's survey identity (survey/results_survey.h).
#include "survey/results_survey.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "survey/input_error.h"
#include "survey/results.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

ExposureTable Table() {
  ExposureTable table;
  for (int i = 0; i < 5; ++i) {
    Exposure exposure;
    exposure.exposure_id = 100 + i;
    exposure.time = 313426.5 + 0.4 * i;
    exposure.image_of_camera = {2 * i, 2 * i + 1};
    table.exposures.push_back(exposure);
    table.images.push_back({exposure.exposure_id, exposure.time, 0,
                            "images/left/" + std::to_string(i) + ".png"});
    table.images.push_back({exposure.exposure_id, exposure.time, 1,
                            "images/right/" + std::to_string(i) + ".png"});
  }
  return table;
}

TEST(SurveyIdentity, IsTheExposuresIdsAndExactTimes) {
  const ExposureTable table = Table();
  const std::string identity = SurveyIdentity(table);
  EXPECT_EQ(identity.size(), 16u);
  // Image paths are not in it: moving the images keeps the survey.
  ExposureTable moved = table;
  for (ExposureImage& image : moved.images) image.image = "pool/" + image.image;
  EXPECT_EQ(SurveyIdentity(moved), identity);
  // One id renumbered, or one time moved by one ulp: another survey.
  ExposureTable renumbered = table;
  renumbered.exposures[3].exposure_id += 1000;
  EXPECT_NE(SurveyIdentity(renumbered), identity);
  ExposureTable shifted = table;
  shifted.exposures[0].time = std::nextafter(shifted.exposures[0].time, 1e9);
  EXPECT_NE(SurveyIdentity(shifted), identity);
  ExposureTable shorter = table;
  shorter.exposures.pop_back();
  EXPECT_NE(SurveyIdentity(shorter), identity);
}

TEST(SurveyIdentity, IsReadBackFromTheWritersComments) {
  TemporaryFolder tmp;
  const ExposureTable table = Table();
  const std::string identity = SurveyIdentity(table);
  const std::string path = tmp.Path("matches.csv");
  WriteMatches({{100, 7, 0, "c1", 1, 0}},
               WithSurveyIdentity(table, {"zebrageo match: 1 vertex"}), path);
  const StageFileSurvey file = ReadStageFileSurvey(path, "matches.csv");
  EXPECT_EQ(file.identity, identity);
  EXPECT_EQ(file.line, 1);
  EXPECT_NO_THROW(CheckStageFileSurvey(path, identity));
  EXPECT_EQ(ReadMatches(path, "matches.csv").size(), 1u);

  ExposureTable other = table;
  other.exposures[1].exposure_id = 7;
  try {
    CheckStageFileSurvey(path, SurveyIdentity(other));
    ADD_FAILURE() << "another survey's file was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.file(), path);
    EXPECT_EQ(error.line(), 1);
    EXPECT_NE(error.problem().find("belongs to another survey"),
              std::string::npos)
        << error.what();
  }
}

TEST(SurveyIdentity, OnlyLeadingCommentsNameIt) {
  TemporaryFolder tmp;
  // An older version's file: no identity, read with a warning.
  const std::string old = tmp.Write(
      "old.csv", "# zebrageo match\nexposure_id,band_id\n# survey: 1234\n");
  EXPECT_EQ(ReadStageFileSurvey(old, "old.csv").identity, "");
  EXPECT_NO_THROW(CheckStageFileSurvey(old, "00000000000000ff"));
  // No survey to compare with: not read at all.
  EXPECT_NO_THROW(CheckStageFileSurvey(tmp.Path("absent.csv"), ""));
  EXPECT_THROW(ReadStageFileSurvey(tmp.Path("absent.csv"), "absent.csv"),
               InputError);
  // A byte-order mark and blank lines before it.
  const std::string bom = tmp.Write(
      "bom.csv", "\xEF\xBB\xBF\n  # survey:  00000000000000ff \nexposure_id\n");
  const StageFileSurvey file = ReadStageFileSurvey(bom, "bom.csv");
  EXPECT_EQ(file.identity, "00000000000000ff");
  EXPECT_EQ(file.line, 2);
}

}  // namespace
}  // namespace zebrageo
