#include "survey/roadmarks.h"

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/geojson_internal.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

using nlohmann::json;

// A ring is closed when its last position repeats the first; writers that
// round through another unit may leave a last-digit difference.
constexpr double kClosureToleranceDeg = 1e-9;
constexpr double kClosureToleranceM = 1e-6;
// Degenerate bands: corners closer than this (horizontally) are repeated,
// and a band smaller than this is no band (a real one is >= 1 m^2).
constexpr double kRepeatedCornerM = 1e-3;
constexpr double kMinBandAreaM2 = 0.01;
// Road-line accuracy when the database does not give one.
constexpr double kDefaultLineSigmaXyM = 0.05;
constexpr double kDefaultLineSigmaZM = 0.10;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Sign of the turn a -> b -> c: +1 left, -1 right, 0 collinear.
int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  const double cross = Cross(b - a, c - a);
  return (cross > 0.0) - (cross < 0.0);
}

bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
               const Eigen::Vector2d& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
         p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y());
}

// True when closed segments ab and cd share a point (touching counts).
bool SegmentsIntersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                       const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const int o1 = Orientation(a, b, c);
  const int o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a);
  const int o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

// "" or why the band's four corners make no usable polygon. Computed in a
// tangent plane at the first corner, in metres: degrees are not isotropic.
std::string DegeneracyOf(const std::array<Geodetic, 4>& corners) {
  const LocalFrame frame(corners[0]);
  std::array<Eigen::Vector2d, 4> p;
  for (int i = 0; i < 4; ++i) {
    p[i] = frame.EnuFromGeodetic(corners[i]).head<2>();
  }
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if ((p[i] - p[j]).norm() < kRepeatedCornerM) {
        return "degenerate band: corners " + std::to_string(i) + " and " +
               std::to_string(j) + " are the same point";
      }
    }
  }
  // In a quadrilateral only opposite edges can cross.
  if (SegmentsIntersect(p[0], p[1], p[2], p[3]) ||
      SegmentsIntersect(p[1], p[2], p[3], p[0])) {
    return "degenerate band: the ring is self-intersecting (corners not in "
           "order around the band)";
  }
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) twice_area += Cross(p[i], p[(i + 1) % 4]);
  const double area = std::abs(twice_area) / 2.0;
  if (area < kMinBandAreaM2) {
    std::ostringstream problem;
    problem << "degenerate band: area " << area << " m^2 is about zero";
    return problem.str();
  }
  return "";
}

class RoadmarkParser {
 public:
  RoadmarkParser(const std::string& text, std::string display_name)
      : text_(text), display_name_(std::move(display_name)) {}

  RoadmarkDatabase Parse() {
    const json root = geojson_internal::ParseJson(text_, display_name_);
    if (!root.is_object() || !root.contains("type") ||
        root["type"] != "FeatureCollection") {
      throw InputError(display_name_, 1,
                       "not a GeoJSON FeatureCollection (\"type\": "
                       "\"FeatureCollection\" missing)");
    }
    CheckCrs(root);
    const auto features = root.find("features");
    if (features == root.end() || !features->is_array()) {
      throw InputError(display_name_, 1,
                       "FeatureCollection has no \"features\" array");
    }
    feature_lines_ = geojson_internal::FeatureLines(text_);
    for (size_t i = 0; i < features->size(); ++i) {
      ParseFeature((*features)[i], static_cast<int>(i));
    }
    return std::move(database_);
  }

 private:
  // RFC 7946 coordinates are WGS84 lon/lat; an old-style "crs" member naming
  // a projected system would put metres where degrees belong.
  void CheckCrs(const json& root) const {
    const auto crs = root.find("crs");
    if (crs == root.end() || crs->is_null()) return;
    const json* name = nullptr;
    if (crs->is_object() && crs->contains("properties") &&
        (*crs)["properties"].is_object() &&
        (*crs)["properties"].contains("name")) {
      name = &(*crs)["properties"]["name"];
    }
    const std::string text =
        name != nullptr && name->is_string() ? name->get<std::string>() : "";
    for (const char* ok : {"CRS84", "4326", "4979", "CRS:84"}) {
      if (text.find(ok) != std::string::npos) return;
    }
    throw InputError(display_name_, 1,
                     "\"crs\" is '" + text +
                         "': coordinates must be WGS84 [lon, lat, h] "
                         "(RFC 7946); reproject the file");
  }

