#include "survey/roadmarks.h"

#include <simdjson.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "survey/atomic_file.h"
#include "survey/band_degeneracy.h"
#include "survey/csv.h"
#include "survey/geojson_internal.h"
#include "survey/input_error.h"
#include "survey/text_file.h"

namespace zebrageo {
namespace {

// A ring is closed when its last position repeats the first; writers that
// round through another unit may leave a last-digit difference.
constexpr double kClosureToleranceDeg = 1e-9;
constexpr double kClosureToleranceM = 1e-6;
// Road-line accuracy when the database does not give one.
constexpr double kDefaultLineSigmaXyM = 0.05;
constexpr double kDefaultLineSigmaZM = 0.10;

// JSON values as parsed by simdjson (DOM).
using Element = simdjson::dom::element;
using ElementType = simdjson::dom::element_type;

bool IsObject(const Element& e) { return e.type() == ElementType::OBJECT; }
bool IsArray(const Element& e) { return e.type() == ElementType::ARRAY; }
bool IsString(const Element& e) { return e.type() == ElementType::STRING; }
bool IsNull(const Element& e) { return e.type() == ElementType::NULL_VALUE; }
bool IsInteger(const Element& e) {
  return e.type() == ElementType::INT64 || e.type() == ElementType::UINT64;
}
bool IsNumber(const Element& e) {
  return IsInteger(e) || e.type() == ElementType::DOUBLE;
}
// Call only on objects and arrays (returned by value: the simdjson_result
// they come in is a temporary).
simdjson::dom::object ObjectOf(const Element& e) {
  return e.get_object().value_unsafe();
}
simdjson::dom::array ArrayOf(const Element& e) {
  return e.get_array().value_unsafe();
}
// Call only on numbers.
double NumberOf(const Element& e) { return e.get_double().value_unsafe(); }
// Call only on strings.
std::string StringOf(const Element& e) {
  return std::string(e.get_string().value_unsafe());
}
// The value as JSON text, for messages ("1.5", "\"a,b\"").
std::string Dump(const Element& e) { return simdjson::minify(e); }

// The member `key` of `object` (an OBJECT element), or false. With repeated
// keys the last one counts, as with nlohmann::json and most JSON readers.
bool Member(const Element& object, std::string_view key, Element* value) {
  bool found = false;
  for (const simdjson::dom::key_value_pair field : ObjectOf(object)) {
    if (field.key == key) {
      *value = field.value;
      found = true;
    }
  }
  return found;
}

// Reads one [lon, lat, h] position. Returns "" or the problem (the words of
// geojson_internal::ReadPosition).
std::string ReadPosition(const Element& position, Geodetic* geodetic) {
  if (!IsArray(position)) return "is not an array [lon, lat, h]";
  const simdjson::dom::array values = ArrayOf(position);
  const std::string size_problem =
      geojson_internal::PositionSizeProblem(values.size());
  if (!size_problem.empty()) return size_problem;
  double numbers[3];
  int k = 0;
  for (const Element value : values) {
    if (!IsNumber(value)) return "holds a value that is not a number";
    numbers[k++] = NumberOf(value);
  }
  return geojson_internal::CheckPosition(numbers, geodetic);
}

// (crossing_id, band) pairs, hashed: a city holds 100,000 bands.
struct BandKeyHash {
  size_t operator()(const std::pair<std::string, int>& key) const {
    return std::hash<std::string>()(key.first) * 31u +
           std::hash<int>()(key.second);
  }
};

// The parse runs on simdjson's DOM (a city-sized database is tens of MB:
// nlohmann::json's DOM took seconds); nlohmann::json only words syntax
// errors with their line, which simdjson does not give.
class RoadmarkParser {
 public:
  RoadmarkParser(const std::string& text, std::string display_name)
      : text_(text), display_name_(std::move(display_name)) {}

