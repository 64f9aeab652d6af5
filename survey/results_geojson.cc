// bands.geojson of the results contract (survey/results.h).
#include <fstream>
#include <sstream>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/geojson_internal.h"
#include "survey/input_error.h"
#include "survey/output_crs.h"
#include "survey/results.h"
#include "survey/text_file.h"

namespace zebrageo {
namespace {

using nlohmann::json;

}  // namespace

// ---------------------------------------------------------------------------
// bands.geojson

void WriteAdjustedBands(const std::vector<AdjustedBand>& bands,
                        const std::string& path, const OutputCrs* crs) {
  using geojson_internal::JsonString;
  using geojson_internal::PositionText;
  // One feature per line, like roadmarks.geojson.
  std::string body =
      crs == nullptr ? "{\"type\": \"FeatureCollection\", \"features\": [\n"
                     : "{\"type\": \"FeatureCollection\", \"crs\": " +
                           crs->GeoJsonMember().dump() + ", \"features\": [\n";
  for (size_t i = 0; i < bands.size(); ++i) {
    const AdjustedBand& band = bands[i];
    std::string ring;
    for (int k = 0; k <= 4; ++k) {
      ring += (k > 0 ? ", " : "") + PositionText(band.corners[k % 4]);
    }
    std::string feature =
        "{\"type\": \"Feature\", \"geometry\": {\"type\": \"Polygon\", "
        "\"coordinates\": [[" +
        ring + "]]}, \"properties\": {\"crossing_id\": " +
        (band.crossing_id ? JsonString(*band.crossing_id) : "null") +
        ", \"band\": " + (band.band ? std::to_string(*band.band) : "null") +
        ", \"band_id\": " + std::to_string(band.band_id) +
        ", \"exposure_id\": " + std::to_string(band.exposure_id) + "}}";
    if (crs != nullptr) {
      // In the output CRS (GeoJSON 2008): the feature as nlohmann writes it.
      json f = json::parse(feature);
      json xyz_ring = json::array();
      for (int k = 0; k <= 4; ++k) {
        const Eigen::Vector3d xyz = crs->FromWgs84(band.corners[k % 4]);
        xyz_ring.push_back({xyz.x(), xyz.y(), xyz.z()});
      }
      f["geometry"]["coordinates"] = json::array({xyz_ring});
      feature = f.dump();
    }
    body += std::string(i > 0 ? ",\n" : "") + feature;
  }
  body += "\n]}\n";
  AtomicFile file(path);
  file.stream() << body;
  file.Commit();
}

std::vector<AdjustedBand> ReadAdjustedBands(const std::string& path,
                                            const std::string& display_name) {
  const std::string text = ReadTextFile(path, display_name);
  const json root = geojson_internal::ParseJson(text, display_name);
  if (!root.is_object() || !root.contains("type") ||
      root["type"] != "FeatureCollection" || !root.contains("features") ||
      !root["features"].is_array()) {
    throw InputError(display_name, 1, "not a GeoJSON FeatureCollection");
  }
  const std::vector<int> lines = geojson_internal::FeatureLines(text);
  const json& features = root["features"];
  std::vector<AdjustedBand> bands;
  for (size_t i = 0; i < features.size(); ++i) {
    auto fail = [&](const std::string& problem) {
      throw InputError(display_name, i < lines.size() ? lines[i] : 0,
                       "feature " + std::to_string(i + 1) + ": " + problem);
    };
    const json& feature = features[i];
    if (!feature.is_object() || !feature.contains("geometry") ||
        !feature["geometry"].is_object() ||
        !feature["geometry"].contains("type") ||
        feature["geometry"]["type"] != "Polygon" ||
        !feature["geometry"].contains("coordinates")) {
      fail("expected a Polygon feature");
    }
    const json& rings = feature["geometry"]["coordinates"];
    if (!rings.is_array() || rings.size() != 1 || !rings[0].is_array() ||
        rings[0].size() != 5) {
      fail("expected one ring of 5 positions");
    }
    AdjustedBand band;
    Geodetic last;
    for (int k = 0; k < 5; ++k) {
      const std::string problem = geojson_internal::ReadPosition(
          rings[0][k], k < 4 ? &band.corners[k] : &last);
      if (!problem.empty())
        fail("position " + std::to_string(k) + " " + problem);
    }
    if (last.lat_deg != band.corners[0].lat_deg ||
        last.lon_deg != band.corners[0].lon_deg ||
        last.h_m != band.corners[0].h_m) {
      fail("ring is not closed");
    }
    if (!feature.contains("properties") || !feature["properties"].is_object()) {
      fail("no properties");
    }
    const json& properties = feature["properties"];
    for (const char* key : {"crossing_id", "band", "band_id", "exposure_id"}) {
      if (!properties.contains(key)) {
        fail(std::string("missing property '") + key + "'");
      }
    }
    const json& crossing_id = properties["crossing_id"];
    if (crossing_id.is_string()) {
      band.crossing_id = crossing_id.get<std::string>();
    } else if (!crossing_id.is_null()) {
      fail("property 'crossing_id' must be a string or null");
    }
    const json& band_number = properties["band"];
    if (band_number.is_number_integer()) {
      band.band = band_number.get<int>();
    } else if (!band_number.is_null()) {
      fail("property 'band' must be an integer or null");
    }
    if (!properties["band_id"].is_number_integer() ||
        !properties["exposure_id"].is_number_integer()) {
      fail("properties 'band_id' and 'exposure_id' must be integers");
    }
    band.band_id = properties["band_id"].get<int64_t>();
    band.exposure_id = properties["exposure_id"].get<int64_t>();
    bands.push_back(std::move(band));
  }
  return bands;
}

}  // namespace zebrageo
