#include "survey/results.h"

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/geojson_internal.h"
#include "survey/input_error.h"
#include "survey/output_crs.h"

namespace zebrageo {
namespace {

using nlohmann::json;

// A quaternion in poses.csv is a rotation: its norm is 1 up to the digits
// written (all of them, with FormatDouble).
constexpr double kQuaternionNormTolerance = 1e-6;

// Writers: a string field that the CSV reader could not read back (it splits
// on ',' and rejects '"') is a bug upstream, not an input error.
const std::string& CheckedField(const std::string& value, const char* column) {
  if (value.find_first_of(",\"\n\r") != std::string::npos) {
    throw std::invalid_argument(std::string("CSV writer: column '") + column +
                                "' value '" + value +
                                "' holds ',', '\"' or a line break");
  }
  return value;
}

void WriteComments(CsvWriter* csv, const std::vector<std::string>& comments) {
  for (const std::string& comment : comments) {
    std::istringstream lines(comment);
    std::string line;
    while (std::getline(lines, line)) csv->Comment(line);
  }
}

// An integer column that must lie in [low, high].
int IntInRange(const CsvTable& csv, int row, const std::string& column,
               int64_t low, int64_t high) {
  const int64_t value = csv.GetInt(row, column);
  if (value < low || value > high) {
    csv.Fail(row, "column '" + column + "': " + std::to_string(value) +
                      " is outside [" + std::to_string(low) + ", " +
                      std::to_string(high) + "]");
  }
  return static_cast<int>(value);
}

double NonNegative(const CsvTable& csv, int row, const std::string& column) {
  const double value = csv.GetDouble(row, column);
  if (value < 0.0) {
    csv.Fail(row, "column '" + column + "': " + FormatDouble(value) +
                      " must be >= 0");
  }
  return value;
}

const std::string& NonEmpty(const CsvTable& csv, int row,
                            const std::string& column) {
  const std::string& value = csv.GetString(row, column);
  if (value.empty()) csv.Fail(row, "column '" + column + "' is empty");
  return value;
}

const std::vector<std::string>& ReconstructedColumns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{
          "exposure_id", "pair",    "band_id", "group_id", "vertex",
          "x",           "y",       "z",       "sxx",      "sxy",
          "sxz",         "syy",     "syz",     "szz",      "u_left",
          "v_left",      "u_right", "v_right", "score"};
  return *kColumns;
}

const std::vector<std::string>& MatchColumns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{"exposure_id", "band_id", "vertex",
                                   "crossing_id", "band",    "db_vertex"};
  return *kColumns;
}

const std::vector<std::string>& DecisionColumns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{"exposure_id", "group_id", "decision",
                                   "crossing_id", "reason"};
  return *kColumns;
}

const std::vector<std::string>& PoseColumns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{
          "exposure_id", "camera", "time", "lat", "lon", "h", "east",
          "north",       "up",     "qw",   "qx",  "qy",  "qz"};
  return *kColumns;
}

const std::vector<std::string>& GcpColumns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{"crossing_id", "band",    "vertex", "role",
                                   "de",          "dn",      "du",     "d3d",
                                   "rms_px",      "n_images"};
  return *kColumns;
}

const char* RoleName(GcpRole role) {
  return role == GcpRole::kControl ? "control" : "check";
}

}  // namespace

// ---------------------------------------------------------------------------
// reconstructed_bands.csv

