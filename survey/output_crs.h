// Results in the user's CRS (survey.yaml's `output_crs`, survey/crs.h).
//
// The contract's outputs keep their WGS84 and ENU columns, so every reader
// of SURVEY_FORMAT.md (and ../shared/tools/score_results.py) reads them
// unchanged; their writers (survey/results.h, survey/trajectory.h) add the
// output CRS beside them when given one:
//   poses.csv, trajectory_corrected.csv  columns crs_x, crs_y, crs_z: the
//       row's lat, lon, h in the output CRS;
//   gcp_residuals.csv  crs_x, crs_y, crs_z: the adjusted position of the
//       control point (the database vertex plus de, dn, du);
//   matches.csv        crs_x, crs_y, crs_z: the matched database vertex;
//   bands.geojson      coordinates in the output CRS with a top-level "crs"
//       member (GeoJSON 2008, which GDAL reads: RFC 7946 allows WGS84 only,
//       so this file leaves the RFC when output_crs is set).
// Each CSV names the CRS in `#` comment lines before its header:
//   # output_crs: EPSG:2154+5720
//   # crs_x,crs_y,crs_z: RGF93 v1 / Lambert-93 + NGF-IGN69 height [...]
//   # output_crs_wkt: COMPOUNDCRS[...]
// x, y, z are in the CRS's units and east-first order (survey/crs.h). The
// camera rotation stays camera-to-ENU (true north, not grid north).
#ifndef ZEBRAGEO_SURVEY_OUTPUT_CRS_H_
#define ZEBRAGEO_SURVEY_OUTPUT_CRS_H_

#include <Eigen/Core>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/geodesy.h"

namespace zebrageo {

struct Survey;

class OutputCrs {
 public:
  // Null when the survey has no output_crs. Throws InputError naming
  // survey.yaml's output_crs line (unknown CRS, missing grid).
  static std::unique_ptr<OutputCrs> Of(const Survey& survey);

  // The three comment lines naming the CRS, and crs_x, crs_y, crs_z after
  // `columns`, before a CSV's header.
  void AddHeader(CsvWriter* csv, std::vector<std::string>* columns) const;
  // The row's crs_x, crs_y, crs_z of a WGS84 position. Throws InputError
  // naming survey.yaml's output_crs line when PROJ cannot convert it.
  void AddColumns(const Geodetic& wgs84, CsvWriter* csv) const;
  Eigen::Vector3d FromWgs84(const Geodetic& wgs84) const;
  // A database vertex (crossing_id, band, db_vertex) in WGS84; InputError
  // naming `file` when the survey's database lacks it.
  Geodetic DatabaseVertex(const std::string& crossing_id, int band, int vertex,
                          const std::string& file) const;
  // The survey's ENU frame (gcp_residuals.csv's d_enu from the vertex).
  const LocalFrame& frame() const { return frame_; }
  // bands.geojson's "crs" member (GeoJSON 2008's named CRS).
  nlohmann::json GeoJsonMember() const;
  std::string Description() const;

 private:
  OutputCrs(CrsTransformer transformer, int line, LocalFrame frame);

  CrsTransformer transformer_;
  int line_;  // survey.yaml's output_crs line
  LocalFrame frame_;
  std::map<std::tuple<std::string, int, int>, Geodetic> vertices_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_OUTPUT_CRS_H_