  int LineOfFeature(int index) const {
    return index < static_cast<int>(feature_lines_.size())
               ? feature_lines_[index]
               : 0;
  }

  // "feature 12 (crossing 'C3', band 2)": the 1-based feature number and
  // whatever identifies it, for messages.
  static std::string Describe(const json& feature, int index) {
    std::string label = "feature " + std::to_string(index + 1);
    if (!feature.is_object() || !feature.contains("properties") ||
        !feature["properties"].is_object()) {
      return label;
    }
    const json& properties = feature["properties"];
    std::string details;
    const auto crossing = properties.find("crossing_id");
    if (crossing != properties.end() &&
        (crossing->is_string() || crossing->is_number_integer())) {
      details = "crossing '" +
                (crossing->is_string() ? crossing->get<std::string>()
                                       : crossing->dump()) +
                "'";
    }
    const auto band = properties.find("band");
    if (band != properties.end() && band->is_number()) {
      details +=
          (details.empty() ? "" : ", ") + std::string("band ") + band->dump();
    }
    const auto type = properties.find("type");
    if (details.empty() && type != properties.end() && type->is_string()) {
      details = "type '" + type->get<std::string>() + "'";
    }
    return details.empty() ? label : label + " (" + details + ")";
  }

  [[noreturn]] void Fail(const json& feature, int index,
                         const std::string& problem) const {
    throw InputError(display_name_, LineOfFeature(index),
                     Describe(feature, index) + ": " + problem);
  }

  void ParseFeature(const json& feature, int index) {
    if (!feature.is_object()) Fail(feature, index, "is not a JSON object");
    const auto geometry = feature.find("geometry");
    // RFC 7946 allows unlocated features (geometry null): nothing to use.
    if (geometry == feature.end() || geometry->is_null()) return;
    if (!geometry->is_object() || !geometry->contains("type") ||
        !(*geometry)["type"].is_string()) {
      Fail(feature, index, "geometry has no \"type\"");
    }
    const json empty = json::object();
    const json& properties =
        feature.contains("properties") && feature["properties"].is_object()
            ? feature["properties"]
            : empty;
    const std::string type = (*geometry)["type"].get<std::string>();
    const bool has_band_properties =
        properties.contains("crossing_id") || properties.contains("band");
    if (type == "Polygon" || type == "MultiPolygon") {
      // A polygon with a road-mark "type" but no crossing (an arrow, a
      // painted island) is another road mark: ignored like other types.
      if (!has_band_properties && properties.contains("type")) return;
      ParseBand(feature, *geometry, properties, index);
    } else if (type == "LineString") {
      if (!properties.contains("type")) return;
      ParseLine(feature, *geometry, properties, index);
    }
    // Points, MultiLineStrings...: not used.
  }

  const json& Coordinates(const json& feature, const json& geometry,
                          int index) const {
    const auto coordinates = geometry.find("coordinates");
    if (coordinates == geometry.end() || !coordinates->is_array()) {
      Fail(feature, index, "geometry has no \"coordinates\" array");
    }
    return *coordinates;
  }

  double Sigma(const json& feature, const json& properties, const char* key,
               int index, const double* default_value) const {
    const auto it = properties.find(key);
    if (it == properties.end() || it->is_null()) {
      if (default_value != nullptr) return *default_value;
      Fail(feature, index,
           std::string("missing property '") + key + "' (metres)");
    }
    if (!it->is_number()) {
      Fail(feature, index,
           std::string("property '") + key + "' is not a number");
    }
    const double value = it->get<double>();
    if (!std::isfinite(value) || value < 0.0) {
      Fail(feature, index,
           std::string("property '") + key + "' = " + it->dump() +
               ": must be a finite number >= 0");
    }
    return value;
  }

