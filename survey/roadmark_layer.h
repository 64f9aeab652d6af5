// A road-mark database read through GDAL/OGR: a GeoPackage, Shapefile,
// FlatGeobuf or GeoJSON layer in any CRS, or a PostGIS table ("PG:" source).
//
// Features as in roadmarks.geojson (survey/roadmarks.h): a Polygon (or a
// MultiPolygon of one polygon) per zebra band, its exterior ring's first 4
// positions being the corners; LineStrings with a `type` are road lines.
// Coordinates are converted from the layer's CRS (or `crs` when given) to
// WGS84 through PROJ (survey/crs.h). Attributes are found by name,
// case-insensitively, from the map of the options or from common names
// (RoadmarkFields). 2D polygons have no height: their corners get the
// height of the trajectory below the road (`height_guess`) and
// `sigma_z_without_height_m`, so the adjustment takes the bands' heights
// from the reconstruction, and `height_known` is false.
#ifndef ZEBRAGEO_SURVEY_ROADMARK_LAYER_H_
#define ZEBRAGEO_SURVEY_ROADMARK_LAYER_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "survey/crs.h"
#include "survey/roadmarks.h"

namespace zebrageo {

// Attribute names; empty: guessed from common names (case-insensitive).
struct RoadmarkFields {
  std::string crossing_id;  // crossing_id, crossing, crossing_i, zebra_id...
  std::string band;         // band, band_index, band_no, stripe...
  std::string sigma_xy;     // sigma_xy, accuracy_xy, acc_h...
  std::string sigma_z;      // sigma_z, accuracy_z, acc_v...
  std::string type;         // type, kind, class (road lines)
};

// A WGS84 box (degrees) of the area to read.
struct GeodeticBox {
  double south_deg = 0.0, west_deg = 0.0, north_deg = 0.0, east_deg = 0.0;
};

struct RoadmarkLayerOptions {
  // A file path or a GDAL connection string ("PG:dbname=... host=...").
  std::string source;
  // The layer (table) to read; empty: the source's only layer.
  std::string layer;
  // The CRS of the coordinates; empty: the layer's own (an error when the
  // layer has none).
  std::string crs;
  CrsOptions crs_options;
  RoadmarkFields fields;
  // Only features intersecting this box are read (pushed down to the
  // driver: PostGIS uses its spatial index). Unset: everything.
  std::optional<GeodeticBox> area;
  // Accuracy of a band whose layer has no sigma field (metres, per axis).
  double default_sigma_xy_m = 0.10;
  double default_sigma_z_m = 0.15;
  // Height sigma of a band from a 2D polygon: wide, so the adjustment takes
  // its height from the reconstruction.
  double sigma_z_without_height_m = 5.0;
  // Height (WGS84 ellipsoidal) of the road at a point, for 2D polygons
  // (e.g. from the trajectory). Null: 2D polygons are an error.
  std::function<double(double lat_deg, double lon_deg)> height_guess;

  std::string Check() const;
};

// Reads the layer. `display_name` names the source in messages (a PG:
// string's password is never printed). Throws InputError: a source GDAL
// cannot open, no such layer, a layer with several and none named, no CRS,
// a missing attribute, a feature that is no band (its FID and problem),
// two bands with the same (crossing_id, band), a point PROJ cannot convert.
RoadmarkDatabase ReadRoadmarkLayer(const RoadmarkLayerOptions& options,
                                   const std::string& display_name);

// The box around WGS84 positions, widened by `margin_m` on every side.
GeodeticBox BoxAround(const std::vector<Geodetic>& positions, double margin_m);

// A PG: connection string with its password replaced by "***".
std::string RedactedSource(const std::string& source);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_ROADMARK_LAYER_H_
