// A survey folder (SURVEY_FORMAT.md): the manifest and everything it names,
// loaded and validated.
#ifndef ZEBRAGEO_SURVEY_SURVEY_H_
#define ZEBRAGEO_SURVEY_SURVEY_H_

#include <optional>
#include <string>
#include <vector>

#include "survey/crs.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/plausibility.h"
#include "survey/rig.h"
#include "survey/roadmark_layer.h"
#include "survey/roadmarks.h"
#include "survey/survey_paths.h"
#include "survey/trajectory.h"

namespace zebrageo {

// A CRS named in survey.yaml, with its line for messages.
struct SurveyCrs {
  std::string definition;  // empty: WGS84 as in the contract
  int line = 0;
  bool is_set() const { return !definition.empty(); }
};

struct SurveyManifest {
  std::string name;
  std::string rig = "rig.yaml";  // paths relative to the survey folder
  std::string trajectory = "trajectory.csv";
  std::string exposures = "exposures.csv";
  std::string roadmarks = "roadmarks.geojson";
  std::optional<Geodetic> origin;  // default: the first trajectory sample
  int origin_line = 0;             // in survey.yaml, for messages

  // Optional CRSs (survey/crs.h: an EPSG code, "EPSG:2154+5720", a PROJ
  // string, WKT). Empty: the contract's WGS84 (lat, lon, ellipsoidal h),
  // and every file exactly as SURVEY_FORMAT.md says.
  SurveyCrs roadmarks_crs;   // of the road-mark database's coordinates
  SurveyCrs trajectory_crs;  // of trajectory.csv (columns x, y, z)
  SurveyCrs output_crs;      // added to every output carrying coordinates
  // Folders (relative to the survey folder) searched for geoid and datum
  // grids before PROJ's own; `crs_grid_dirs` in survey.yaml.
  std::vector<std::string> crs_grid_dirs;
  // A road-mark layer read through GDAL/OGR (survey/roadmark_layer.h):
  // `roadmarks` may then be any vector file or a "PG:..." connection.
  std::string roadmarks_layer;        // the layer or table; "": the only one
  RoadmarkFields roadmarks_fields;    // attribute names; "": guessed
  double roadmarks_margin_m = 200.0;  // read only around the trajectory

  // Whether the database is read through GDAL (anything but a plain
  // GeoJSON of the contract).
  bool RoadmarksThroughGdal() const;
};

// Reads survey.yaml (a leading UTF-8 byte-order mark is allowed). Throws
// InputError for malformed YAML, a key given twice, a missing key, an
// origin that is not 3 finite numbers, or a named file that does not exist,
// is a folder, a loop of symbolic links or not a regular file, or (unless
// `paths.allow_outside_paths`) is absolute or resolves outside the survey
// folder (survey/survey_paths.h).
SurveyManifest ReadManifest(const std::string& survey_folder,
                            const SurveyPathOptions& paths = {});
void WriteManifest(const SurveyManifest& manifest, const std::string& path);

struct SurveyLoadOptions {
  // Load roadmarks.geojson (match and adjust need it; reconstruct does not).
  bool load_roadmarks = true;
  // Share of images that may be missing before the survey is rejected; a few
  // missing images only produce warnings (SURVEY_FORMAT.md).
  double max_missing_image_fraction = 0.2;
  // Whether the images are needed. adjust works on the geometry alone (its
  // images only feed tie points): then any share may be missing and a
  // stereo pair need not have an exposure with both images.
  bool require_images = true;
  // Confinement of the files the survey names to its folder.
  SurveyPathOptions paths;
  // Checks of a valid survey against physics and itself (gaps, rates,
  // angle units, distances), run last.
  PlausibilityOptions plausibility;

  std::string Check() const;
};

struct Survey {
  std::string folder;
  SurveyManifest manifest;
  Rig rig;
  LocalFrame frame{Geodetic{}};
  Trajectory trajectory;
  ExposureTable exposures;
  RoadmarkDatabase roadmarks;
  // Problems that do not stop processing (missing images...), for report.json.
  std::vector<std::string> warnings;
  // How the files it names were confined (later readers do the same).
  SurveyPathOptions paths;

  // Absolute path of a file named relative to the survey folder.
  std::string PathOf(const std::string& relative) const;
};

// The grid folders of survey.yaml (`crs_grid_dirs`), as absolute paths, for
// CrsTransformer.
CrsOptions SurveyCrsOptions(const std::string& survey_folder,
                            const SurveyManifest& manifest);

// The transformer of a CRS named in survey.yaml. Throws InputError naming
// survey.yaml, the key's line and PROJ's problem (an unknown CRS, a missing
// grid).
CrsTransformer MakeSurveyCrsTransformer(const std::string& survey_folder,
                                        const SurveyManifest& manifest,
                                        const SurveyCrs& crs,
                                        const std::string& key);

// The survey's trajectory in WGS84: trajectory.csv as the contract says,
// or, with `trajectory_crs`, its x, y, z columns converted (every stage
// reads the trajectory through this).
std::vector<TrajectorySample> ReadSurveyTrajectory(
    const std::string& survey_folder, const SurveyManifest& manifest);

// The survey's road-mark database in WGS84 (every stage reads it through
// this): the contract's GeoJSON reader for a plain survey; a layer read
// through GDAL/OGR (survey/roadmark_layer.h) when the manifest names a
// CRS, a layer or attribute map, or a file or PG: source that is not
// GeoJSON. `trajectory` bounds what is read from a large table.
RoadmarkDatabase ReadSurveyRoadmarks(
    const std::string& survey_folder, const SurveyManifest& manifest,
    const std::vector<TrajectorySample>& trajectory);

// Loads and cross-validates a survey. Throws InputError: everything the
// individual readers reject, plus exposures outside the trajectory's time
// span, an image path that is absolute or resolves outside the survey folder
// (unless allowed), too many missing images (a folder, a loop of symbolic
// links or a device in an image's place counts as missing, with its own
// message), a rig without stereo pairs, a stereo pair none of whose
// exposures has both images, and what CheckPlausibility refuses; its
// warnings go to `warnings`. Throws std::invalid_argument when
// `options.Check()` fails.
Survey LoadSurvey(const std::string& folder,
                  const SurveyLoadOptions& options = SurveyLoadOptions());

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_SURVEY_H_