  void ParseBand(const json& feature, const json& geometry,
                 const json& properties, int index) {
    const json* polygon = &Coordinates(feature, geometry, index);
    if (geometry["type"] == "MultiPolygon") {
      // GIS exports often promote polygons to one-part multipolygons.
      if (polygon->size() != 1) {
        Fail(feature, index,
             "a band must be one Polygon; this MultiPolygon has " +
                 std::to_string(polygon->size()) + " parts");
      }
      polygon = &(*polygon)[0];
      if (!polygon->is_array()) Fail(feature, index, "malformed MultiPolygon");
    }
    if (polygon->size() != 1) {
      Fail(feature, index,
           "polygon has " + std::to_string(polygon->size()) +
               " rings; a band has exactly one (no holes)");
    }
    const json& ring = (*polygon)[0];
    if (!ring.is_array() || ring.size() != 5) {
      Fail(feature, index,
           "ring has " +
               (ring.is_array() ? std::to_string(ring.size()) : "no") +
               " positions; a band needs 5 (4 corners, then the first "
               "again)");
    }
    std::array<Geodetic, 5> positions;
    for (int k = 0; k < 5; ++k) {
      const std::string problem =
          geojson_internal::ReadPosition(ring[k], &positions[k]);
      if (!problem.empty()) {
        Fail(feature, index, "position " + std::to_string(k) + " " + problem);
      }
    }
    if (std::abs(positions[4].lon_deg - positions[0].lon_deg) >
            kClosureToleranceDeg ||
        std::abs(positions[4].lat_deg - positions[0].lat_deg) >
            kClosureToleranceDeg ||
        std::abs(positions[4].h_m - positions[0].h_m) > kClosureToleranceM) {
      Fail(feature, index,
           "ring is not closed (its 5th position must repeat the first)");
    }
    RoadmarkBand band;
    std::copy(positions.begin(), positions.begin() + 4, band.corners.begin());

    band.crossing_id = CrossingId(feature, properties, index);
    const auto band_number = properties.find("band");
    if (band_number == properties.end() || band_number->is_null()) {
      Fail(feature, index, "missing property 'band' (1-based integer)");
    }
    if (!band_number->is_number() ||
        band_number->get<double>() != std::floor(band_number->get<double>()) ||
        band_number->get<double>() < 1.0 || band_number->get<double>() > 1e6) {
      Fail(feature, index,
           "property 'band' = " + band_number->dump() +
               ": must be an integer >= 1");
    }
    band.band = static_cast<int>(band_number->get<double>());
    band.sigma_xy_m = Sigma(feature, properties, "sigma_xy", index, nullptr);
    band.sigma_z_m = Sigma(feature, properties, "sigma_z", index, nullptr);

    const std::string degenerate = DegeneracyOf(band.corners);
    if (!degenerate.empty()) Fail(feature, index, degenerate);

    const auto key = std::make_pair(band.crossing_id, band.band);
    const auto [it, inserted] =
        line_of_band_.emplace(key, LineOfFeature(index));
    if (!inserted) {
      Fail(feature, index,
           "duplicate band: crossing '" + band.crossing_id + "' band " +
               std::to_string(band.band) + " already appears on line " +
               std::to_string(it->second));
    }
    database_.bands.push_back(std::move(band));
  }

  std::string CrossingId(const json& feature, const json& properties,
                         int index) const {
    const auto it = properties.find("crossing_id");
    if (it == properties.end() || it->is_null()) {
      Fail(feature, index, "missing property 'crossing_id'");
    }
    std::string id;
    if (it->is_string()) {
      id = it->get<std::string>();
    } else if (it->is_number_integer()) {
      // Some GIS tools write numeric ids; they name the same crossing.
      id = it->dump();
    } else {
      Fail(feature, index,
           "property 'crossing_id' = " + it->dump() +
               " is neither a string nor an integer");
    }
    // The id is written to matches.csv and crossing_decisions.csv.
    if (id.empty() || id.find_first_of(",\"\n\r") != std::string::npos ||
        id.front() == ' ' || id.back() == ' ') {
      Fail(feature, index,
           "property 'crossing_id' " + it->dump() +
               " must be non-empty, without ',', '\"', line breaks or "
               "leading/trailing spaces (it is written to CSV files)");
    }
    return id;
  }

