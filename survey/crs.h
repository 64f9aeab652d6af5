// Coordinate reference systems through PROJ: a CRS the user names (EPSG
// code, compound code such as "EPSG:2154+5720", PROJ string, WKT, PROJJSON)
// and the transformation between it and the contract's WGS84 (EPSG:4979:
// latitude, longitude, ellipsoidal height).
//
// Coordinates of a CRS (`Eigen::Vector3d xyz`) are in its own units, in
// "east, north, up" order whatever the CRS's official axis order (PROJ's
// normalisation for visualisation): easting, northing for a projected CRS,
// longitude, latitude (degrees) for a geographic one, then the height: the
// CRS's vertical axis (orthometric for a compound CRS with a geoid, in the
// vertical unit), or the ellipsoidal height in metres for a CRS without one.
// WGS84 positions are the survey's `Geodetic` (degrees, as in every file).
//
// A transformation never falls back silently: PROJ's "ballpark" operations
// (a datum shift or a geoid ignored) are refused, so a compound CRS whose
// geoid grid is not installed is an error naming the grid and where PROJ
// looked, never an ellipsoidal height passed off as an orthometric one.
#ifndef ZEBRAGEO_SURVEY_CRS_H_
#define ZEBRAGEO_SURVEY_CRS_H_

#include <Eigen/Core>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "survey/geodesy.h"

namespace zebrageo {

// An unknown or unusable CRS, a missing grid, a point outside every
// available operation's area. The message names the CRS (and the grid); the
// caller adds the file and line where the CRS was given.
class CrsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CrsOptions {
  // Folders searched for grids (geoid models, datum shifts) before PROJ's
  // own search path (PROJ_DATA, /usr/share/proj where Debian's proj-data
  // installs them). Default: none.
  std::vector<std::string> grid_dirs;

  std::string Check() const;
};

// A CRS, parsed and validated by PROJ. Cheap to copy (shared, immutable).
class Crs {
 public:
  // Throws CrsError when PROJ does not know `definition` or it is not a CRS.
  explicit Crs(const std::string& definition);

  // The text the user gave.
  const std::string& definition() const { return definition_; }
  // PROJ's name, e.g. "RGF93 v1 / Lambert-93 + NGF-IGN69 height".
  const std::string& name() const { return name_; }
  // "AUTH:CODE" when the CRS is one of a database (a compound CRS built
  // from codes gives "EPSG:2154+5720"), else "".
  const std::string& identifier() const { return identifier_; }
  // WKT2:2019 on one line, for file headers.
  const std::string& wkt() const { return wkt_; }
  // x, y are longitude, latitude in degrees.
  bool is_geographic() const { return is_geographic_; }
  // The height is the CRS's vertical axis (else ellipsoidal, metres).
  bool has_vertical() const { return has_vertical_; }
  // Unit names of x/y and of the height, e.g. "metre", "degree", "US survey
  // foot".
  const std::string& horizontal_unit() const { return horizontal_unit_; }
  const std::string& vertical_unit() const { return vertical_unit_; }
  // One line for a file header: "<name> [<identifier>]; x,y: <unit>;
  // height: <vertical name or 'ellipsoidal (WGS84)'>".
  std::string Description() const;

 private:
  std::string definition_;
  std::string name_;
  std::string identifier_;
  std::string wkt_;
  bool is_geographic_ = false;
  bool has_vertical_ = false;
  std::string horizontal_unit_;
  std::string vertical_unit_;
  std::string vertical_name_;
};

// Transforms between WGS84 (EPSG:4979) and one CRS. Holds its own PROJ
// context: a transformer is used by one thread at a time (make one per
// thread). Movable, not copyable.
class CrsTransformer {
 public:
  // Finds PROJ's candidate operations (best first) and keeps those that can
  // run (their grids are found) and are not ballpark. Throws CrsError when
  // none is left, naming the grids that are missing.
  explicit CrsTransformer(const Crs& crs,
                          const CrsOptions& options = CrsOptions());
  ~CrsTransformer();
  CrsTransformer(CrsTransformer&&) noexcept;
  CrsTransformer& operator=(CrsTransformer&&) noexcept;

  const Crs& crs() const;

  // WGS84 -> the CRS (coordinates as in the header comment). Throws
  // CrsError when no usable operation covers the point (a grid that covers
  // it is missing) or PROJ fails.
  Eigen::Vector3d FromWgs84(const Geodetic& wgs84) const;
  // The CRS -> WGS84.
  Geodetic ToWgs84(const Eigen::Vector3d& xyz) const;

  // The operation last used, e.g. "Inverse of RGF93 v1 to WGS 84 (1) +
  // Lambert-93", for logs and reports.
  std::string LastOperationName() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// True for an empty definition or one PROJ identifies as EPSG:4979 (the
// contract's CRS, for which no transformation is made).
bool IsContractCrs(const std::string& definition);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_CRS_H_
