// The road-line files of a results folder (issue 9; SURVEY_FORMAT.md "Stage
// outputs"): plain structs, one reader and one writer per file, like
// survey/results.h.
//   reconstructed_lines.csv  written by reconstruct --lines: line vertices in
//                            the body frame, per stereo pair
//   line_matches.csv         written by the adjustment: the line points that
//                            became control, and what each constrains
//   line_control.json        written by the adjustment: what the road lines
//                            controlled, per stretch of trajectory, and the
//                            database lines rejected (the report reads it)
// Units: metres, body or ENU frame as named; times in seconds.
#ifndef ZEBRAGEO_SURVEY_RESULTS_LINES_H_
#define ZEBRAGEO_SURVEY_RESULTS_LINES_H_

#include <Eigen/Core>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace zebrageo {

inline constexpr char kReconstructedLinesFile[] = "reconstructed_lines.csv";
inline constexpr char kLineMatchesFile[] = "line_matches.csv";
inline constexpr char kLineControlFile[] = "line_control.json";

// kCrossingEdge: the seen ends of a zebra crossing's bands, one line across
// them (reconstruction/crossing_edges.h); its points are ordered so that,
// seen from above, the paint lies to the left of the way they run.
enum class RoadLineType { kLaneSolid, kLaneDashed, kStopLine, kCrossingEdge };
inline constexpr int kRoadLineTypes = 4;
const char* RoadLineTypeName(RoadLineType type);  // lane_solid, ...

// reconstructed_lines.csv: one row per vertex of a line seen in one pair.
struct ReconstructedLinePoint {
  int64_t exposure_id = 0;
  int pair = 0;
  int64_t line_id = 0;  // unique within the file
  RoadLineType type = RoadLineType::kLaneSolid;
  int point = 0;  // 0.. along the line
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance_body = Eigen::Matrix3d::Zero();
  Eigen::Vector2d uv_left = Eigen::Vector2d::Zero();
  Eigen::Vector2d uv_right = Eigen::Vector2d::Zero();
};
// Each comment is one "# " line (not split at line breaks).
void WriteReconstructedLines(const std::vector<ReconstructedLinePoint>& points,
                             const std::vector<std::string>& comments,
                             const std::string& path);
// Throws InputError naming the file and line (missing column, bad number,
// unknown type, negative variance).
std::vector<ReconstructedLinePoint> ReadReconstructedLines(
    const std::string& path, const std::string& display_name);

// line_matches.csv: a reconstructed line point matched to a database line.
struct LineMatch {
  int64_t exposure_id = 0;
  int64_t line_id = 0;
  int point = 0;
  RoadLineType type = RoadLineType::kLaneSolid;
  std::string db_line;  // the database line's id
  Eigen::Vector2d across_enu = Eigen::Vector2d::Zero();  // unit, ENU (e, n)
  double distance_m = 0.0;                               // across the line
  double height_m = 0.0;                                 // above the line
  // Across the line and the height (a line along the vehicle), or the
  // height only (a line across the road: a stop line).
  bool constrains_across = true;
  // A whole dash's centre (point -1) on its database dash's: the position
  // along the dash (across_enu then holds the dash's direction, distance_m
  // the offset along it); constrains_across is false.
  bool along = false;
};
void WriteLineMatches(const std::vector<LineMatch>& matches,
                      const std::string& path);
std::vector<LineMatch> ReadLineMatches(const std::string& path,
                                       const std::string& display_name);

// line_control.json.
struct LineControlStretch {
  double t0_s = 0.0;  // from the first exposure
  double t1_s = 0.0;
  double time0 = 0.0;  // absolute time of t0_s
  int cross_track_points = 0;
  int height_points = 0;
  int along_track_points = 0;
};
struct RejectedDatabaseLine {
  std::string db_line;
  std::string type;
  int points = 0;
  double offset_m = 0.0;  // median distance across the line
};
struct LineControlRecord {
  double stretch_s = 30.0;
  int64_t reconstructed_points = 0;
  int64_t matched_points = 0;
  int64_t used_points = 0;
  std::vector<RejectedDatabaseLine> rejected_lines;
  std::vector<LineControlStretch> stretches;
};
// The file's JSON (also embedded in report.json as "road_lines").
nlohmann::json LineControlJson(const LineControlRecord& record);
void WriteLineControl(const LineControlRecord& record, const std::string& path);
// Throws InputError for malformed JSON or a missing or mistyped field.
LineControlRecord ReadLineControl(const std::string& path,
                                  const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_LINES_H_
