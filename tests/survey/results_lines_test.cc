#include "survey/results_lines.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "survey/input_error.h"
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

TEST(ReconstructedLines, WriteThenReadIsExact) {
  TemporaryFolder folder;
  std::vector<ReconstructedLinePoint> points(2);
  points[0].exposure_id = 123456789012;
  points[0].line_id = 4;
  points[0].point = 2;
  points[0].type = RoadLineType::kStopLine;
  points[0].p_body = Eigen::Vector3d(7.0 + 1.0 / 3, -1.0 / 7, 2.1);
  points[0].covariance_body = Eigen::Vector3d(1e-4, 2e-4, 3e-6).asDiagonal();
  points[0].covariance_body(0, 1) = points[0].covariance_body(1, 0) = 1e-5;
  points[0].uv_left = Eigen::Vector2d(100.25, 300.125);
  points[1].pair = 1;
  points[1].type = RoadLineType::kLaneDashed;
  const std::string path = folder.Path(kReconstructedLinesFile);
  WriteReconstructedLines(points, {"test"}, path);
  const std::vector<ReconstructedLinePoint> read =
      ReadReconstructedLines(path, kReconstructedLinesFile);
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, points[i].exposure_id);
    EXPECT_EQ(read[i].pair, points[i].pair);
    EXPECT_EQ(read[i].line_id, points[i].line_id);
    EXPECT_EQ(read[i].type, points[i].type);
    EXPECT_EQ(read[i].point, points[i].point);
    EXPECT_EQ(read[i].p_body, points[i].p_body);
    EXPECT_EQ(read[i].covariance_body, points[i].covariance_body);
    EXPECT_EQ(read[i].uv_left, points[i].uv_left);
    EXPECT_EQ(read[i].uv_right, points[i].uv_right);
  }
}

TEST(LineMatches, WriteThenReadIsExact) {
  TemporaryFolder folder;
  std::vector<LineMatch> matches(3);
  matches[0].exposure_id = 17;
  matches[0].line_id = 3;
  matches[0].point = 5;
  matches[0].type = RoadLineType::kLaneSolid;
  matches[0].db_line = "L12";
  matches[0].across_enu = Eigen::Vector2d(0.6, -0.8);
  matches[0].distance_m = -1.0 / 3;
  matches[0].height_m = 0.0125;
  matches[1].type = RoadLineType::kStopLine;
  matches[1].db_line = "S1";
  matches[1].constrains_across = false;
  // A dash's centre: along its database dash.
  matches[2].point = -1;
  matches[2].type = RoadLineType::kLaneDashed;
  matches[2].db_line = "D4";
  matches[2].across_enu = Eigen::Vector2d(0.8, 0.6);
  matches[2].distance_m = 0.125;
  matches[2].constrains_across = false;
  matches[2].along = true;
  const std::string path = folder.Path(kLineMatchesFile);
  WriteLineMatches(matches, path);
  const std::vector<LineMatch> read = ReadLineMatches(path, kLineMatchesFile);
  ASSERT_EQ(read.size(), 3u);
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].exposure_id, matches[i].exposure_id);
    EXPECT_EQ(read[i].line_id, matches[i].line_id);
    EXPECT_EQ(read[i].point, matches[i].point);
    EXPECT_EQ(read[i].type, matches[i].type);
    EXPECT_EQ(read[i].db_line, matches[i].db_line);
    EXPECT_EQ(read[i].across_enu, matches[i].across_enu);
    EXPECT_EQ(read[i].distance_m, matches[i].distance_m);
    EXPECT_EQ(read[i].height_m, matches[i].height_m);
    EXPECT_EQ(read[i].constrains_across, matches[i].constrains_across);
    EXPECT_EQ(read[i].along, matches[i].along);
  }
}

TEST(LineMatches, ReaderRejectsUnknownConstraints) {
  TemporaryFolder folder;
  const std::string path = folder.Write(
      "m.csv",
      "exposure_id,line_id,point,type,db_line,across_e,across_n,distance_m,"
      "height_m,constrains\n"
      "1,2,3,lane_solid,L1,1,0,0.1,0,sideways\n");
  EXPECT_THAT(ErrorOf([&] { ReadLineMatches(path, kLineMatchesFile); }),
              HasSubstr("line_matches.csv:2: constrains must be"));
}

TEST(LineControl, WriteThenReadGivesTheSameFile) {
  TemporaryFolder folder;
  LineControlRecord record;
  record.reconstructed_points = 1200;
  record.matched_points = 800;
  record.used_points = 640;
  record.rejected_lines.push_back({"L7", "lane_dashed", 44, -0.31});
  record.stretches.push_back({0.0, 30.0, 1000.5, 12, 20, 0});
  record.stretches.push_back({60.0, 90.0, 1060.5, 0, 3, 1});
  const std::string path = folder.Path(kLineControlFile);
  WriteLineControl(record, path);
  const LineControlRecord read = ReadLineControl(path, kLineControlFile);
  EXPECT_EQ(read.stretch_s, record.stretch_s);
  EXPECT_EQ(read.used_points, record.used_points);
  ASSERT_EQ(read.rejected_lines.size(), 1u);
  EXPECT_EQ(read.rejected_lines[0].db_line, "L7");
  EXPECT_EQ(read.rejected_lines[0].offset_m, -0.31);
  ASSERT_EQ(read.stretches.size(), 2u);
  EXPECT_EQ(read.stretches[1].time0, 1060.5);
  EXPECT_EQ(read.stretches[1].along_track_points, 1);
  EXPECT_EQ(LineControlJson(read), LineControlJson(record));
  const nlohmann::json j = LineControlJson(record);
  EXPECT_EQ(j["stretches"][0]["controlled"],
            nlohmann::json::array({"cross-track", "height"}));
}

TEST(LineControl, ReaderNamesAMissingField) {
  TemporaryFolder folder;
  const std::string path = folder.Write("c.json", "{\"stretch_s\": 30.0}");
  EXPECT_THAT(ErrorOf([&] { ReadLineControl(path, kLineControlFile); }),
              HasSubstr("no field 'reconstructed_points'"));
}

}  // namespace
}  // namespace zebrageo
