#include "survey/results_adjustment.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "survey/input_error.h"
#include "survey/results_report.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

std::string TextOf(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

AdjustmentRecord SampleRecord() {
  AdjustmentRecord r;
  r.usable = true;
  r.message = "converged";
  r.sigma0 = 1.0 / 3;
  r.iterations = 41;
  r.solves = 3;
  r.time_s = 2.5;
  r.counts.exposures = 120;
  r.counts.trajectory_samples = 12001;
  r.counts.control_crossings = 4;
  r.counts.check_crossings = 1;
  r.counts.reconstructed_vertices = 4400;
  r.rms["vertex"] = {"px", 880, 12.5, 0.41};
  r.rms["gnss"] = {"m", 12001, 0.0, 0.052};
  r.check.vertices = 16;
  r.check.evaluated_vertices = 16;
  r.check.rmse_horizontal_m = 0.043;
  r.check.implied_trajectory_vertical_m = 0.004;
  r.posterior_sd_computed = true;
  r.median_posterior_sd_horizontal_m = 0.021;
  r.rejected.push_back({"C3", 2, 1, 7.1, Eigen::Vector3d(0.5, -0.25, 0.01)});
  r.rig.push_back({"left", Eigen::Vector3d(1.5, 0.3, -1.9), 0.0});
  r.model.knot_spacing_s = 1.0;
  r.model.attitude_sigma_deg = Eigen::Vector3d(0.01, 0.01, 0.05);
  r.model.attitude_significance = Eigen::Vector3d(0.3, 0.5, 2.5);
  r.model.attitude_held = {true, true, false};
  r.model.vehicle_motion_sigma_deg = Eigen::Vector2d(0.5, 0.25);
  r.tie_points = AdjustmentRecord::TiePoints{240, 0, 5000, 900, 3600, 4.25};
  r.warnings = {"2 of 240 images are missing: no tie points in them"};
  return r;
}

TEST(AdjustmentRecord, WriteThenReadGivesTheSameFile) {
  TemporaryFolder folder;
  const AdjustmentRecord record = SampleRecord();
  const std::string path = folder.Path(kAdjustmentJsonFile);
  WriteAdjustmentRecord(record, path);
  const AdjustmentRecord read = ReadAdjustmentRecord(path, kAdjustmentJsonFile);
  EXPECT_EQ(read.sigma0, record.sigma0);
  EXPECT_EQ(read.counts.control_crossings, 4);
  EXPECT_EQ(read.rms.at("vertex").after, 0.41);
  EXPECT_TRUE(read.posterior_sd_computed);
  ASSERT_EQ(read.rejected.size(), 1u);
  EXPECT_EQ(read.rejected[0].d_enu_m, record.rejected[0].d_enu_m);
  ASSERT_TRUE(read.tie_points.has_value());
  EXPECT_EQ(read.tie_points->tracks, 900);
  EXPECT_EQ(read.warnings, record.warnings);
  const std::string again = folder.Path("again.json");
  WriteAdjustmentRecord(read, again);
  EXPECT_EQ(TextOf(again), TextOf(path));
}

// No check point evaluated: the figures are null, not a perfect 0.
TEST(AdjustmentRecord, UnevaluatedCheckFiguresAreNull) {
  TemporaryFolder folder;
  AdjustmentRecord record = SampleRecord();
  record.check.evaluated_vertices = 0;
  record.tie_points.reset();
  const nlohmann::json j = AdjustmentJson(record);
  EXPECT_TRUE(j["check_rmse_m"]["horizontal"].is_null());
  EXPECT_TRUE(j["check_rmse_m"]["implied_trajectory"]["vertical"].is_null());
  EXPECT_FALSE(j.contains("tie_points"));
  const std::string path = folder.Path(kAdjustmentJsonFile);
  WriteAdjustmentRecord(record, path);
  const AdjustmentRecord read = ReadAdjustmentRecord(path, kAdjustmentJsonFile);
  EXPECT_TRUE(std::isnan(read.check.rmse_horizontal_m));
  EXPECT_FALSE(read.tie_points.has_value());
  EXPECT_EQ(AdjustmentJson(read), j);
}

// Road lines as the only control: said in the file; a file written before
// the field existed reads as zebra control.
TEST(AdjustmentRecord, RoadLinesOnlyRoundTripsAndDefaultsToFalse) {
  TemporaryFolder folder;
  AdjustmentRecord record = SampleRecord();
  record.road_lines_only = true;
  const std::string path = folder.Path(kAdjustmentJsonFile);
  WriteAdjustmentRecord(record, path);
  EXPECT_TRUE(ReadAdjustmentRecord(path, kAdjustmentJsonFile).road_lines_only);
  nlohmann::json j = AdjustmentJson(record);
  j.erase("road_lines_only");
  const std::string older = folder.Write("older.json", j.dump());
  EXPECT_FALSE(
      ReadAdjustmentRecord(older, kAdjustmentJsonFile).road_lines_only);
  j["road_lines_only"] = "yes";
  const std::string bad = folder.Write("bad.json", j.dump());
  EXPECT_THAT(ErrorOf([&] { ReadAdjustmentRecord(bad, kAdjustmentJsonFile); }),
              HasSubstr("field 'road_lines_only'"));
}

TEST(AdjustmentRecord, ReaderNamesTheProblem) {
  TemporaryFolder folder;
  EXPECT_THAT(ErrorOf([&] {
                ReadAdjustmentRecord(folder.Write("a.json", "{"),
                                     kAdjustmentJsonFile);
              }),
              HasSubstr("adjustment.json: malformed JSON"));
  EXPECT_THAT(ErrorOf([&] {
                ReadAdjustmentRecord(folder.Write("b.json", "{\"usable\": 1}"),
                                     kAdjustmentJsonFile);
              }),
              HasSubstr("field 'usable'"));
}

TEST(ReportJson, WrittenIndentedByOne) {
  TemporaryFolder folder;
  const std::string path = folder.Path("report.json");
  WriteReportJson(nlohmann::json{{"a", 1}}, path);
  EXPECT_EQ(TextOf(path), "{\n \"a\": 1\n}\n");
}

}  // namespace
}  // namespace zebrageo
