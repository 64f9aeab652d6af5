// Road lines to database lines (issue 9, step 2).
//
// A reconstructed line point, put in ENU with a trajectory (the GNSS/INS
// one, or better the one already corrected by the zebra crossings), is
// matched to the nearest database line of a compatible type (lane_solid and
// lane_dashed are interchangeable: a dash cut by the image border looks
// solid; stop lines only to stop lines) when:
//   - it lies within gate_m of the line horizontally and max_height_m in
//     height (the trajectory's remaining error);
//   - the next candidate line is at least min_separation_ratio times
//     farther (lane lines are 1.5 to 4 m apart: a drift of half the spacing
//     would match the neighbour, so an ambiguous point is left out);
//   - the reconstructed line runs along the database segment (angle below
//     max_angle_rad).
// All points of one reconstructed line must agree on the database line;
// lines whose points split between two database lines are dropped.
//
// A line constrains only across itself: each match says so, with the
// horizontal unit normal of the database segment (across) and up (height);
// the direction along the line is free.
#ifndef ZEBRAGEO_REGISTRATION_LINE_MATCHER_H_
#define ZEBRAGEO_REGISTRATION_LINE_MATCHER_H_

#include <Eigen/Core>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "survey/geodesy.h"
#include "survey/roadmarks.h"

namespace zebrageo {

struct LineMatchOptions {
  double gate_m = 0.6;
  double max_height_m = 0.5;
  double min_separation_ratio = 2.5;
  double max_angle_rad = 0.2;
  // A reconstructed line is kept when at least this share of its points
  // match, all to the same database line.
  double min_matched_share = 0.5;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("gate_m", gate_m);
    v("max_height_m", max_height_m);
    v("min_separation_ratio", min_separation_ratio);
    v("max_angle_rad", max_angle_rad);
    v("min_matched_share", min_matched_share);
  }
};

// A database line in the working frame.
struct DatabaseLineEnu {
  std::string id;
  std::string type;
  std::vector<Eigen::Vector3d> points;
  double sigma_xy_m = 0.0;
  double sigma_z_m = 0.0;
};

std::vector<DatabaseLineEnu> DatabaseLinesEnu(const RoadmarkDatabase& database,
                                              const LocalFrame& frame);

// The slope (dz per horizontal metre, in the direction of the line's
// points) of a database line at a point of one of its segments (fraction
// t in [0, 1]): the least-squares slope of its vertices within
// half_window_m (horizontal, along the line) of that point, so one vertex's
// height noise does not make a short segment steep; the segment's own
// slope when fewer than 3 vertices are that close.
double DatabaseLineGrade(const DatabaseLineEnu& line, int segment, double t,
                         double half_window_m);

// One reconstructed line point in ENU.
struct LinePointEnu {
  int64_t line_id = 0;  // points of one line share it, consecutive
  std::string type;     // lane_solid, lane_dashed, stop_line
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
};

struct LinePointMatch {
  int point = 0;              // index into the points
  int db_line = 0;            // index into the database lines
  int db_segment = 0;         // its segment (points[db_segment], points[+1])
  double db_segment_t = 0.0;  // where on it, [0, 1]
  // The matched database segment's point nearest (horizontally) to the
  // reconstructed point, and the directions the match constrains.
  Eigen::Vector3d db_point_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d across_enu = Eigen::Vector3d::Zero();  // horizontal unit
  Eigen::Vector3d along_enu = Eigen::Vector3d::Zero();   // not constrained
  double distance_m = 0.0;  // horizontal, signed along across_enu
  double height_m = 0.0;    // point minus database
};

std::vector<LinePointMatch> MatchLinePoints(
    const std::vector<LinePointEnu>& points,
    const std::vector<DatabaseLineEnu>& database,
    const LineMatchOptions& options);

// Stale database lines. A line repainted since the database was made (or a
// database line that was never this mark) still lies within the matching
// gate when it moved by a few decimetres, and would pull the trajectory by
// as much. The trajectory's own remaining error is common to every line
// seen at the same time, so each database line is compared with the others:
// a point's offset is its distance across the line minus the median
// distance, along the same direction, of the points of the other (parallel)
// lines matched within window_s of it. A database line whose median offset
// exceeds max_offset_m, over at least min_points points, is rejected. A line
// seen alone cannot be checked and is kept (the adjustment's robust loss
// remains).
struct LineConsistencyOptions {
  double window_s = 2.0;
  double max_offset_m = 0.15;
  int min_points = 5;
  // Other lines count as parallel when |cos| of their normals exceeds this.
  double min_parallel_cos = 0.9;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("window_s", window_s);
    v("max_offset_m", max_offset_m);
    v("min_points", min_points);
    v("min_parallel_cos", min_parallel_cos);
  }
};

struct RejectedLine {
  int db_line = 0;
  int points = 0;         // its matched points with a reference
  double offset_m = 0.0;  // median offset from the other lines, signed
};

// Splits `matches` (of points at `point_time[m.point]`) into the kept ones
// and the database lines rejected as inconsistent, largest offset first.
// `checked` (optional): the kept database lines that another painted line
// vouched for (at least min_points points compared); a line seen alone is
// kept but not checked.
std::vector<RejectedLine> RejectInconsistentLines(
    const std::vector<LinePointMatch>& matches,
    const std::vector<double>& point_time,
    const LineConsistencyOptions& options, std::vector<LinePointMatch>* kept,
    std::set<int>* checked = nullptr);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_LINE_MATCHER_H_