void WriteReconstructedBands(const std::vector<ReconstructedVertex>& vertices,
                             const std::vector<std::string>& comments,
                             const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  WriteComments(&csv, comments);
  std::vector<std::string> columns = ReconstructedColumns();
  columns.push_back("end_evidence");  // extra trailing column (issue 52)
  csv.Header(columns);
  for (const ReconstructedVertex& v : vertices) {
    const Eigen::Matrix3d& c = v.covariance_body;
    csv.Add(v.exposure_id)
        .Add(v.pair)
        .Add(v.band_id)
        .Add(v.group_id)
        .Add(v.vertex)
        .Add(v.p_body.x())
        .Add(v.p_body.y())
        .Add(v.p_body.z())
        .Add(c(0, 0))
        .Add(c(0, 1))
        .Add(c(0, 2))
        .Add(c(1, 1))
        .Add(c(1, 2))
        .Add(c(2, 2))
        .Add(v.uv_left.x())
        .Add(v.uv_left.y())
        .Add(v.uv_right.x())
        .Add(v.uv_right.y())
        .Add(v.score)
        .Add(v.end_evidence);
    csv.EndRow();
  }
  file.Commit();
}

std::vector<ReconstructedVertex> ReadReconstructedBands(
    const std::string& path, const std::string& display_name) {
  const CsvTable csv =
      CsvTable::Read(path, display_name, ReconstructedColumns());
  std::vector<ReconstructedVertex> vertices;
  // band_id -> (exposure_id, pair, group_id) and row, to check that a band
  // id names one band; (band_id, vertex) must be unique.
  std::map<int64_t, std::pair<std::tuple<int64_t, int, int64_t>, int>> bands;
  std::map<std::pair<int64_t, int>, int> row_of_vertex;
  for (int row = 0; row < csv.NumRows(); ++row) {
    ReconstructedVertex v;
    v.exposure_id = csv.GetInt(row, "exposure_id");
    v.pair = IntInRange(csv, row, "pair", 0, 1000000);
    v.band_id = csv.GetInt(row, "band_id");
    v.group_id = csv.GetInt(row, "group_id");
    v.vertex = IntInRange(csv, row, "vertex", 0, 3);
    v.p_body = Eigen::Vector3d(csv.GetDouble(row, "x"), csv.GetDouble(row, "y"),
                               csv.GetDouble(row, "z"));
    const double sxx = NonNegative(csv, row, "sxx");
    const double syy = NonNegative(csv, row, "syy");
    const double szz = NonNegative(csv, row, "szz");
    const double sxy = csv.GetDouble(row, "sxy");
    const double sxz = csv.GetDouble(row, "sxz");
    const double syz = csv.GetDouble(row, "syz");
    v.covariance_body << sxx, sxy, sxz, sxy, syy, syz, sxz, syz, szz;
    v.uv_left = Eigen::Vector2d(csv.GetDouble(row, "u_left"),
                                csv.GetDouble(row, "v_left"));
    v.uv_right = Eigen::Vector2d(csv.GetDouble(row, "u_right"),
                                 csv.GetDouble(row, "v_right"));
    v.score = csv.GetDouble(row, "score");
    if (csv.HasColumn("end_evidence")) {
      v.end_evidence = csv.GetString(row, "end_evidence");
    }
    if (v.score < 0.0 || v.score > 1.0) {
      csv.Fail(row, "column 'score': " + FormatDouble(v.score) +
                        " is outside [0, 1]");
    }
    const auto identity = std::make_tuple(v.exposure_id, v.pair, v.group_id);
    const auto [band, new_band] =
        bands.emplace(v.band_id, std::make_pair(identity, row));
    if (!new_band && band->second.first != identity) {
      csv.Fail(row, "band_id " + std::to_string(v.band_id) +
                        " has another exposure_id, pair or group_id than on "
                        "line " +
                        std::to_string(csv.LineOf(band->second.second)));
    }
    const auto [vertex, new_vertex] =
        row_of_vertex.emplace(std::make_pair(v.band_id, v.vertex), row);
    if (!new_vertex) {
      csv.Fail(row, "band_id " + std::to_string(v.band_id) + " vertex " +
                        std::to_string(v.vertex) + " already on line " +
                        std::to_string(csv.LineOf(vertex->second)));
    }
    vertices.push_back(v);
  }
  return vertices;
}

// ---------------------------------------------------------------------------
// matches.csv

