#include "reconstruction/road_lines_io.h"

#include "survey/atomic_file.h"
#include "survey/csv.h"

namespace zebrageo {

const char* RoadLineTypeName(RoadLineType type) {
  switch (type) {
    case RoadLineType::kLaneSolid:
      return "lane_solid";
    case RoadLineType::kLaneDashed:
      return "lane_dashed";
    case RoadLineType::kStopLine:
      return "stop_line";
  }
  return "lane_solid";
}

namespace {
const std::vector<std::string>& LineColumns() {
  static const std::vector<std::string> columns = {
      "exposure_id", "pair",   "line_id", "type",   "point",   "x",
      "y",           "z",      "cov_xx",  "cov_xy", "cov_xz",  "cov_yy",
      "cov_yz",      "cov_zz", "u_left",  "v_left", "u_right", "v_right"};
  return columns;
}
}  // namespace

void WriteReconstructedLines(const std::vector<ReconstructedLinePoint>& points,
                             const std::vector<std::string>& comments,
                             const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  for (const std::string& comment : comments) csv.Comment(comment);
  csv.Header(LineColumns());
  for (const ReconstructedLinePoint& p : points) {
    const Eigen::Matrix3d& c = p.covariance_body;
    csv.Add(p.exposure_id)
        .Add(p.pair)
        .Add(p.line_id)
        .Add(RoadLineTypeName(p.type))
        .Add(p.point)
        .Add(p.p_body.x())
        .Add(p.p_body.y())
        .Add(p.p_body.z())
        .Add(c(0, 0))
        .Add(c(0, 1))
        .Add(c(0, 2))
        .Add(c(1, 1))
        .Add(c(1, 2))
        .Add(c(2, 2))
        .Add(p.uv_left.x())
        .Add(p.uv_left.y())
        .Add(p.uv_right.x())
        .Add(p.uv_right.y());
    csv.EndRow();
  }
  file.Commit();
}

std::vector<ReconstructedLinePoint> ReadReconstructedLines(
    const std::string& path, const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, LineColumns());
  std::vector<ReconstructedLinePoint> points;
  for (int row = 0; row < csv.NumRows(); ++row) {
    ReconstructedLinePoint p;
    p.exposure_id = csv.GetInt(row, "exposure_id");
    p.pair = static_cast<int>(csv.GetInt(row, "pair"));
    p.line_id = csv.GetInt(row, "line_id");
    const std::string& type = csv.GetString(row, "type");
    if (type == "lane_solid") {
      p.type = RoadLineType::kLaneSolid;
    } else if (type == "lane_dashed") {
      p.type = RoadLineType::kLaneDashed;
    } else if (type == "stop_line") {
      p.type = RoadLineType::kStopLine;
    } else {
      csv.Fail(row, "type must be lane_solid, lane_dashed or stop_line");
    }
    p.point = static_cast<int>(csv.GetInt(row, "point"));
    p.p_body = Eigen::Vector3d(csv.GetDouble(row, "x"), csv.GetDouble(row, "y"),
                               csv.GetDouble(row, "z"));
    Eigen::Matrix3d& c = p.covariance_body;
    c(0, 0) = csv.GetDouble(row, "cov_xx");
    c(0, 1) = c(1, 0) = csv.GetDouble(row, "cov_xy");
    c(0, 2) = c(2, 0) = csv.GetDouble(row, "cov_xz");
    c(1, 1) = csv.GetDouble(row, "cov_yy");
    c(1, 2) = c(2, 1) = csv.GetDouble(row, "cov_yz");
    c(2, 2) = csv.GetDouble(row, "cov_zz");
    if (!(c(0, 0) >= 0.0 && c(1, 1) >= 0.0 && c(2, 2) >= 0.0)) {
      csv.Fail(row, "a variance is negative");
    }
    p.uv_left = Eigen::Vector2d(csv.GetDouble(row, "u_left"),
                                csv.GetDouble(row, "v_left"));
    p.uv_right = Eigen::Vector2d(csv.GetDouble(row, "u_right"),
                                 csv.GetDouble(row, "v_right"));
    points.push_back(p);
  }
  return points;
}

}  // namespace zebrageo
