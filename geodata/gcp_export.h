// The matched band vertices as ground control points, with their image
// observations, for photogrammetry suites.
//
// A ground control point is a vertex of the road-mark database (crossing,
// band, db_vertex) that the adjustment used: its coordinates are the
// database's (the control), its observations are the reconstructed band
// vertices matched to it (matches.csv -> reconstructed_bands.csv: the left
// and right images of the stereo pair at that exposure, pixel positions in
// the original distorted image, pixel (0, 0) the centre of the top-left
// pixel, as OpenCV and OpenSfM count), its role and residual come from
// gcp_residuals.csv (control or check; adjusted minus database, ENU m).
//
// Formats (each header of geodata/gcp_export.cc quotes its specification):
//  - OpenDroneMap gcp_list.txt: a CRS line, then "geo_x geo_y geo_z im_x im_y
//    image_name gcp_name" per observation.
//  - OpenSfM ground_control_points.json: {"points": [{"id", "position":
//    {"latitude", "longitude", "altitude"}, "observations": [{"shot_id",
//    "projection": [x, y]}]}]}, projections in OpenSfM's normalised image
//    coordinates ((pixel + 0.5 - size / 2) / max(width, height)); plus a
//    "role" key per point, which OpenSfM ignores.
//  - Metashape reference CSV (File > Import Reference): label, x, y, z,
//    accuracies, enabled (1 control, 0 check), and the marker projections
//    beside it.
//  - GeoPackage (GDAL/OGR) of control and check points with residuals, for
//    QGIS (geodata/gcp_geopackage.cc).
#ifndef ZEBRAGEO_GEODATA_GCP_EXPORT_H_
#define ZEBRAGEO_GEODATA_GCP_EXPORT_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "survey/results.h"
#include "survey/survey.h"

namespace zebrageo {

struct GcpObservation {
  int64_t exposure_id = 0;
  std::string camera;
  std::string image;       // as exposures.csv names it (relative)
  std::string image_name;  // what the export writes (see GcpExportOptions)
  int width = 0;
  int height = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // pixels, distorted image
};

struct GroundControlPoint {
  std::string name;  // "<crossing_id>/<band>/<db_vertex>"
  std::string crossing_id;
  int band = 0;
  int db_vertex = 0;
  Geodetic position;  // the database's vertex, WGS84
  double sigma_xy_m = 0.0;
  double sigma_z_m = 0.0;
  GcpRole role = GcpRole::kControl;
  // From gcp_residuals.csv (absent when the folder has none).
  bool has_residual = false;
  Eigen::Vector3d d_enu_m = Eigen::Vector3d::Zero();
  double rms_px = 0.0;
  std::vector<GcpObservation> observations;
};

enum class GcpImageNames {
  kBaseName,  // "12_left.png": ODM and OpenSfM keep images in one folder
  kPath,      // "images/12_left.png", as exposures.csv names it
};

struct GcpExportOptions {
  GcpImageNames image_names = GcpImageNames::kBaseName;
  // Which points go out: the control points only, or the check points too
  // (OpenSfM and ODM would use a check point as control: they are left out
  // of their files unless asked for).
  bool include_check_points = false;

  std::string Check() const { return ""; }
};

// Collects the points from a survey (its database and exposures) and a
// results folder (matches.csv, reconstructed_bands.csv, gcp_residuals.csv
// if present). Throws InputError naming the file and line of a match whose
// reconstructed vertex or database vertex does not exist, or two images of
// different folders that share a base name.
std::vector<GroundControlPoint> CollectGroundControlPoints(
    const Survey& survey, const std::string& results_folder,
    const GcpExportOptions& options);

// How a point's WGS84 position is written: the header line naming the CRS
// (gcp_list.txt's first line) and the transformation to (x, y, z) in it.
struct GcpCoordinateSystem {
  std::string header;  // "WGS84 UTM 32N", "EPSG:2154", "+proj=...", "WGS84"
  std::function<Eigen::Vector3d(const Geodetic&)> from_wgs84;
  // The CRS named for people and Metashape, a compound one too:
  // "EPSG:2154+5720 (RGF93 v1 / Lambert-93 + NGF-IGN69 height)".
  std::string name;
};
// Longitude, latitude (degrees), ellipsoidal height: "EPSG:4326" (ODM
// reads x, y as longitude, latitude).
GcpCoordinateSystem Wgs84GcpCoordinates();

// The coordinates of an export: the system and, for the GeoPackage, the
// spatial reference GDAL is given.
struct GcpCoordinates {
  GcpCoordinateSystem system;
  std::string srs_definition;  // "EPSG:4979" for WGS84
};
// For `definition`: "" (WGS84), "utm" (the WGS84 UTM zone of `near`, header
// "WGS84 UTM 32N", EPSG:326zz/327zz), or any CRS PROJ knows (survey/crs.h:
// EPSG code, compound code with a geoid, PROJ string, WKT), transformed by
// PROJ. The header is the CRS as gcp_list.txt names one: "EPSG:<code>" or
// the PROJ string given; "" when ODM cannot name it (a compound CRS: ODM's
// reader takes one EPSG code). Throws CrsError (unknown CRS, missing grid).
GcpCoordinates GcpCoordinatesFor(
    const std::string& definition, const Geodetic& near,
    const std::vector<std::string>& grid_dirs = {});

// Writers (atomic). `gcps` are written in order, observations in order.
void WriteOdmGcpList(const std::vector<GroundControlPoint>& gcps,
                     const GcpCoordinateSystem& crs, const std::string& path);
void WriteOpenSfmGroundControlPoints(
    const std::vector<GroundControlPoint>& gcps, const std::string& path);
// `path` gets the reference (label,x,y,z,accuracies,enabled); the
// projections go to `projections_path` (marker,image,x,y).
void WriteMetashapeMarkers(const std::vector<GroundControlPoint>& gcps,
                           const GcpCoordinateSystem& crs,
                           const std::string& path,
                           const std::string& projections_path);
// A GeoPackage with one PointZ layer "ground_control_points" (WGS84,
// EPSG:4979, or `srs_wkt` with coordinates from `crs`).
void WriteGcpGeoPackage(const std::vector<GroundControlPoint>& gcps,
                        const GcpCoordinateSystem& crs,
                        const std::string& srs_definition,
                        const std::string& path);

// OpenSfM's normalised image coordinates of pixel `uv` (OpenSfM
// features.normalized_image_coordinates).
Eigen::Vector2d OpenSfmNormalized(const Eigen::Vector2d& uv, int width,
                                  int height);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_GCP_EXPORT_H_
