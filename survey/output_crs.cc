#include "survey/output_crs.h"

#include <glog/logging.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>
#include <vector>

#include "survey/atomic_file.h"
#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/results.h"
#include "survey/text_file.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr char kCrsColumns[] = "crs_x,crs_y,crs_z";
constexpr char kCrsCommentPrefix[] = "# output_crs";
constexpr char kCrsColumnsComment[] = "# crs_x,crs_y,crs_z:";

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) lines.push_back(line);
  return lines;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

// Keeps the first `count` (> 0) comma-separated fields of `line`.
std::string FirstFields(const std::string& line, int count) {
  std::size_t comma = 0;
  for (int i = 0; i < count; ++i) {
    comma = line.find(',', i == 0 ? 0 : comma + 1);
    if (comma == std::string::npos) return line;
  }
  return line.substr(0, comma);
}

// The database vertices by (crossing_id, band, db_vertex).
using VertexKey = std::tuple<std::string, int, int>;
std::map<VertexKey, Geodetic> DatabaseVertices(const RoadmarkDatabase& db) {
  std::map<VertexKey, Geodetic> vertices;
  for (const RoadmarkBand& band : db.bands) {
    for (int k = 0; k < 4; ++k) {
      vertices[{band.crossing_id, band.band, k}] = band.corners[k];
    }
  }
  return vertices;
}

struct CrsWriter {
  const Survey& survey;
  const Crs& crs;
  const CrsTransformer& transformer;

  Eigen::Vector3d Transform(const Geodetic& wgs84) const {
    try {
      return transformer.FromWgs84(wgs84);
    } catch (const CrsError& error) {
      throw InputError("survey.yaml", survey.manifest.output_crs.line,
                       std::string("output_crs: ") + error.what());
    }
  }

  std::vector<std::string> HeaderComments() const {
    return {
        std::string(kCrsCommentPrefix) + ": " +
            (crs.identifier().empty() ? crs.definition() : crs.identifier()),
        std::string(kCrsColumnsComment) + " " + crs.Description(),
        std::string(kCrsCommentPrefix) + "_wkt: " + crs.wkt()};
  }

  // Rewrites the CSV at `path` with crs_x, crs_y, crs_z appended, from the
  // WGS84 position `position` gives for each row. Earlier crs columns and
  // comments are dropped first.
  void AppendColumns(
      const std::string& path, const std::string& display_name,
      const std::vector<std::string>& required,
      const std::function<Geodetic(const CsvTable&, int)>& position) const {
    const std::string text = ReadTextFile(path, display_name);
    const CsvTable table = CsvTable::Parse(text, display_name, required);
    std::vector<std::string> lines = SplitLines(text);
    const int kept_fields = table.ColumnIndex("crs_x");
    std::vector<std::string> out;
    bool header_done = false;
    int row = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      std::string line = lines[i];
      const std::size_t first = line.find_first_not_of(" \t\r");
      const bool comment = first != std::string::npos && line[first] == '#';
      if (comment && (StartsWith(line.substr(first), kCrsCommentPrefix) ||
                      StartsWith(line.substr(first), kCrsColumnsComment))) {
        continue;
      }
      if (comment || first == std::string::npos) {
        out.push_back(line);
        continue;
      }
      if (kept_fields >= 0) line = FirstFields(line, kept_fields);
      if (!header_done) {
        for (const std::string& c : HeaderComments()) out.push_back(c);
        out.push_back(line + "," + kCrsColumns);
        header_done = true;
        continue;
      }
      if (row >= table.NumRows() ||
          table.LineOf(row) != static_cast<int>(i) + 1) {
        throw InputError(display_name, static_cast<int>(i) + 1,
                         "unexpected line while adding output_crs columns");
      }
      const Eigen::Vector3d xyz = Transform(position(table, row));
      out.push_back(line + "," + FormatDouble(xyz.x()) + "," +
                    FormatDouble(xyz.y()) + "," + FormatDouble(xyz.z()));
      ++row;
    }
    WriteFileAtomically(path, [&](std::ostream& stream) {
      for (const std::string& line : out) stream << line << "\n";
    });
  }

  // bands.geojson with its coordinates in the output CRS and a "crs" member.
  void RewriteBands(const std::string& path) const {
    // The features' properties are kept as written: the JSON itself, with
    // the contract's reader for the corners.
    nlohmann::json collection = ReadJsonFile(path, kBandsGeoJsonFile);
    if (collection.contains("crs")) return;  // already in the output CRS
    const std::vector<AdjustedBand> bands =
        ReadAdjustedBands(path, kBandsGeoJsonFile);
    nlohmann::json features = collection.value("features", nlohmann::json());
    if (!features.is_array() || features.size() != bands.size()) {
      throw InputError(kBandsGeoJsonFile, 0, "unexpected features");
    }
    std::string body =
        "{\"type\": \"FeatureCollection\", \"crs\": " + CrsMember().dump() +
        ", \"features\": [\n";
    for (std::size_t i = 0; i < bands.size(); ++i) {
      nlohmann::json ring = nlohmann::json::array();
      for (int k = 0; k <= 4; ++k) {
        const Eigen::Vector3d xyz = Transform(bands[i].corners[k % 4]);
        ring.push_back({xyz.x(), xyz.y(), xyz.z()});
      }
      features[i]["geometry"]["coordinates"] = nlohmann::json::array({ring});
      body += (i > 0 ? ",\n" : "") + features[i].dump();
    }
    body += "\n]}\n";
    WriteFileAtomically(path, [&](std::ostream& stream) { stream << body; });
  }

  // GeoJSON 2008's named CRS: an OGC URN GDAL and PROJ read, compound CRSs
  // included; WKT for a CRS without a code.
  nlohmann::json CrsMember() const {
    std::string name = crs.wkt();
    const std::string& id = crs.identifier();
    const std::size_t colon = id.find(':');
    if (colon != std::string::npos) {
      const std::string authority = id.substr(0, colon);
      const std::string codes = id.substr(colon + 1);
      const std::size_t plus = codes.find('+');
      name = plus == std::string::npos
                 ? "urn:ogc:def:crs:" + authority + "::" + codes
                 : "urn:ogc:def:crs,crs:" + authority +
                       "::" + codes.substr(0, plus) + ",crs:" + authority +
                       "::" + codes.substr(plus + 1);
    }
    return {{"type", "name"}, {"properties", {{"name", name}}}};
  }
};

}  // namespace