void WriteMatches(const std::vector<VertexMatch>& matches,
                  const std::vector<std::string>& comments,
                  const std::string& path, const OutputCrs* crs) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  WriteComments(&csv, comments);
  std::vector<std::string> columns = MatchColumns();
  if (crs != nullptr) crs->AddHeader(&csv, &columns);
  csv.Header(columns);
  for (const VertexMatch& m : matches) {
    csv.Add(m.exposure_id)
        .Add(m.band_id)
        .Add(m.vertex)
        .Add(CheckedField(m.crossing_id, "crossing_id"))
        .Add(m.band)
        .Add(m.db_vertex);
    if (crs != nullptr) {
      crs->AddColumns(
          crs->DatabaseVertex(m.crossing_id, m.band, m.db_vertex, kMatchesFile),
          &csv);
    }
    csv.EndRow();
  }
  file.Commit();
}

std::vector<VertexMatch> ReadMatches(const std::string& path,
                                     const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, MatchColumns());
  std::vector<VertexMatch> matches;
  for (int row = 0; row < csv.NumRows(); ++row) {
    VertexMatch m;
    m.exposure_id = csv.GetInt(row, "exposure_id");
    m.band_id = csv.GetInt(row, "band_id");
    m.vertex = IntInRange(csv, row, "vertex", 0, 3);
    m.crossing_id = NonEmpty(csv, row, "crossing_id");
    m.band = IntInRange(csv, row, "band", 1, 1000000);
    m.db_vertex = IntInRange(csv, row, "db_vertex", 0, 3);
    matches.push_back(std::move(m));
  }
  return matches;
}

// ---------------------------------------------------------------------------
// skipped_exposures.csv

void WriteSkippedExposures(const std::vector<SkippedExposure>& skipped,
                           const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  csv.Comment("exposures whose images could not be read: no pose in poses.csv");
  csv.Header({"exposure_id", "reason"});
  for (const SkippedExposure& s : skipped) {
    csv.Add(s.exposure_id).Add(s.reason);
    csv.EndRow();
  }
  file.Commit();
}

std::vector<SkippedExposure> ReadSkippedExposures(
    const std::string& path, const std::string& display_name) {
  const CsvTable csv =
      CsvTable::Read(path, display_name, {"exposure_id", "reason"});
  std::vector<SkippedExposure> skipped;
  for (int row = 0; row < csv.NumRows(); ++row) {
    skipped.push_back(
        {csv.GetInt(row, "exposure_id"), csv.GetString(row, "reason")});
  }
  return skipped;
}

// ---------------------------------------------------------------------------
// crossing_decisions.csv

const char* DecisionName(Decision decision) {
  switch (decision) {
    case Decision::kMatched:
      return "matched";
    case Decision::kRefused:
      return "refused";
    case Decision::kNoCandidate:
      return "no_candidate";
  }
  return "no_candidate";
}

void WriteCrossingDecisions(const std::vector<CrossingDecision>& decisions,
                            const std::vector<std::string>& comments,
                            const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  WriteComments(&csv, comments);
  csv.Header(DecisionColumns());
  for (const CrossingDecision& d : decisions) {
    // The reason is free text: make it one CSV field.
    std::string reason = d.reason;
    for (char& c : reason) {
      if (c == ',') c = ';';
      if (c == '"') c = '\'';
      if (c == '\n' || c == '\r') c = ' ';
    }
    csv.Add(d.exposure_id)
        .Add(d.group_id)
        .Add(DecisionName(d.decision))
        .Add(CheckedField(d.crossing_id, "crossing_id"))
        .Add(reason);
    csv.EndRow();
  }
  file.Commit();
}

