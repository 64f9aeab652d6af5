// The import commands: calibrations to rig.yaml (import-opencv-stereo,
// import-kalibr, import-ros-camera-info) and INS trajectories to
// trajectory.csv (import-trajectory). The conversions live in survey/rig.h
// and geodata/; this file only maps arguments onto them.
#include <glog/logging.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "geodata/calibration_import.h"
#include "geodata/camera_mount.h"
#include "geodata/gps_time.h"
#include "geodata/trajectory_import.h"
#include "pipeline/exit_codes.h"
#include "survey/crs.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/rig.h"
#include "tools/commands.h"
#include "tools/file_arguments.h"

namespace zebrageo {
namespace {

struct ImportArguments {
  std::string calibration;
  std::string right_calibration;  // import-ros-camera-info
  std::string output;
  int width = 0;
  int height = 0;
  MountArguments mount;
  CalibrationImportOptions options;
};

// The mount options and -o of every calibration import.
void AddRigOutputOptions(CLI::App* sub, ImportArguments* args) {
  sub->add_option("-o,--output", args->output, "rig.yaml to write")
      ->required()
      ->check(OutputFileValidator());
  AddMountOptions(sub, &args->mount);
}

// Writes the rig and says how each camera sits on the vehicle, in the
// mount convention the options take (so a user can check it against the
// mount sheet).
void WriteImportedRig(const Rig& rig, const CameraMount& mount,
                      const std::string& output) {
  if (!mount.rotation_stated) {
    LOG(WARNING) << "no mount rotation given: the left camera is taken as "
                    "looking straight ahead along the body x axis, level. "
                    "State the mount's roll, pitch and yaw (or "
                    "--mount-rotation): an unstated misalignment of half a "
                    "degree gives wrong matches, and zebrageo does not "
                    "estimate it";
  }
  WriteRig(rig, output);
  LOG(INFO) << "wrote " << output << " (" << rig.cameras.size() << " cameras)";
  for (const RigCamera& camera : rig.cameras) {
    const Eigen::Vector3d angles = MountAngles(camera.T_body_cam.linear());
    const Eigen::Vector3d t = camera.T_body_cam.translation();
    LOG(INFO) << camera.camera.name() << ": lever arm " << t.x() << " " << t.y()
              << " " << t.z() << " m, mount roll " << RadToDeg(angles.x())
              << " pitch " << RadToDeg(angles.y()) << " yaw "
              << RadToDeg(angles.z()) << " deg";
  }
}

CsvTrajectoryFormat CsvFormatOf(const TrajectoryArguments& args) {
  CsvTrajectoryFormat format;
  format.angle_unit =
      args.angles == "rad" ? AngleUnit::kRadians : AngleUnit::kDegrees;
  format.time_kind = args.time == "utc"           ? TimeKind::kUtc
                     : args.time == "gps-seconds" ? TimeKind::kGpsSeconds
                                                  : TimeKind::kGpsWeekSeconds;
  format.delimiter = args.delimiter == "whitespace"  ? Delimiter::kWhitespace
                     : args.delimiter == "semicolon" ? Delimiter::kSemicolon
                                                     : Delimiter::kComma;
  format.leap_seconds_file = args.leap_seconds;
  format.crs = args.crs;
  format.grid_dirs = args.grid_dirs;
  if (!args.columns.empty()) {
    const std::string error = ParseColumnMap(args.columns, &format);
    if (!error.empty()) throw UsageError(args.prefix + "columns: " + error);
  }
  const std::string problem = format.Check();
  if (!problem.empty()) throw UsageError(problem);
  return format;
}

void RunImportTrajectory(const TrajectoryArguments& args) {
  const std::vector<TrajectorySample> samples = ImportTrajectory(args);
  WriteTrajectorySamples(samples, args.output);
  LOG(INFO) << "wrote " << args.output << " (" << samples.size()
            << " samples, GPS seconds of week " << samples.front().time
            << " to " << samples.back().time << ")";
}

}  // namespace

std::vector<TrajectorySample> ImportTrajectory(
    const TrajectoryArguments& args) {
  std::string format = args.format;
  if (format == "auto") {
    format = GuessTrajectoryFormat(args.input);
    LOG(INFO) << args.input << ": read as " << format;
  }
  if (!args.crs.empty() && format != "csv") {
    throw UsageError("--" + args.prefix + "crs goes with --" + args.prefix +
                     "format csv only (SBET and NovAtel logs are WGS84)");
  }
  if (format != "sbet" && !args.smrmsg.empty()) {
    throw UsageError("--smrmsg goes with an SBET only");
  }
  try {
    if (format == "sbet") return ReadSbet(args.input, args.smrmsg);
    return format == "novatel"
               ? ReadNovatelAscii(args.input)
               : ReadTrajectoryCsv(args.input, CsvFormatOf(args));
  } catch (const CrsError& error) {
    throw UsageError("--" + args.prefix + "crs: " + error.what());
  }
}

void AddTrajectoryFormatOptions(CLI::App* sub, TrajectoryArguments* args) {
  const std::string p = "--" + args->prefix;
  sub->add_option("--smrmsg", args->smrmsg,
                  "sbet: the smrmsg accuracy file (for the sd_* columns)")
      ->check(CLI::ExistingFile);
  sub->add_option(p + "columns", args->columns,
                  "csv: NAME=COLUMN,... for time, lat, lon, h, roll, pitch, "
                  "heading, sd_e, sd_n, sd_u, sd_roll, sd_pitch, sd_heading "
                  "(unmapped names are looked up as themselves)");
  sub->add_option(p + "angles", args->angles,
                  "csv: unit of lat, lon and the attitude: deg or rad")
      ->check(CLI::IsMember({"deg", "rad"}))
      ->capture_default_str();
  sub->add_option(p + "time", args->time,
                  "csv: week-seconds (GPS), gps-seconds (since 1980-01-06) "
                  "or utc (ISO 8601, converted with leap seconds)")
      ->check(CLI::IsMember({"week-seconds", "gps-seconds", "utc"}))
      ->capture_default_str();
  sub->add_option(p + "delimiter", args->delimiter,
                  "csv: comma, whitespace or semicolon")
      ->check(CLI::IsMember({"comma", "whitespace", "semicolon"}))
      ->capture_default_str();
  sub->add_option("--leap-seconds", args->leap_seconds,
                  "IERS leap-seconds.list (UTC times)")
      ->capture_default_str();
  sub->add_option(p + "crs", args->crs,
                  "csv: CRS of the positions (EPSG code, compound code with a "
                  "geoid, PROJ string): columns x, y, h instead of lat, lon, "
                  "h, transformed to WGS84 by PROJ");
  sub->add_option("--grid-dir", args->grid_dirs,
                  "csv --crs: a folder holding PROJ grids (geoid models), "
                  "searched first");
}

void AddImportCalibrationCommands(CLI::App* app,
                                  std::vector<Command>* commands) {
  {
    auto args = std::make_shared<ImportArguments>();
    CLI::App* sub = app->add_subcommand(
        "import-kalibr",
        "Convert a Kalibr camchain.yaml (pinhole, radtan or equidistant) to "
        "rig.yaml, with the left camera's mount (see --help). cam0 is the "
        "left camera; the others follow from T_cn_cnm1.");
    sub->footer(kMountHelp);
    sub->add_option("camchain", args->calibration, "Kalibr camchain.yaml")
        ->required()
        ->check(CLI::ExistingFile);
    AddRigOutputOptions(sub, args.get());
    AddMaxFitErrorOption(sub, &args->options.max_fit_error_px);
    commands->push_back({sub, [args] {
                           const CameraMount mount = MountOf(args->mount);
                           WriteImportedRig(
                               ImportKalibrCamchain(args->calibration,
                                                    mount.T_body_cam(),
                                                    args->options),
                               mount, args->output);
                         }});
  }
  {
    auto args = std::make_shared<ImportArguments>();
    CLI::App* sub = app->add_subcommand(
        "import-ros-camera-info",
        "Convert a left and a right ROS camera_info YAML (from "
        "camera_calibration's stereo calibration) to rig.yaml, with the left "
        "camera's mount (see --help).");
    sub->footer(kMountHelp);
    sub->add_option("left", args->calibration, "left camera_info YAML")
        ->required()
        ->check(CLI::ExistingFile);
    sub->add_option("right", args->right_calibration, "right camera_info YAML")
        ->required()
        ->check(CLI::ExistingFile);
    AddRigOutputOptions(sub, args.get());
    AddMaxFitErrorOption(sub, &args->options.max_fit_error_px);
    commands->push_back({sub, [args] {
                           const CameraMount mount = MountOf(args->mount);
                           WriteImportedRig(
                               ImportRosCameraInfoPair(
                                   args->calibration, args->right_calibration,
                                   mount.T_body_cam(), args->options),
                               mount, args->output);
                         }});
  }
}

void AddImportTrajectoryCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<TrajectoryArguments>();
  CLI::App* sub = app->add_subcommand(
      "import-trajectory",
      "Convert a GNSS/INS trajectory (Applanix SBET with its smrmsg, NovAtel "
      "SPAN INSPVAXA/INSPVAA ASCII log, or a delimited text export with a "
      "column map) to the survey's trajectory.csv. Time is written as GPS "
      "seconds of week (of the first record's week): exposures.csv must use "
      "the same clock.");
  sub->add_option("input", args->input, "trajectory file")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--format", args->format,
                  "sbet, novatel, csv, or auto (binary: sbet; #INSPVA "
                  "records: novatel; else csv)")
      ->required()
      ->check(CLI::IsMember({"sbet", "novatel", "csv", "auto"}));
  sub->add_option("-o,--output", args->output, "trajectory.csv to write")
      ->required()
      ->check(OutputFileValidator());
  AddTrajectoryFormatOptions(sub, args.get());
  commands->push_back({sub, [args] { RunImportTrajectory(*args); }});
}

void AddImportOpenCvStereoCommand(CLI::App* app,
                                  std::vector<Command>* commands) {
  auto args = std::make_shared<ImportArguments>();
  CLI::App* sub = app->add_subcommand(
      "import-opencv-stereo",
      "Convert an OpenCV stereoCalibrate file (YAML/XML with K1, D1, K2, D2, "
      "R, T) to rig.yaml, with the left camera's mount (see --help).");
  sub->footer(kMountHelp);
  sub->add_option("calibration", args->calibration, "OpenCV FileStorage file")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--width", args->width,
                  "image width in pixels (if not in the file)")
      ->check(CLI::Range(1, 100000));
  sub->add_option("--height", args->height,
                  "image height in pixels (if not in the file)")
      ->check(CLI::Range(1, 100000));
  AddRigOutputOptions(sub, args.get());
  commands->push_back(
      {sub, [args] {
         const CameraMount mount = MountOf(args->mount);
         WriteImportedRig(ImportOpenCvStereo(args->calibration, args->width,
                                             args->height, mount.T_body_cam()),
                          mount, args->output);
       }});
}

}  // namespace zebrageo
