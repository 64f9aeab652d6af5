// The diagnosis of a database offset (pipeline/diagnosis.h) on plain data:
// the field cases' own corrections (a GNSS/INS bias of 0.3 to 0.48 m) say
// nothing; amiens-short's database moved 0.8 m east (its run: 1.1 m at
// both crossings) is named with the offset and what to check.
#include "pipeline/diagnosis.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

std::vector<CrossingCorrection> Corrections(
    const std::vector<Eigen::Vector3d>& corrections, double sd_m = 0.03) {
  std::vector<CrossingCorrection> crossings;
  for (size_t i = 0; i < corrections.size(); ++i) {
    CrossingCorrection c;
    c.crossing_id = "C" + std::to_string(i);
    c.time_s = 10.0 * i;
    c.correction_enu = corrections[i];
    c.stated_sd_enu = Eigen::Vector3d(sd_m, sd_m, 1.5 * sd_m);
    crossings.push_back(c);
  }
  return crossings;
}

TEST(DiagnoseCommonOffset, NamesAnOffsetOfTheDatabaseWithWhatToCheck) {
  const auto diagnosis = DiagnoseCommonOffset(
      Corrections({{1.12, 0.30, 0.01}, {1.05, 0.28, -0.01}}),
      "roadmarks.geojson", "trajectory.csv", DiagnosisOptions());
  ASSERT_TRUE(diagnosis.has_value());
  EXPECT_EQ(diagnosis->cause, "database_offset");
  EXPECT_THAT(diagnosis->message, HasSubstr("E +1.08 N +0.29"));
  EXPECT_THAT(diagnosis->message, HasSubstr("112 cm horizontally"));
  EXPECT_THAT(diagnosis->message, HasSubstr("roadmarks.geojson"));
  EXPECT_THAT(diagnosis->message, HasSubstr("roadmarks_crs"));
  EXPECT_THAT(diagnosis->message, HasSubstr("trajectory.csv states"));
}

TEST(DiagnoseCommonOffset, TheFieldCasesBiasesSayNothing) {
  // amiens-short-jittery's largest correction, buenos-aires's.
  EXPECT_FALSE(
      DiagnoseCommonOffset(Corrections({{0.30, 0.37, 0.0}, {0.25, 0.36, 0.0}}),
                           "r", "t", DiagnosisOptions())
          .has_value());
  EXPECT_FALSE(
      DiagnoseCommonOffset(Corrections({{-0.42, 0.15, 0.0}, {-0.36, 0.0, 0.0}}),
                           "r", "t", DiagnosisOptions())
          .has_value());
}

TEST(DiagnoseCommonOffset,
     NeedsTheOffsetCommonBeyondTheStatedSdAndTwoCrossings) {
  // Not common: a drift that grows along the survey.
  EXPECT_FALSE(
      DiagnoseCommonOffset(Corrections({{0.4, 0.0, 0.0}, {1.6, 0.0, 0.0}}), "r",
                           "t", DiagnosisOptions())
          .has_value());
  // Within what the trajectory states (sd 0.5 m: 5 sd is 2.5 m).
  EXPECT_FALSE(
      DiagnoseCommonOffset(Corrections({{1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, 0.5),
                           "r", "t", DiagnosisOptions())
          .has_value());
  // One crossing says nothing of constancy.
  EXPECT_FALSE(DiagnoseCommonOffset(Corrections({{1.0, 0.0, 0.0}}), "r", "t",
                                    DiagnosisOptions())
                   .has_value());
}

TEST(DiagnosisOptions, CheckNamesTheField) {
  DiagnosisOptions options;
  options.min_crossings = 1;
  EXPECT_THAT(options.Check(), HasSubstr("min_crossings"));
  EXPECT_THROW(DiagnoseCommonOffset({}, "r", "t", options),
               std::invalid_argument);
}

}  // namespace
}  // namespace zebrageo