int AddOutputCrs(const Survey& survey, const std::string& results_folder) {
  if (!survey.manifest.output_crs.is_set()) return 0;
  const CrsTransformer transformer = MakeSurveyCrsTransformer(
      survey.folder, survey.manifest, survey.manifest.output_crs, "output_crs");
  const CrsWriter writer{survey, transformer.crs(), transformer};
  const fs::path folder(results_folder);
  int rewritten = 0;
  auto lat_lon_h = [](const CsvTable& table, int row) {
    return Geodetic{table.GetDouble(row, "lat"), table.GetDouble(row, "lon"),
                    table.GetDouble(row, "h")};
  };
  for (const char* name : {kPosesFile, kTrajectoryCorrectedFile}) {
    const fs::path path = folder / name;
    if (!fs::exists(path)) continue;
    writer.AppendColumns(path.string(), name, {"lat", "lon", "h"}, lat_lon_h);
    ++rewritten;
  }

  const std::map<VertexKey, Geodetic> vertices =
      DatabaseVertices(survey.roadmarks);
  auto vertex_of = [&vertices](const CsvTable& table, int row,
                               const char* vertex_column) {
    const auto it =
        vertices.find({table.GetString(row, "crossing_id"),
                       static_cast<int>(table.GetInt(row, "band")),
                       static_cast<int>(table.GetInt(row, vertex_column))});
    if (it == vertices.end()) {
      table.Fail(row, "crossing " + table.GetString(row, "crossing_id") +
                          " band " + table.GetString(row, "band") +
                          " is not in the road-mark database");
    }
    return it->second;
  };
  const fs::path gcp_path = folder / kGcpResidualsFile;
  if (fs::exists(gcp_path)) {
    writer.AppendColumns(
        gcp_path.string(), kGcpResidualsFile,
        {"crossing_id", "band", "vertex", "de", "dn", "du"},
        [&](const CsvTable& table, int row) {
          const Eigen::Vector3d d_enu(table.GetDouble(row, "de"),
                                      table.GetDouble(row, "dn"),
                                      table.GetDouble(row, "du"));
          const Geodetic db = vertex_of(table, row, "vertex");
          return survey.frame.GeodeticFromEnu(survey.frame.EnuFromGeodetic(db) +
                                              d_enu);
        });
    ++rewritten;
  }
  const fs::path matches_path = folder / kMatchesFile;
  if (fs::exists(matches_path)) {
    writer.AppendColumns(matches_path.string(), kMatchesFile,
                         {"crossing_id", "band", "db_vertex"},
                         [&](const CsvTable& table, int row) {
                           return vertex_of(table, row, "db_vertex");
                         });
    ++rewritten;
  }
  const fs::path bands_path = folder / kBandsGeoJsonFile;
  if (fs::exists(bands_path)) {
    writer.RewriteBands(bands_path.string());
    ++rewritten;
  }
  LOG(INFO) << "output_crs: " << rewritten << " files with coordinates in "
            << transformer.crs().Description() << " ("
            << transformer.LastOperationName() << ")";
  return rewritten;
}

}  // namespace zebrageo