  RoadmarkDatabase Parse() {
    simdjson::dom::parser parser;
    // nlohmann::json accepts a UTF-8 byte order mark; simdjson leaves it to
    // the caller.
    const size_t skip = text_.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    Element root;
    const simdjson::error_code error =
        parser.parse(text_.data() + skip, text_.size() - skip).get(root);
    if (error != simdjson::SUCCESS) {
      // Throws the error with its line when nlohmann::json rejects the text
      // too; otherwise (a limit of simdjson's, e.g. an integer beyond 64
      // bits) says what simdjson found.
      geojson_internal::ParseJson(text_, display_name_);
      throw InputError(
          display_name_, 0,
          std::string("malformed JSON: ") + simdjson::error_message(error));
    }
    Element type;
    if (!IsObject(root) || !Member(root, "type", &type) || !IsString(type) ||
        StringOf(type) != "FeatureCollection") {
      throw InputError(display_name_, 1,
                       "not a GeoJSON FeatureCollection (\"type\": "
                       "\"FeatureCollection\" missing)");
    }
    CheckCrs(root);
    Element features;
    if (!Member(root, "features", &features) || !IsArray(features)) {
      throw InputError(display_name_, 1,
                       "FeatureCollection has no \"features\" array");
    }
    const simdjson::dom::array list = ArrayOf(features);
    database_.bands.reserve(list.size());
    band_of_key_.reserve(list.size());
    int index = 0;
    for (const Element feature : list) ParseFeature(feature, index++);
    return std::move(database_);
  }

 private:
  // RFC 7946 coordinates are WGS84 lon/lat; an old-style "crs" member naming
  // a projected system would put metres where degrees belong.
  void CheckCrs(const Element& root) const {
    Element crs;
    if (!Member(root, "crs", &crs) || IsNull(crs)) return;
    Element properties;
    Element name;
    const bool named = IsObject(crs) &&
                       Member(crs, "properties", &properties) &&
                       IsObject(properties) &&
                       Member(properties, "name", &name) && IsString(name);
    const std::string text = named ? StringOf(name) : "";
    for (const char* ok : {"CRS84", "4326", "4979", "CRS:84"}) {
      if (text.find(ok) != std::string::npos) return;
    }
    throw InputError(display_name_, 1,
                     "\"crs\" is '" + text +
                         "': coordinates must be WGS84 [lon, lat, h] "
                         "(RFC 7946); reproject the file");
  }

  // Lines are only needed for messages: the text is scanned for them then.
  int LineOfFeature(int index) const {
    if (feature_lines_.empty()) {
      feature_lines_ = geojson_internal::FeatureLines(text_);
    }
    return index < static_cast<int>(feature_lines_.size())
               ? feature_lines_[index]
               : 0;
  }

  // "feature 12 (crossing 'C3', band 2)": the 1-based feature number and
  // whatever identifies it, for messages.
  static std::string Describe(const Element& feature, int index) {
    std::string label = "feature " + std::to_string(index + 1);
    Element properties;
    if (!IsObject(feature) || !Member(feature, "properties", &properties) ||
        !IsObject(properties)) {
      return label;
    }
    std::string details;
    Element crossing;
    if (Member(properties, "crossing_id", &crossing) &&
        (IsString(crossing) || IsInteger(crossing))) {
      details = "crossing '" +
                (IsString(crossing) ? StringOf(crossing) : Dump(crossing)) +
                "'";
    }
    Element band;
    if (Member(properties, "band", &band) && IsNumber(band)) {
      details +=
          (details.empty() ? "" : ", ") + std::string("band ") + Dump(band);
    }
    Element type;
    if (details.empty() && Member(properties, "type", &type) &&
        IsString(type)) {
      details = "type '" + StringOf(type) + "'";
    }
    return details.empty() ? label : label + " (" + details + ")";
  }

  [[noreturn]] void Fail(const Element& feature, int index,
                         const std::string& problem) const {
    throw InputError(display_name_, LineOfFeature(index),
                     Describe(feature, index) + ": " + problem);
  }