std::vector<CrossingDecision> ReadCrossingDecisions(
    const std::string& path, const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, DecisionColumns());
  std::vector<CrossingDecision> decisions;
  for (int row = 0; row < csv.NumRows(); ++row) {
    CrossingDecision d;
    d.exposure_id = csv.GetInt(row, "exposure_id");
    d.group_id = csv.GetInt(row, "group_id");
    const std::string& name = csv.GetString(row, "decision");
    if (name == "matched") {
      d.decision = Decision::kMatched;
    } else if (name == "refused") {
      d.decision = Decision::kRefused;
    } else if (name == "no_candidate") {
      d.decision = Decision::kNoCandidate;
    } else {
      csv.Fail(row, "column 'decision': '" + name +
                        "' is not matched, refused or no_candidate");
    }
    d.crossing_id = csv.GetString(row, "crossing_id");
    if (d.decision == Decision::kMatched && d.crossing_id.empty()) {
      csv.Fail(row, "decision 'matched' without a crossing_id");
    }
    d.reason = csv.GetString(row, "reason");
    decisions.push_back(std::move(d));
  }
  return decisions;
}

// ---------------------------------------------------------------------------
// poses.csv

void WriteCameraPoses(const std::vector<CameraPose>& poses,
                      const std::string& path, const OutputCrs* crs) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  csv.Comment(
      "camera projection centres; q = Hamilton quaternion (w first) of the "
      "camera-to-ENU rotation");
  std::vector<std::string> columns = PoseColumns();
  if (crs != nullptr) crs->AddHeader(&csv, &columns);
  csv.Header(columns);
  for (const CameraPose& p : poses) {
    csv.Add(p.exposure_id)
        .Add(CheckedField(p.camera, "camera"))
        .Add(p.time)
        .Add(p.position.lat_deg)
        .Add(p.position.lon_deg)
        .Add(p.position.h_m)
        .Add(p.p_enu.x())
        .Add(p.p_enu.y())
        .Add(p.p_enu.z())
        .Add(p.q_enu_cam.w())
        .Add(p.q_enu_cam.x())
        .Add(p.q_enu_cam.y())
        .Add(p.q_enu_cam.z());
    if (crs != nullptr) crs->AddColumns(p.position, &csv);
    csv.EndRow();
  }
  file.Commit();
}

std::vector<CameraPose> ReadCameraPoses(const std::string& path,
                                        const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, PoseColumns());
  std::vector<CameraPose> poses;
  for (int row = 0; row < csv.NumRows(); ++row) {
    CameraPose p;
    p.exposure_id = csv.GetInt(row, "exposure_id");
    p.camera = NonEmpty(csv, row, "camera");
    p.time = csv.GetDouble(row, "time");
    p.position.lat_deg = csv.GetDouble(row, "lat");
    p.position.lon_deg = csv.GetDouble(row, "lon");
    p.position.h_m = csv.GetDouble(row, "h");
    if (std::abs(p.position.lat_deg) > 90.0) {
      csv.Fail(row, "column 'lat': " + FormatDouble(p.position.lat_deg) +
                        " is outside [-90, 90]");
    }
    if (std::abs(p.position.lon_deg) > 180.0) {
      csv.Fail(row, "column 'lon': " + FormatDouble(p.position.lon_deg) +
                        " is outside [-180, 180]");
    }
    p.p_enu =
        Eigen::Vector3d(csv.GetDouble(row, "east"), csv.GetDouble(row, "north"),
                        csv.GetDouble(row, "up"));
    p.q_enu_cam =
        Eigen::Quaterniond(csv.GetDouble(row, "qw"), csv.GetDouble(row, "qx"),
                           csv.GetDouble(row, "qy"), csv.GetDouble(row, "qz"));
    const double norm = p.q_enu_cam.norm();
    if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
      csv.Fail(row, "quaternion qw,qx,qy,qz has norm " + FormatDouble(norm) +
                        ", not 1: not a rotation");
    }
    poses.push_back(std::move(p));
  }
  return poses;
}

// ---------------------------------------------------------------------------
// gcp_residuals.csv

const char* GcpStatusName(GcpStatus status) {
  switch (status) {
    case GcpStatus::kControl:
      return "control";
    case GcpStatus::kCheck:
      return "check";
    case GcpStatus::kRejected:
      return "rejected";
  }
  return "control";
}

