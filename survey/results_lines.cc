#include "survey/results_lines.h"

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/json_file.h"

namespace zebrageo {
namespace {

using nlohmann::json;

const std::vector<std::string>& LineColumns() {
  static const std::vector<std::string> columns = {
      "exposure_id", "pair",   "line_id", "type",   "point",   "x",
      "y",           "z",      "cov_xx",  "cov_xy", "cov_xz",  "cov_yy",
      "cov_yz",      "cov_zz", "u_left",  "v_left", "u_right", "v_right"};
  return columns;
}

const std::vector<std::string>& LineMatchColumns() {
  static const std::vector<std::string> columns = {
      "exposure_id", "line_id",  "point",      "type",     "db_line",
      "across_e",    "across_n", "distance_m", "height_m", "constrains"};
  return columns;
}

RoadLineType TypeOf(const CsvTable& csv, int row) {
  const std::string& type = csv.GetString(row, "type");
  if (type == "lane_solid") return RoadLineType::kLaneSolid;
  if (type == "lane_dashed") return RoadLineType::kLaneDashed;
  if (type == "stop_line") return RoadLineType::kStopLine;
  if (type == "crossing_edge") return RoadLineType::kCrossingEdge;
  csv.Fail(row,
           "type must be lane_solid, lane_dashed, stop_line or crossing_edge");
}

// The value of `key` in `object` as T; throws InputError naming the key.
template <typename T>
T Field(const json& object, const char* key, const std::string& display_name) {
  if (!object.is_object() || !object.contains(key)) {
    throw InputError(display_name, 0, std::string("no field '") + key + "'");
  }
  try {
    return object.at(key).get<T>();
  } catch (const json::exception& error) {
    throw InputError(display_name, 0,
                     std::string("field '") + key + "': " + error.what());
  }
}

}  // namespace

const char* RoadLineTypeName(RoadLineType type) {
  switch (type) {
    case RoadLineType::kLaneSolid:
      return "lane_solid";
    case RoadLineType::kLaneDashed:
      return "lane_dashed";
    case RoadLineType::kStopLine:
      return "stop_line";
    case RoadLineType::kCrossingEdge:
      return "crossing_edge";
  }
  return "lane_solid";
}

// ---------------------------------------------------------------------------
// reconstructed_lines.csv

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
    p.type = TypeOf(csv, row);
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

// ---------------------------------------------------------------------------
// line_matches.csv

void WriteLineMatches(const std::vector<LineMatch>& matches,
                      const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  csv.Comment(
      "road-line points matched to database lines (issue 9); each constrains "
      "the position across the line (across_e, across_n) and the height, "
      "never along the line; a whole dash's centre (point -1, constrains "
      "along) the position along its database dash (across_e, across_n then "
      "hold the dash's direction, distance_m the offset along it)");
  csv.Header(LineMatchColumns());
  for (const LineMatch& m : matches) {
    csv.Add(m.exposure_id)
        .Add(m.line_id)
        .Add(m.point)
        .Add(RoadLineTypeName(m.type))
        .Add(m.db_line)
        .Add(m.across_enu.x())
        .Add(m.across_enu.y())
        .Add(m.distance_m)
        .Add(m.height_m)
        .Add(m.along ? "along"
                     : (m.constrains_across ? "across+height" : "height"));
    csv.EndRow();
  }
  file.Commit();
}

std::vector<LineMatch> ReadLineMatches(const std::string& path,
                                       const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, LineMatchColumns());
  std::vector<LineMatch> matches;
  for (int row = 0; row < csv.NumRows(); ++row) {
    LineMatch m;
    m.exposure_id = csv.GetInt(row, "exposure_id");
    m.line_id = csv.GetInt(row, "line_id");
    m.point = static_cast<int>(csv.GetInt(row, "point"));
    m.type = TypeOf(csv, row);
    m.db_line = csv.GetString(row, "db_line");
    m.across_enu = Eigen::Vector2d(csv.GetDouble(row, "across_e"),
                                   csv.GetDouble(row, "across_n"));
    m.distance_m = csv.GetDouble(row, "distance_m");
    m.height_m = csv.GetDouble(row, "height_m");
    const std::string& constrains = csv.GetString(row, "constrains");
    if (constrains != "across+height" && constrains != "height" &&
        constrains != "along") {
      csv.Fail(row, "constrains must be across+height, height or along");
    }
    m.constrains_across = constrains == "across+height";
    m.along = constrains == "along";
    matches.push_back(m);
  }
  return matches;
}

// ---------------------------------------------------------------------------
// line_control.json

json LineControlJson(const LineControlRecord& record) {
  json j;
  j["stretch_s"] = record.stretch_s;
  j["reconstructed_points"] = record.reconstructed_points;
  j["matched_points"] = record.matched_points;
  j["used_points"] = record.used_points;
  json rejected = json::array();
  for (const RejectedDatabaseLine& r : record.rejected_lines) {
    rejected.push_back({{"db_line", r.db_line},
                        {"type", r.type},
                        {"points", r.points},
                        {"offset_m", r.offset_m}});
  }
  j["rejected_lines"] = rejected;
  j["note"] =
      "a road line constrains the position across itself and the height, "
      "never along itself: lane lines control cross-track and height; stop "
      "lines the height only (the zebra crossings beside them hold the "
      "along-track position); a dash seen whole, matched to a database "
      "dash, the position along the track";
  json list = json::array();
  for (const LineControlStretch& s : record.stretches) {
    json controlled = json::array();
    if (s.cross_track_points > 0) controlled.push_back("cross-track");
    if (s.height_points > 0) controlled.push_back("height");
    if (s.along_track_points > 0) controlled.push_back("along-track");
    list.push_back({{"t0_s", s.t0_s},
                    {"t1_s", s.t1_s},
                    {"time0", s.time0},
                    {"cross_track_points", s.cross_track_points},
                    {"height_points", s.height_points},
                    {"along_track_points", s.along_track_points},
                    {"controlled", controlled}});
  }
  j["stretches"] = list;
  return j;
}

void WriteLineControl(const LineControlRecord& record,
                      const std::string& path) {
  AtomicFile file(path);
  file.stream() << LineControlJson(record).dump(2) << "\n";
  file.Commit();
}

LineControlRecord ReadLineControl(const std::string& path,
                                  const std::string& display_name) {
  const json j = ReadJsonFile(path, display_name);
  const std::string& name = display_name;
  LineControlRecord record;
  record.stretch_s = Field<double>(j, "stretch_s", name);
  record.reconstructed_points = Field<int64_t>(j, "reconstructed_points", name);
  record.matched_points = Field<int64_t>(j, "matched_points", name);
  record.used_points = Field<int64_t>(j, "used_points", name);
  for (const json& r : Field<json>(j, "rejected_lines", name)) {
    record.rejected_lines.push_back({Field<std::string>(r, "db_line", name),
                                     Field<std::string>(r, "type", name),
                                     Field<int>(r, "points", name),
                                     Field<double>(r, "offset_m", name)});
  }
  for (const json& s : Field<json>(j, "stretches", name)) {
    LineControlStretch stretch;
    stretch.t0_s = Field<double>(s, "t0_s", name);
    stretch.t1_s = Field<double>(s, "t1_s", name);
    stretch.time0 = Field<double>(s, "time0", name);
    stretch.cross_track_points = Field<int>(s, "cross_track_points", name);
    stretch.height_points = Field<int>(s, "height_points", name);
    stretch.along_track_points = Field<int>(s, "along_track_points", name);
    record.stretches.push_back(stretch);
  }
  return record;
}

}  // namespace zebrageo