  void ParseFeature(const Element& feature, int index) {
    if (!IsObject(feature)) Fail(feature, index, "is not a JSON object");
    Element geometry;
    // RFC 7946 allows unlocated features (geometry null): nothing to use.
    if (!Member(feature, "geometry", &geometry) || IsNull(geometry)) return;
    Element type_value;
    if (!IsObject(geometry) || !Member(geometry, "type", &type_value) ||
        !IsString(type_value)) {
      Fail(feature, index, "geometry has no \"type\"");
    }
    Element properties;
    const bool has_properties =
        Member(feature, "properties", &properties) && IsObject(properties);
    Element unused;
    auto has = [&](std::string_view key) {
      return has_properties && Member(properties, key, &unused);
    };
    const std::string type = StringOf(type_value);
    const bool has_band_properties = has("crossing_id") || has("band");
    if (type == "Polygon" || type == "MultiPolygon") {
      // A polygon with a road-mark "type" but no crossing (an arrow, a
      // painted island) is another road mark: ignored like other types.
      if (!has_band_properties && has("type")) return;
      ParseBand(feature, geometry, type == "MultiPolygon",
                has_properties ? &properties : nullptr, index);
    } else if (type == "LineString") {
      if (!has("type")) return;
      ParseLine(feature, geometry, properties, index);
    }
    // Points, MultiLineStrings...: not used.
  }

  simdjson::dom::array Coordinates(const Element& feature,
                                   const Element& geometry, int index) const {
    Element coordinates;
    if (!Member(geometry, "coordinates", &coordinates) ||
        !IsArray(coordinates)) {
      Fail(feature, index, "geometry has no \"coordinates\" array");
    }
    return ArrayOf(coordinates);
  }

  // `properties` may be null (no properties object).
  double Sigma(const Element& feature, const Element* properties,
               const char* key, int index, const double* default_value) const {
    Element value;
    if (properties == nullptr || !Member(*properties, key, &value) ||
        IsNull(value)) {
      if (default_value != nullptr) return *default_value;
      Fail(feature, index,
           std::string("missing property '") + key + "' (metres)");
    }
    if (!IsNumber(value)) {
      Fail(feature, index,
           std::string("property '") + key + "' is not a number");
    }
    const double sigma = NumberOf(value);
    if (!std::isfinite(sigma) || sigma < 0.0) {
      Fail(feature, index,
           std::string("property '") + key + "' = " + Dump(value) +
               ": must be a finite number >= 0");
    }
    return sigma;
  }