void WriteGcpResiduals(const std::vector<GcpResidual>& residuals,
                       const std::string& path, const OutputCrs* crs) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  csv.Comment(
      "d* = adjusted (control) or image-only (check, rejected) minus "
      "database, metres ENU; status: control | check | rejected (blunder, "
      "removed from the adjustment)");
  std::vector<std::string> columns = GcpColumns();
  columns.push_back("status");
  columns.push_back("normalized_residual");
  if (crs != nullptr) crs->AddHeader(&csv, &columns);
  csv.Header(columns);
  for (const GcpResidual& r : residuals) {
    csv.Add(CheckedField(r.crossing_id, "crossing_id"))
        .Add(r.band)
        .Add(r.vertex)
        .Add(RoleName(r.role))
        .AddFixed(r.d_enu.x(), 4)
        .AddFixed(r.d_enu.y(), 4)
        .AddFixed(r.d_enu.z(), 4)
        .AddFixed(r.d_enu.norm(), 4)
        .AddFixed(r.rms_px, 3)
        .Add(r.n_images)
        .Add(GcpStatusName(r.status))
        .AddFixed(r.normalized_residual, 2);
    if (crs != nullptr) {
      // The adjusted position: the database vertex plus the offsets as
      // written (0.1 mm).
      const Eigen::Vector3d d(ParseDouble(FormatFixed(r.d_enu.x(), 4)),
                              ParseDouble(FormatFixed(r.d_enu.y(), 4)),
                              ParseDouble(FormatFixed(r.d_enu.z(), 4)));
      const Geodetic db = crs->DatabaseVertex(r.crossing_id, r.band, r.vertex,
                                              kGcpResidualsFile);
      crs->AddColumns(
          crs->frame().GeodeticFromEnu(crs->frame().EnuFromGeodetic(db) + d),
          &csv);
    }
    csv.EndRow();
  }
  file.Commit();
}

std::vector<GcpResidual> ReadGcpResiduals(const std::string& path,
                                          const std::string& display_name) {
  const CsvTable csv = CsvTable::Read(path, display_name, GcpColumns());
  std::vector<GcpResidual> residuals;
  for (int row = 0; row < csv.NumRows(); ++row) {
    GcpResidual r;
    r.crossing_id = NonEmpty(csv, row, "crossing_id");
    r.band = IntInRange(csv, row, "band", 1, 1000000);
    r.vertex = IntInRange(csv, row, "vertex", 0, 3);
    const std::string& role = csv.GetString(row, "role");
    if (role == "control") {
      r.role = GcpRole::kControl;
    } else if (role == "check") {
      r.role = GcpRole::kCheck;
    } else {
      csv.Fail(row, "column 'role': '" + role + "' is not control or check");
    }
    r.d_enu =
        Eigen::Vector3d(csv.GetDouble(row, "de"), csv.GetDouble(row, "dn"),
                        csv.GetDouble(row, "du"));
    NonNegative(csv, row, "d3d");  // derived from de,dn,du; checked only
    r.rms_px = NonNegative(csv, row, "rms_px");
    r.n_images = IntInRange(csv, row, "n_images", 0, 1000000000);
    r.status =
        r.role == GcpRole::kCheck ? GcpStatus::kCheck : GcpStatus::kControl;
    if (csv.HasColumn("status")) {
      const std::string& status = csv.GetString(row, "status");
      if (status == "rejected") {
        r.status = GcpStatus::kRejected;
      } else if (status != GcpStatusName(r.status)) {
        csv.Fail(row, "column 'status': '" + status + "' is not " +
                          GcpStatusName(r.status) + " or rejected");
      }
    }
    if (csv.HasColumn("normalized_residual")) {
      r.normalized_residual = NonNegative(csv, row, "normalized_residual");
    }
    residuals.push_back(std::move(r));
  }
  return residuals;
}

}  // namespace zebrageo
