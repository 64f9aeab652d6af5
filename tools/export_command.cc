// `zebrageo export-gcp SURVEY RESULTS --format F -o FILE`: the matched band
// vertices as ground control points for ODM, OpenSfM, Metashape or QGIS.
// The collection and the formats live in geodata/gcp_export.h.
#include <glog/logging.h>

#include <filesystem>
#include <memory>
#include <string>

#include "geodata/gcp_export.h"
#include "pipeline/exit_codes.h"
#include "survey/crs.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/file_arguments.h"

namespace zebrageo {
namespace {

struct ExportArguments {
  std::string survey;
  std::string results;
  std::string format;
  std::string output;
  std::string crs;
  std::vector<std::string> grid_dirs;
  bool include_check_points = false;
  bool image_paths = false;
  bool allow_outside_paths = false;
};

void RunExportGcp(const ExportArguments& args) {
  if (!std::filesystem::is_directory(args.results)) {
    throw UsageError(args.results + " is not a results folder");
  }
  SurveyLoadOptions load;
  load.require_images = false;
  load.paths.allow_outside_paths = args.allow_outside_paths;
  const Survey survey = LoadSurvey(args.survey, load);
  GcpExportOptions options;
  options.include_check_points = args.include_check_points ||
                                 args.format == "gpkg" ||
                                 args.format == "metashape";
  options.image_names =
      args.image_paths ? GcpImageNames::kPath : GcpImageNames::kBaseName;
  const std::vector<GroundControlPoint> gcps =
      CollectGroundControlPoints(survey, args.results, options);
  if (gcps.empty()) {
    throw StageFailedError("no ground control point in " + args.results +
                           " (no matched crossing): nothing to export");
  }
  GcpCoordinates coordinates;
  try {
    coordinates =
        GcpCoordinatesFor(args.crs, survey.frame.origin(), args.grid_dirs);
  } catch (const CrsError& error) {
    throw UsageError(std::string("--crs: ") + error.what());
  }
  if (args.format == "odm" && coordinates.system.header.empty()) {
    throw UsageError("--crs " + args.crs +
                     ": ODM's gcp_list.txt names its CRS by one EPSG code or "
                     "a PROJ string; give the horizontal EPSG code (heights "
                     "are then ellipsoidal)");
  }
  if (args.format == "odm") {
    WriteOdmGcpList(gcps, coordinates.system, args.output);
  } else if (args.format == "opensfm") {
    WriteOpenSfmGroundControlPoints(gcps, args.output);
  } else if (args.format == "metashape") {
    const std::filesystem::path path(args.output);
    const std::string projections =
        (path.parent_path() / (path.stem().string() + "_projections.csv"))
            .string();
    if (std::filesystem::is_directory(projections)) {
      throw UsageError(projections +
                       " (the projections beside -o) is a folder");
    }
    WriteMetashapeMarkers(gcps, coordinates.system, args.output, projections);
    LOG(INFO) << "wrote " << projections;
  } else {
    WriteGcpGeoPackage(gcps, coordinates.system, coordinates.srs_definition,
                       args.output);
  }
  int observations = 0;
  for (const GroundControlPoint& gcp : gcps) {
    observations += static_cast<int>(gcp.observations.size());
  }
  LOG(INFO) << "wrote " << args.output << ": " << gcps.size() << " points, "
            << observations << " image observations, CRS "
            << coordinates.system.header;
}

}  // namespace

void AddExportGcpCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* sub = app->add_subcommand(
      "export-gcp",
      "Export the matched band vertices of a results folder as ground "
      "control points with their image observations: OpenDroneMap "
      "gcp_list.txt (odm), OpenSfM ground_control_points.json (opensfm), "
      "Metashape reference CSV and projections (metashape), or a GeoPackage "
      "with residuals for QGIS (gpkg).");
  sub->add_option("survey", args->survey, "survey folder")->required();
  sub->add_option("results", args->results, "results folder (after adjust)")
      ->required();
  sub->add_option("--format", args->format, "odm, opensfm, metashape or gpkg")
      ->required()
      ->check(CLI::IsMember({"odm", "opensfm", "metashape", "gpkg"}));
  sub->add_option("-o,--output", args->output, "file to write")
      ->required()
      ->check(OutputFileValidator());
  sub->add_option("--crs", args->crs,
                  "CRS of the coordinates (odm, metashape, gpkg): 'utm' (the "
                  "survey's WGS84 UTM zone, ODM's usual), an EPSG code or a "
                  "PROJ string; default WGS84 longitude, latitude, "
                  "ellipsoidal height. opensfm is always WGS84.");
  sub->add_option("--grid-dir", args->grid_dirs,
                  "a folder holding PROJ grids (geoid models), searched "
                  "first");
  sub->add_flag("--include-check", args->include_check_points,
                "odm, opensfm: also write the adjustment's check points "
                "(those tools would use them as control)");
  sub->add_flag("--image-paths", args->image_paths,
                "name images by their path in the survey, not their file "
                "name");
  AddAllowOutsidePathsFlag(sub, &args->allow_outside_paths);
  commands->push_back({sub, [args] { RunExportGcp(*args); }});
}

}  // namespace zebrageo
