// Results in the user's CRS (survey.yaml's `output_crs`, survey/crs.h).
//
// The contract's outputs keep their WGS84 and ENU columns, so every reader
// of SURVEY_FORMAT.md (and ../shared/tools/score_results.py) reads them
// unchanged; the output CRS is added beside them:
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

#include <string>

#include "survey/survey.h"

namespace zebrageo {

// Adds the output CRS to each of the files above present in
// `results_folder`, rewriting them atomically; does nothing when the
// survey has no output_crs. Idempotent: columns and comments of an earlier
// call are replaced. Returns the number of files rewritten. Throws
// InputError naming survey.yaml's output_crs line (unknown CRS, missing
// grid, a point PROJ cannot convert) or the output file and line (a
// control point that is not in the survey's database).
int AddOutputCrs(const Survey& survey, const std::string& results_folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_OUTPUT_CRS_H_