  void ParseLine(const json& feature, const json& geometry,
                 const json& properties, int index) {
    const json& coordinates = Coordinates(feature, geometry, index);
    if (coordinates.size() < 2) {
      Fail(feature, index, "a LineString needs at least 2 positions");
    }
    RoadmarkLine line;
    const json& type = properties["type"];
    if (!type.is_string()) {
      Fail(feature, index, "property 'type' is not a string");
    }
    line.type = type.get<std::string>();
    const auto id = properties.find("id");
    if (id != properties.end() && id->is_string()) {
      line.id = id->get<std::string>();
    } else if (id != properties.end() && id->is_number_integer()) {
      line.id = id->dump();
    } else {
      line.id = "line-" + std::to_string(database_.lines.size());
    }
    for (size_t k = 0; k < coordinates.size(); ++k) {
      Geodetic point;
      const std::string problem =
          geojson_internal::ReadPosition(coordinates[k], &point);
      if (!problem.empty()) {
        Fail(feature, index, "position " + std::to_string(k) + " " + problem);
      }
      line.points.push_back(point);
    }
    line.sigma_xy_m =
        Sigma(feature, properties, "sigma_xy", index, &kDefaultLineSigmaXyM);
    line.sigma_z_m =
        Sigma(feature, properties, "sigma_z", index, &kDefaultLineSigmaZM);
    database_.lines.push_back(std::move(line));
  }

  const std::string& text_;
  std::string display_name_;
  std::vector<int> feature_lines_;
  std::map<std::pair<std::string, int>, int> line_of_band_;
  RoadmarkDatabase database_;
};

std::string ReadWholeFile(const std::string& path,
                          const std::string& display_name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(display_name, 0, "cannot open " + path);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(display_name, 0, "cannot read " + path);
  return text.str();
}

std::string SigmaText(double sigma) {
  if (!std::isfinite(sigma) || sigma < 0.0) {
    throw std::invalid_argument("WriteRoadmarks: sigma must be finite, >= 0");
  }
  return FormatDouble(sigma);
}

}  // namespace

RoadmarkDatabase ParseRoadmarks(const std::string& text,
                                const std::string& display_name) {
  return RoadmarkParser(text, display_name).Parse();
}

RoadmarkDatabase ReadRoadmarks(const std::string& path,
                               const std::string& display_name) {
  return ParseRoadmarks(ReadWholeFile(path, display_name), display_name);
}

void WriteRoadmarks(const RoadmarkDatabase& database, const std::string& path) {
  using geojson_internal::JsonString;
  using geojson_internal::PositionText;
  // Built as text rather than through nlohmann::json so each feature sits on
  // its own line: a reader's error message then points at the feature.
  std::string body = "{\"type\": \"FeatureCollection\", \"features\": [\n";
  bool first = true;
  auto separator = [&first]() {
    const char* text = first ? "" : ",\n";
    first = false;
    return text;
  };
  for (const RoadmarkBand& band : database.bands) {
    std::string ring;
    for (int k = 0; k <= 4; ++k) {
      ring += (k > 0 ? ", " : "") + PositionText(band.corners[k % 4]);
    }
    body += std::string(separator()) +
            "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
            "\"coordinates\": [[" +
            ring + "]]}, \"properties\": {\"crossing_id\": " +
            JsonString(band.crossing_id) +
            ", \"band\": " + std::to_string(band.band) +
            ", \"sigma_xy\": " + SigmaText(band.sigma_xy_m) +
            ", \"sigma_z\": " + SigmaText(band.sigma_z_m) + "}}";
  }
  for (const RoadmarkLine& line : database.lines) {
    std::string points;
    for (size_t k = 0; k < line.points.size(); ++k) {
      points += (k > 0 ? ", " : "") + PositionText(line.points[k]);
    }
    body += std::string(separator()) +
            "{\"type\": \"Feature\", \"geometry\": {\"type\": "
            "\"LineString\", \"coordinates\": [" +
            points + "]}, \"properties\": {\"id\": " + JsonString(line.id) +
            ", \"type\": " + JsonString(line.type) +
            ", \"sigma_xy\": " + SigmaText(line.sigma_xy_m) +
            ", \"sigma_z\": " + SigmaText(line.sigma_z_m) + "}}";
  }
  body += "\n]}\n";
  AtomicFile file(path);
  file.stream() << body;
  file.Commit();
}

}  // namespace zebrageo