  void ParseBand(const Element& feature, const Element& geometry,
                 bool multi_polygon, const Element* properties, int index) {
    simdjson::dom::array polygon = Coordinates(feature, geometry, index);
    if (multi_polygon) {
      // GIS exports often promote polygons to one-part multipolygons.
      if (polygon.size() != 1) {
        Fail(feature, index,
             "a band must be one Polygon; this MultiPolygon has " +
                 std::to_string(polygon.size()) + " parts");
      }
      const Element part = polygon.at(0).value_unsafe();
      if (!IsArray(part)) Fail(feature, index, "malformed MultiPolygon");
      polygon = ArrayOf(part);
    }
    if (polygon.size() != 1) {
      Fail(feature, index,
           "polygon has " + std::to_string(polygon.size()) +
               " rings; a band has exactly one (no holes)");
    }
    const Element ring = polygon.at(0).value_unsafe();
    const size_t ring_size = IsArray(ring) ? ArrayOf(ring).size() : 0;
    if (!IsArray(ring) || ring_size != 5) {
      Fail(feature, index,
           "ring has " + (IsArray(ring) ? std::to_string(ring_size) : "no") +
               " positions; a band needs 5 (4 corners, then the first "
               "again)");
    }
    std::array<Geodetic, 5> positions;
    int k = 0;
    for (const Element position : ArrayOf(ring)) {
      const std::string problem = ReadPosition(position, &positions[k]);
      if (!problem.empty()) {
        Fail(feature, index, "position " + std::to_string(k) + " " + problem);
      }
      ++k;
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
    Element band_number;
    if (!Member(*properties, "band", &band_number) || IsNull(band_number)) {
      Fail(feature, index, "missing property 'band' (1-based integer)");
    }
    const double number = IsNumber(band_number) ? NumberOf(band_number) : 0.0;
    if (!IsNumber(band_number) || number != std::floor(number) ||
        number < 1.0 || number > 1e6) {
      Fail(feature, index,
           "property 'band' = " + Dump(band_number) +
               ": must be an integer >= 1");
    }
    band.band = static_cast<int>(number);
    band.sigma_xy_m = Sigma(feature, properties, "sigma_xy", index, nullptr);
    band.sigma_z_m = Sigma(feature, properties, "sigma_z", index, nullptr);

    const std::string degenerate = BandDegeneracy(band.corners);
    if (!degenerate.empty()) Fail(feature, index, degenerate);

    const auto [it, inserted] = band_of_key_.emplace(
        std::make_pair(band.crossing_id, band.band), index);
    if (!inserted) {
      Fail(feature, index,
           "duplicate band: crossing '" + band.crossing_id + "' band " +
               std::to_string(band.band) + " already appears on line " +
               std::to_string(LineOfFeature(it->second)));
    }
    database_.bands.push_back(std::move(band));
  }

  // `properties` may be null (no properties object).
  std::string CrossingId(const Element& feature, const Element* properties,
                         int index) const {
    Element value;
    if (properties == nullptr || !Member(*properties, "crossing_id", &value) ||
        IsNull(value)) {
      Fail(feature, index, "missing property 'crossing_id'");
    }
    std::string id;
    if (IsString(value)) {
      id = StringOf(value);
    } else if (IsInteger(value)) {
      // Some GIS tools write numeric ids; they name the same crossing.
      id = Dump(value);
    } else {
      Fail(feature, index,
           "property 'crossing_id' = " + Dump(value) +
               " is neither a string nor an integer");
    }
    // The id is written to matches.csv and crossing_decisions.csv.
    if (id.empty() || id.find_first_of(",\"\n\r") != std::string::npos ||
        id.front() == ' ' || id.back() == ' ') {
      Fail(feature, index,
           "property 'crossing_id' " + Dump(value) +
               " must be non-empty, without ',', '\"', line breaks or "
               "leading/trailing spaces (it is written to CSV files)");
    }
    return id;
  }

  void ParseLine(const Element& feature, const Element& geometry,
                 const Element& properties, int index) {
    const simdjson::dom::array coordinates =
        Coordinates(feature, geometry, index);
    if (coordinates.size() < 2) {
      Fail(feature, index, "a LineString needs at least 2 positions");
    }
    RoadmarkLine line;
    Element type;
    Member(properties, "type", &type);
    if (!IsString(type)) {
      Fail(feature, index, "property 'type' is not a string");
    }
    line.type = StringOf(type);
    Element id;
    const bool has_id = Member(properties, "id", &id);
    if (has_id && IsString(id)) {
      line.id = StringOf(id);
    } else if (has_id && IsInteger(id)) {
      line.id = Dump(id);
    } else {
      line.id = "line-" + std::to_string(database_.lines.size());
    }
    int k = 0;
    for (const Element position : coordinates) {
      Geodetic point;
      const std::string problem = ReadPosition(position, &point);
      if (!problem.empty()) {
        Fail(feature, index, "position " + std::to_string(k) + " " + problem);
      }
      line.points.push_back(point);
      ++k;
    }
    line.sigma_xy_m =
        Sigma(feature, &properties, "sigma_xy", index, &kDefaultLineSigmaXyM);
    line.sigma_z_m =
        Sigma(feature, &properties, "sigma_z", index, &kDefaultLineSigmaZM);
    database_.lines.push_back(std::move(line));
  }

  const std::string& text_;
  std::string display_name_;
  mutable std::vector<int> feature_lines_;
  // (crossing_id, band) -> index of the feature that has it.
  std::unordered_map<std::pair<std::string, int>, int, BandKeyHash>
      band_of_key_;
  RoadmarkDatabase database_;
};

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
  return ParseRoadmarks(ReadTextFile(path, display_name), display_name);
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
