#include "survey/roadmark_layer.h"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include <GeographicLib/Geodesic.hpp>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <utility>

#include "survey/band_degeneracy.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

constexpr double kMetresPerDegreeLat = 111320.0;
// A layer whose features all lie farther than this (m) from the survey's
// area is another place's, or read in the wrong CRS (the contract's
// GeoJSON: PlausibilityOptions::max_database_distance_m).
constexpr double kMaxOutsideDistanceM = 5e3;
// Road lines without their own accuracy (as the GeoJSON reader).
constexpr double kDefaultLineSigmaXyM = 0.05;
constexpr double kDefaultLineSigmaZM = 0.10;

std::string Lower(std::string text) {
  for (char& c : text)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// GDAL's messages go to the InputError, not to stderr.
class QuietGdal {
 public:
  QuietGdal() {
    static std::once_flag registered;
    std::call_once(registered, [] { GDALAllRegister(); });
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

std::string LastGdalError() {
  const char* message = CPLGetLastErrorMsg();
  return message == nullptr || *message == '\0' ? "no reason given" : message;
}

// Geodesic distance on the WGS84 ellipsoid (m).
double GeodesicDistanceM(const Geodetic& a, const Geodetic& b) {
  double s12 = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(a.lat_deg, a.lon_deg, b.lat_deg,
                                           b.lon_deg, s12);
  return s12;
}

// What the file itself shows when GDAL says nothing (a file no driver
// recognises): empty, or not the SQLite file a GeoPackage is.
std::string FileEvidence(const std::string& source) {
  std::error_code error;
  if (source.rfind("PG:", 0) == 0 ||
      !std::filesystem::is_regular_file(source, error)) {
    return "";
  }
  const auto size = std::filesystem::file_size(source, error);
  if (error) return "";
  if (size == 0) return " (the file is empty: 0 bytes)";
  const std::string extension =
      Lower(std::filesystem::path(source).extension().string());
  if (extension == ".gpkg") {
    char header[16] = {};
    std::ifstream(source, std::ios::binary).read(header, sizeof(header));
    if (std::string(header, sizeof(header)) !=
        std::string("SQLite format 3\0", 16)) {
      return " (" + std::to_string(size) +
             " bytes that do not start with the SQLite header a GeoPackage "
             "starts with: not a GeoPackage, or a damaged one)";
    }
    return " (" + std::to_string(size) +
           " bytes with a SQLite header: a damaged or truncated GeoPackage?)";
  }
  return " (" + std::to_string(size) + " bytes)";
}

// The index of the field named `wanted`, or guessed from `guesses` when
// `wanted` is empty; -1 when absent. Case-insensitive.
int FieldIndex(OGRFeatureDefn* definition, const std::string& wanted,
               const std::vector<std::string>& guesses) {
  std::vector<std::string> names;
  for (int i = 0; i < definition->GetFieldCount(); ++i) {
    names.push_back(Lower(definition->GetFieldDefn(i)->GetNameRef()));
  }
  const std::vector<std::string> candidates =
      wanted.empty() ? guesses : std::vector<std::string>{wanted};
  for (const std::string& candidate : candidates) {
    const auto it = std::find(names.begin(), names.end(), Lower(candidate));
    if (it != names.end()) return static_cast<int>(it - names.begin());
  }
  return -1;
}

struct FieldIndices {
  int crossing_id = -1, band = -1, sigma_xy = -1, sigma_z = -1, type = -1,
      id = -1;
};

std::string FieldList(OGRFeatureDefn* definition) {
  std::string list;
  for (int i = 0; i < definition->GetFieldCount(); ++i) {
    list += (i > 0 ? ", " : "") +
            std::string(definition->GetFieldDefn(i)->GetNameRef());
  }
  return list.empty() ? "none" : list;
}

FieldIndices FindFields(OGRFeatureDefn* definition,
                        const RoadmarkFields& fields,
                        const std::string& where) {
  FieldIndices indices;
  // Shapefile truncates names to 10 characters (crossing_id: crossing_i).
  indices.crossing_id =
      FieldIndex(definition, fields.crossing_id,
                 {"crossing_id", "crossing_i", "crossingid", "crossing",
                  "cross_id", "zebra_id", "zebra", "xing_id", "group_id"});
  indices.band =
      FieldIndex(definition, fields.band,
                 {"band", "band_index", "band_indx", "band_no", "band_nr",
                  "band_num", "stripe", "stripe_no", "stripe_index", "bar"});
  indices.sigma_xy = FieldIndex(
      definition, fields.sigma_xy,
      {"sigma_xy", "sigma_h", "accuracy_xy", "accuracy_h", "acc_xy", "acc_h",
       "sd_xy", "std_xy", "horizontal_accuracy", "horiz_acc"});
  indices.sigma_z =
      FieldIndex(definition, fields.sigma_z,
                 {"sigma_z", "sigma_v", "accuracy_z", "accuracy_v", "acc_z",
                  "acc_v", "sd_z", "std_z", "vertical_accuracy", "vert_acc"});
  indices.type = FieldIndex(definition, fields.type, {"type", "kind", "class"});
  indices.id = FieldIndex(definition, "", {"id", "line_id", "fid_"});
  const std::pair<const std::string*, int> named[] = {
      {&fields.crossing_id, indices.crossing_id},
      {&fields.band, indices.band},
      {&fields.sigma_xy, indices.sigma_xy},
      {&fields.sigma_z, indices.sigma_z},
      {&fields.type, indices.type}};
  for (const auto& [name, index] : named) {
    if (!name->empty() && index < 0) {
      throw InputError(
          where, 0,
          "the layer has no attribute '" + *name +
              "' (roadmarks_fields); its attributes: " + FieldList(definition));
    }
  }
  if (indices.crossing_id < 0 || indices.band < 0) {
    throw InputError(where, 0,
                     "cannot tell which attributes hold the crossing id and "
                     "the band (looked for crossing_id, crossing, ... and "
                     "band, band_index, ...); name them in survey.yaml's "
                     "roadmarks_fields; the layer's attributes: " +
                         FieldList(definition));
  }
  return indices;
}

// The layer's CRS as WKT2 (PROJ reads it into a Crs), or "".
std::string LayerCrsWkt(OGRLayer* layer) {
  const OGRSpatialReference* srs = layer->GetSpatialRef();
  if (srs == nullptr) return "";
  char* wkt = nullptr;
  const char* const options[] = {"FORMAT=WKT2_2019", nullptr};
  if (srs->exportToWkt(&wkt, options) != OGRERR_NONE || wkt == nullptr) {
    CPLFree(wkt);
    return "";
  }
  std::string text = wkt;
  CPLFree(wkt);
  return text;
}

// The layer's coordinates of `area`: its outline sampled and transformed
// (a projection bends the box's edges), bounded.
OGREnvelope LayerEnvelope(const GeodeticBox& area,
                          const CrsTransformer& transformer) {
  OGREnvelope envelope;
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    const double u = static_cast<double>(i) / kSteps;
    const double lat = area.south_deg + u * (area.north_deg - area.south_deg);
    const double lon = area.west_deg + u * (area.east_deg - area.west_deg);
    for (const Geodetic& g :
         {Geodetic{lat, area.west_deg, 0.0}, Geodetic{lat, area.east_deg, 0.0},
          Geodetic{area.south_deg, lon, 0.0},
          Geodetic{area.north_deg, lon, 0.0}}) {
      const Eigen::Vector3d xyz = transformer.FromWgs84(g);
      envelope.Merge(xyz.x(), xyz.y());
    }
  }
  return envelope;
}

// Twice the signed area of the corners' ring, in a local plane (east,
// north metres): > 0 counter-clockwise seen from above.
double SignedArea(const std::array<Geodetic, 4>& corners) {
  const double scale = std::cos(corners[0].lat_deg * kPi / 180.0);
  double area = 0.0;
  for (int k = 0; k < 4; ++k) {
    const Geodetic& a = corners[k];
    const Geodetic& b = corners[(k + 1) % 4];
    const double ax = (a.lon_deg - corners[0].lon_deg) * scale;
    const double ay = a.lat_deg - corners[0].lat_deg;
    const double bx = (b.lon_deg - corners[0].lon_deg) * scale;
    const double by = b.lat_deg - corners[0].lat_deg;
    area += ax * by - bx * ay;
  }
  return area;
}

class LayerReader {
 public:
  LayerReader(const RoadmarkLayerOptions& options, std::string where,
              OGRLayer* layer, CrsTransformer transformer)
      : options_(options),
        where_(std::move(where)),
        layer_(layer),
        transformer_(std::move(transformer)) {}

  RoadmarkDatabase Read() {
    OGRFeatureDefn* definition = layer_->GetLayerDefn();
    fields_ = FindFields(definition, options_.fields, where_);
    if (options_.area) {
      const OGREnvelope box = LayerEnvelope(*options_.area, transformer_);
      layer_->SetSpatialFilterRect(box.MinX, box.MinY, box.MaxX, box.MaxY);
    }
    layer_->ResetReading();
    RoadmarkDatabase database;
    std::set<std::pair<std::string, int>> seen;
    std::map<std::string, int> other_types;  // geometry name -> features
    for (auto& feature : *layer_) {
      const OGRGeometry* geometry = feature->GetGeometryRef();
      if (geometry == nullptr) continue;
      const OGRwkbGeometryType type = wkbFlatten(geometry->getGeometryType());
      if (type != wkbPolygon && type != wkbMultiPolygon &&
          type != wkbLineString) {
        ++other_types[OGRGeometryTypeToName(type)];
      }
      if (type == wkbPolygon || type == wkbMultiPolygon) {
        RoadmarkBand band = ReadBand(*feature, *geometry);
        if (!seen.insert({band.crossing_id, band.band}).second) {
          Fail(*feature, "crossing_id '" + band.crossing_id + "' band " +
                             std::to_string(band.band) +
                             " appears twice in the layer");
        }
        database.bands.push_back(std::move(band));
      } else if (type == wkbLineString && fields_.type >= 0 &&
                 feature->IsFieldSetAndNotNull(fields_.type)) {
        database.lines.push_back(ReadLine(*feature, *geometry->toLineString(),
                                          database.lines.size()));
      }
    }
    if (database.bands.empty() && database.lines.empty()) {
      FailOnOtherGeometries(other_types);
      if (options_.area) LookOutsideArea();
    }
    return database;
  }

 private:
  [[noreturn]] void Fail(const OGRFeature& feature,
                         const std::string& problem) const {
    throw InputError(where_, 0,
                     "feature " + std::to_string(feature.GetFID()) +
                         " of layer " + layer_->GetName() + ": " + problem);
  }

  // A layer of points (or other geometries) and no band: the wrong layer
  // or a conversion that kept the bands' centres.
  void FailOnOtherGeometries(const std::map<std::string, int>& types) const {
    if (types.empty()) return;
    std::string found;
    for (const auto& [name, count] : types) {
      found += (found.empty() ? "" : ", ") + std::to_string(count) + " " +
               name + (count > 1 ? " features" : " feature");
    }
    throw InputError(
        where_, 0,
        std::string("layer ") + layer_->GetName() + " holds " + found +
            " and no zebra band: a band is a Polygon (or a MultiPolygon of "
            "one polygon) whose ring holds its 4 corners, a road line a "
            "LineString with a type (../shared/SURVEY_FORMAT.md, "
            "roadmarks.geojson); name the layer of band polygons in "
            "survey.yaml's roadmarks_layer, or export the bands' outlines "
            "rather than their centres");
  }

  // Nothing in the area though the layer holds features: where are they?
  // A layer far from the survey (its coordinates read in the wrong CRS,
  // degrees as metres) is an error, as for the contract's GeoJSON
  // (survey/plausibility.h): nothing in it can control the trajectory.
  void LookOutsideArea() const {
    constexpr int kMaxFeatures = 200;
    layer_->SetSpatialFilter(nullptr);
    layer_->ResetReading();
    const GeodeticBox& area = *options_.area;
    const Geodetic centre{0.5 * (area.south_deg + area.north_deg),
                          0.5 * (area.west_deg + area.east_deg), 0.0};
    double min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY,
           max_y = -INFINITY, nearest_m = INFINITY;
    Geodetic nearest;
    int features = 0;
    for (auto& feature : *layer_) {
      if (features++ >= kMaxFeatures) break;
      const OGRGeometry* geometry = feature->GetGeometryRef();
      if (geometry == nullptr) continue;
      OGREnvelope box;
      geometry->getEnvelope(&box);
      if (!std::isfinite(box.MinX) || !std::isfinite(box.MinY)) continue;
      min_x = std::min(min_x, box.MinX), max_x = std::max(max_x, box.MaxX);
      min_y = std::min(min_y, box.MinY), max_y = std::max(max_y, box.MaxY);
      try {
        const Geodetic g =
            transformer_.ToWgs84(Eigen::Vector3d(box.MinX, box.MinY, 0.0));
        const double d = GeodesicDistanceM(centre, g);
        if (d < nearest_m) nearest_m = d, nearest = g;
      } catch (const CrsError&) {
        // Outside the CRS's domain: far from anything, say the raw figures.
      }
    }
    if (features == 0 || !std::isfinite(min_x)) return;
    if (nearest_m <= kMaxOutsideDistanceM) return;  // not the survey's area
    const Crs& crs = transformer_.crs();
    std::string problem =
        std::string("none of the features of layer ") + layer_->GetName() +
        " lies within roadmarks_margin_m of the trajectory: its coordinates "
        "(x " +
        FormatDouble(min_x) + " to " + FormatDouble(max_x) + ", y " +
        FormatDouble(min_y) + " to " + FormatDouble(max_y) + "), read in " +
        crs.name() +
        (std::isfinite(nearest_m)
             ? ", put it at lat " + FormatFixed(nearest.lat_deg, 4) + ", lon " +
                   FormatFixed(nearest.lon_deg, 4) + ", " +
                   FormatFixed(nearest_m / 1000.0, 0) +
                   " km from the trajectory"
             : ", are outside that CRS's domain") +
        "; nothing in it can control the trajectory";
    if (!crs.is_geographic() && min_x >= -180.0 && max_x <= 180.0 &&
        min_y >= -90.0 && max_y <= 90.0) {
      problem +=
          ": they look like longitude and latitude in degrees, read as " +
          crs.horizontal_unit() + " of a projection; " +
          (options_.crs.empty()
               ? std::string("name their CRS (EPSG:4326) in survey.yaml's "
                             "roadmarks_crs")
               : std::string("survey.yaml's roadmarks_crs names " +
                             options_.crs +
                             ": remove it, or name the CRS the coordinates "
                             "are in (EPSG:4326)"));
    }
    throw InputError(where_, 0, problem);
  }

  double Sigma(const OGRFeature& feature, int index, double fallback,
               const char* what) const {
    if (index < 0 || !feature.IsFieldSetAndNotNull(index)) return fallback;
    const double sigma = feature.GetFieldAsDouble(index);
    if (!std::isfinite(sigma) || sigma < 0.0) {
      Fail(feature, std::string(what) + " " + FormatDouble(sigma) +
                        " is not a finite non-negative number of metres");
    }
    return sigma;
  }

  Geodetic ToWgs84(const OGRFeature& feature, const OGRPoint& point,
                   bool has_z) const {
    const Eigen::Vector3d xyz(point.getX(), point.getY(),
                              has_z ? point.getZ() : 0.0);
    if (!xyz.allFinite()) Fail(feature, "a coordinate is not finite");
    try {
      Geodetic g = transformer_.ToWgs84(xyz);
      if (!has_z) g.h_m = options_.height_guess(g.lat_deg, g.lon_deg);
      return g;
    } catch (const CrsError& error) {
      Fail(feature, error.what());
    }
  }

  RoadmarkBand ReadBand(const OGRFeature& feature,
                        const OGRGeometry& geometry) const {
    const OGRPolygon* polygon = nullptr;
    if (wkbFlatten(geometry.getGeometryType()) == wkbMultiPolygon) {
      const OGRMultiPolygon* multi = geometry.toMultiPolygon();
      if (multi->getNumGeometries() != 1) {
        Fail(feature, "a MultiPolygon of " +
                          std::to_string(multi->getNumGeometries()) +
                          " polygons is not one band");
      }
      polygon = multi->getGeometryRef(0);
    } else {
      polygon = geometry.toPolygon();
    }
    const OGRLinearRing* ring = polygon->getExteriorRing();
    const int n = ring == nullptr ? 0 : ring->getNumPoints();
    if (n != 5 && n != 4) {
      Fail(feature,
           "a band's ring must hold its 4 corners (then the first "
           "again), not " +
               std::to_string(n) + " positions");
    }
    const bool has_z = geometry.Is3D();
    if (!has_z && !options_.height_guess) {
      Fail(feature, "a 2D polygon and no height to give it");
    }
    RoadmarkBand band;
    for (int k = 0; k < 4; ++k) {
      OGRPoint point;
      ring->getPoint(k, &point);
      band.corners[k] = ToWgs84(feature, point, has_z);
    }
    // The contract's order: counter-clockwise seen from above, first corner
    // kept (a Shapefile stores exterior rings clockwise, so a round trip
    // through one reverses them).
    if (SignedArea(band.corners) < 0.0)
      std::swap(band.corners[1], band.corners[3]);
    const std::string problem = BandDegeneracy(band.corners);
    if (!problem.empty()) Fail(feature, problem);
    band.crossing_id = feature.GetFieldAsString(fields_.crossing_id);
    if (!feature.IsFieldSetAndNotNull(fields_.crossing_id) ||
        band.crossing_id.empty()) {
      Fail(feature, "no crossing id");
    }
    if (!feature.IsFieldSetAndNotNull(fields_.band)) Fail(feature, "no band");
    const double band_number = feature.GetFieldAsDouble(fields_.band);
    if (band_number != std::floor(band_number) || band_number < 1 ||
        band_number > 1e6) {
      Fail(feature, "band '" +
                        std::string(feature.GetFieldAsString(fields_.band)) +
                        "' is not an integer >= 1");
    }
    band.band = static_cast<int>(band_number);
    band.sigma_xy_m = Sigma(feature, fields_.sigma_xy,
                            options_.default_sigma_xy_m, "sigma_xy");
    band.sigma_z_m =
        Sigma(feature, fields_.sigma_z, options_.default_sigma_z_m, "sigma_z");
    band.height_known = has_z;
    if (!has_z) band.sigma_z_m = options_.sigma_z_without_height_m;
    return band;
  }

  RoadmarkLine ReadLine(const OGRFeature& feature, const OGRLineString& line,
                        std::size_t index) const {
    RoadmarkLine result;
    result.type = feature.GetFieldAsString(fields_.type);
    result.id = fields_.id >= 0 && feature.IsFieldSetAndNotNull(fields_.id)
                    ? feature.GetFieldAsString(fields_.id)
                    : "line-" + std::to_string(index);
    const bool has_z = line.Is3D();
    if (!has_z && !options_.height_guess) {
      Fail(feature, "a 2D line and no height to give it");
    }
    for (int i = 0; i < line.getNumPoints(); ++i) {
      OGRPoint point;
      line.getPoint(i, &point);
      result.points.push_back(ToWgs84(feature, point, has_z));
    }
    result.sigma_xy_m =
        Sigma(feature, fields_.sigma_xy, kDefaultLineSigmaXyM, "sigma_xy");
    result.sigma_z_m =
        has_z ? Sigma(feature, fields_.sigma_z, kDefaultLineSigmaZM, "sigma_z")
              : options_.sigma_z_without_height_m;
    return result;
  }

  const RoadmarkLayerOptions& options_;
  std::string where_;
  OGRLayer* layer_;
  CrsTransformer transformer_;
  FieldIndices fields_;
};

OGRLayer* ChooseLayer(GDALDataset* dataset, const std::string& name,
                      const std::string& where) {
  if (!name.empty()) {
    OGRLayer* layer = dataset->GetLayerByName(name.c_str());
    if (layer == nullptr) {
      throw InputError(where, 0, "no layer (table) '" + name + "'");
    }
    return layer;
  }
  const int count = dataset->GetLayerCount();
  if (count == 1) return dataset->GetLayer(0);
  std::string names;
  for (int i = 0; i < count && i < 20; ++i) {
    names += (i > 0 ? ", " : "") + std::string(dataset->GetLayer(i)->GetName());
  }
  throw InputError(where, 0,
                   std::to_string(count) +
                       " layers and none named: name one in survey.yaml's "
                       "roadmarks_layer (" +
                       (names.empty() ? "none" : names) + ")");
}

}  // namespace

std::string RoadmarkLayerOptions::Check() const {
  OptionCheck check;
  check.Require(!source.empty(), "source", std::string("\"\""),
                "must not be empty");
  OPTION_GT(check, default_sigma_xy_m, 0.0);
  OPTION_GT(check, default_sigma_z_m, 0.0);
  OPTION_GT(check, sigma_z_without_height_m, 0.0);
  OPTION_NESTED(check, crs_options);
  return check.problem();
}

std::string RedactedSource(const std::string& source) {
  static const std::regex kPassword(R"((password\s*=\s*)('[^']*'|\S+))",
                                    std::regex::icase);
  return std::regex_replace(source, kPassword, "$1***");
}

GeodeticBox BoxAround(const std::vector<Geodetic>& positions, double margin_m) {
  GeodeticBox box{90.0, 180.0, -90.0, -180.0};
  for (const Geodetic& g : positions) {
    box.south_deg = std::min(box.south_deg, g.lat_deg);
    box.north_deg = std::max(box.north_deg, g.lat_deg);
    box.west_deg = std::min(box.west_deg, g.lon_deg);
    box.east_deg = std::max(box.east_deg, g.lon_deg);
  }
  const double mid_lat = 0.5 * (box.south_deg + box.north_deg);
  const double dlat = margin_m / kMetresPerDegreeLat;
  const double dlon =
      margin_m /
      (kMetresPerDegreeLat * std::max(std::cos(mid_lat * kPi / 180.0), 1e-3));
  box.south_deg = std::max(-90.0, box.south_deg - dlat);
  box.north_deg = std::min(90.0, box.north_deg + dlat);
  box.west_deg = std::max(-180.0, box.west_deg - dlon);
  box.east_deg = std::min(180.0, box.east_deg + dlon);
  return box;
}

RoadmarkDatabase ReadRoadmarkLayer(const RoadmarkLayerOptions& options,
                                   const std::string& display_name) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("RoadmarkLayerOptions: " + problem);
  }
  const std::string where = RedactedSource(display_name);
  QuietGdal quiet;
  const char* const drivers[] = {
      "GPKG", "ESRI Shapefile", "FlatGeobuf",  "GeoJSON", "PostgreSQL", "GML",
      "KML",  "SQLite",         "OpenFileGDB", "CSV",     nullptr};
  GDALDatasetUniquePtr dataset(GDALDataset::Open(
      options.source.c_str(),
      GDAL_OF_VECTOR | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, drivers,
      nullptr, nullptr));
  if (!dataset) {
    throw InputError(where, 0,
                     "GDAL cannot open it as a vector source: GDAL says \"" +
                         RedactedSource(LastGdalError()) + "\"" +
                         FileEvidence(options.source));
  }
  OGRLayer* layer = ChooseLayer(dataset.get(), options.layer, where);
  std::string crs_definition = options.crs;
  if (crs_definition.empty()) crs_definition = LayerCrsWkt(layer);
  if (crs_definition.empty()) {
    throw InputError(where, 0,
                     std::string("layer ") + layer->GetName() +
                         " has no CRS (a Shapefile without its .prj?): name "
                         "it with roadmarks_crs in survey.yaml");
  }
  std::optional<CrsTransformer> transformer;
  try {
    transformer.emplace(Crs(crs_definition), options.crs_options);
  } catch (const CrsError& error) {
    throw InputError(where, 0,
                     std::string("the CRS of layer ") + layer->GetName() +
                         ": " + error.what());
  }
  LayerReader reader(options, where, layer, std::move(*transformer));
  return reader.Read();
}

}  // namespace zebrageo
