// `zebrageo init SURVEY --images DIR --trajectory FILE --calibration FILE
// --roadmarks SOURCE`: a survey folder from a mapping engineer's own files
// (geodata/survey_init.h), then the checks of `zebrageo check`.
#include <glog/logging.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "geodata/calibration_import.h"
#include "geodata/survey_init.h"
#include "pipeline/exit_codes.h"
#include "survey/input_error.h"
#include "survey/rig.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/file_arguments.h"

namespace zebrageo {
namespace {

struct InitArguments {
  std::string survey;
  std::string images;
  TrajectoryArguments trajectory;
  std::vector<std::string> calibration;
  std::string calibration_format = "auto";
  int width = 0;
  int height = 0;
  MountArguments mount;
  CalibrationImportOptions calibration_options;
  std::string roadmarks;
  std::string roadmarks_layer;
  std::string roadmarks_crs;
  std::string output_crs;
  std::string exposure_times = "filename";
  std::string time_clock = "gps-week-seconds";
  std::string time_unit = "s";
  std::string time_regex;
  std::string exif_clock = "utc";
  double exif_utc_offset_h = std::nan("");
  std::string pair_by = "auto";
  double pair_max_dt_s = 0.002;
  std::vector<std::string> camera_patterns;
  bool allow_outside_paths = false;
};

Rig ImportRig(const InitArguments& args) {
  const CameraMount mount = MountOf(args.mount);
  const std::string& first = args.calibration.front();
  CalibrationFormat format = CalibrationFormat::kOpenCv;
  if (args.calibration_format == "auto") {
    format = DetectCalibrationFormat(first);
  } else {
    format = args.calibration_format == "kalibr" ? CalibrationFormat::kKalibr
             : args.calibration_format == "ros"  ? CalibrationFormat::kRos
             : args.calibration_format == "rig"  ? CalibrationFormat::kRig
                                                 : CalibrationFormat::kOpenCv;
  }
  const size_t files = format == CalibrationFormat::kRos ? 2 : 1;
  if (args.calibration.size() != files) {
    throw UsageError("--calibration: " + first + " is " +
                     (files == 2 ? "a ROS camera_info file: give the left "
                                   "and the right one"
                                 : "one file: give it alone"));
  }
  if (format == CalibrationFormat::kRig) {
    if (mount.rotation_stated || !mount.lever_arm_m.isZero()) {
      throw UsageError("--calibration " + first +
                       " is a rig.yaml, which holds the mounts: no mount "
                       "option goes with it");
    }
    return ReadRig(first, first);
  }
  if (!mount.rotation_stated) {
    LOG(WARNING) << "no mount rotation given: the left camera is taken as "
                    "looking straight ahead, level (state roll, pitch and "
                    "yaw: docs/geodata.md)";
  }
  switch (format) {
    case CalibrationFormat::kKalibr:
      return ImportKalibrCamchain(first, mount.T_body_cam(),
                                  args.calibration_options);
    case CalibrationFormat::kRos:
      return ImportRosCameraInfoPair(first, args.calibration[1],
                                     mount.T_body_cam(),
                                     args.calibration_options);
    default:
      return ImportOpenCvStereo(first, args.width, args.height,
                                mount.T_body_cam());
  }
}

ExposureTimeOptions TimeOptionsOf(const InitArguments& args) {
  ExposureTimeOptions times;
  if (args.exposure_times == "exif") {
    times.source = ExposureTimeSource::kExif;
  } else if (args.exposure_times == "filename") {
    times.source = ExposureTimeSource::kFileName;
  } else {
    if (!std::filesystem::is_regular_file(args.exposure_times)) {
      throw UsageError("--exposure-times " + args.exposure_times +
                       ": neither exif, filename nor a times file");
    }
    times.source = ExposureTimeSource::kTimesFile;
    times.times_file = args.exposure_times;
  }
  times.clock = args.time_clock == "unix" ? ImageClock::kUnixUtc
                : args.time_clock == "gps-seconds"
                    ? ImageClock::kGpsSeconds
                    : ImageClock::kGpsWeekSeconds;
  static const std::map<std::string, double> kUnits = {
      {"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"ns", 1e-9}};
  times.name_unit_s = kUnits.at(args.time_unit);
  times.name_regex = args.time_regex;
  times.exif_clock_gps = args.exif_clock == "gps";
  times.exif_utc_offset_h = args.exif_utc_offset_h;
  times.leap_seconds_file = args.trajectory.leap_seconds;
  return times;
}

PairingOptions PairingOf(const InitArguments& args, const Rig& rig) {
  PairingOptions pairing;
  pairing.by = args.pair_by == "name"   ? ImagePairing::kName
               : args.pair_by == "time" ? ImagePairing::kTime
                                        : ImagePairing::kAuto;
  pairing.max_pair_time_difference_s = args.pair_max_dt_s;
  for (const std::string& entry : args.camera_patterns) {
    const size_t equals = entry.find('=');
    const std::string name = entry.substr(0, equals);
    if (equals == std::string::npos || rig.FindCamera(name) < 0) {
      throw UsageError("--camera-pattern " + entry +
                       ": expected CAMERA=REGEX with a camera of the rig");
    }
    pairing.camera_patterns[name] = entry.substr(equals + 1);
  }
  return pairing;
}

void RunInit(const InitArguments& args) {
  namespace fs = std::filesystem;
  for (const std::string& name : SurveyInitFiles()) {
    if (fs::exists(fs::path(args.survey) / name)) {
      throw UsageError(args.survey + " already holds " + name +
                       ": init writes a new survey, it does not overwrite "
                       "one");
    }
  }
  SurveyInitInputs inputs;
  inputs.survey_folder = args.survey;
  inputs.images_folder = args.images;
  inputs.rig = ImportRig(args);
  inputs.trajectory = ImportTrajectory(args.trajectory);
  inputs.roadmarks = args.roadmarks;
  inputs.manifest.roadmarks_layer = args.roadmarks_layer;
  inputs.manifest.roadmarks_crs.definition = args.roadmarks_crs;
  inputs.manifest.output_crs.definition = args.output_crs;
  if (!args.trajectory.crs.empty()) {
    LOG(INFO) << "trajectory positions converted from " << args.trajectory.crs
              << " to WGS84";
  }
  inputs.times = TimeOptionsOf(args);
  const std::string problem = inputs.times.Check();
  if (!problem.empty()) throw UsageError(problem);
  inputs.pairing = PairingOf(args, inputs.rig);
  try {
    const SurveyInitSummary summary =
        InitSurvey(inputs, [&](const std::string& folder) {
          SurveyLoadOptions load;
          load.paths.allow_outside_paths = args.allow_outside_paths;
          PrintSurveySummary(LoadSurvey(folder, load));
        });
    const ExposureListing& listing = summary.listing;
    std::cout << "wrote " << args.survey
              << "/survey.yaml, rig.yaml, trajectory.csv, exposures.csv: "
              << listing.table.images.size() << " images paired by "
              << listing.pairing << " (" << listing.unpaired_images
              << " without a partner, " << listing.skipped_files
              << " other files skipped); images under " << summary.images_prefix
              << "/";
    if (summary.images_linked > 0) {
      std::cout << " (" << summary.images_linked - summary.images_copied
                << " hard-linked, " << summary.images_copied << " copied)";
    }
    std::cout << "\n";
  } catch (const std::invalid_argument& error) {
    throw UsageError(error.what());  // a bad --time-regex or pattern
  }
}

}  // namespace

void AddInitCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<InitArguments>();
  args->trajectory.prefix = "trajectory-";
  CLI::App* sub = app->add_subcommand(
      "init",
      "Create a survey folder (survey.yaml, rig.yaml, trajectory.csv, "
      "exposures.csv) from a folder of images, a GNSS/INS trajectory, a "
      "stereo calibration and a road-mark database, then check it.");
  sub->footer(
      std::string(
          "Images (PNG, TIFF, JPEG) are in one subfolder per camera of the "
          "rig (left/, right/) or picked by --camera-pattern; outside the "
          "survey they are hard-linked into SURVEY/images. Times are put on "
          "the trajectory's clock (GPS seconds of week): UTC times (EXIF, "
          "--time-clock unix) get GPS - UTC from the leap seconds. ") +
      kMountHelp);
  sub->add_option("survey", args->survey, "survey folder to create")
      ->required()
      ->check(OutputFolderValidator());
  sub->add_option("--images", args->images, "folder of the images")
      ->required()
      ->check(CLI::ExistingDirectory);
  sub->add_option("--trajectory", args->trajectory.input,
                  "GNSS/INS trajectory (as import-trajectory reads)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--trajectory-format", args->trajectory.format,
                  "auto, sbet, novatel or csv")
      ->check(CLI::IsMember({"auto", "sbet", "novatel", "csv"}))
      ->capture_default_str();
  AddTrajectoryFormatOptions(sub, &args->trajectory);
  sub->add_option("--calibration", args->calibration,
                  "stereo calibration: an OpenCV stereoCalibrate file, a "
                  "Kalibr camchain, a left and a right ROS camera_info, or "
                  "a rig.yaml")
      ->required()
      ->expected(1, 2)
      ->check(CLI::ExistingFile);
  sub->add_option("--calibration-format", args->calibration_format,
                  "auto, opencv, kalibr, ros or rig")
      ->check(CLI::IsMember({"auto", "opencv", "kalibr", "ros", "rig"}))
      ->capture_default_str();
  sub->add_option("--width", args->width, "opencv: image width (pixels)")
      ->check(CLI::Range(1, 100000));
  sub->add_option("--height", args->height, "opencv: image height (pixels)")
      ->check(CLI::Range(1, 100000));
  AddMaxFitErrorOption(sub, &args->calibration_options.max_fit_error_px);
  AddMountOptions(sub, &args->mount);
  sub->add_option("--roadmarks", args->roadmarks,
                  "road-mark database: a vector file (GeoJSON, GeoPackage, "
                  "Shapefile...) or a PostGIS \"PG:...\" connection")
      ->required();
  sub->add_option("--roadmarks-layer", args->roadmarks_layer,
                  "its layer or table");
  sub->add_option("--roadmarks-crs", args->roadmarks_crs,
                  "its CRS, when the file does not say");
  sub->add_option("--crs", args->output_crs,
                  "the project's CRS (survey.yaml output_crs): outputs "
                  "carry coordinates in it too");
  sub->add_option("--exposure-times", args->exposure_times,
                  "filename (a number in each file name), exif "
                  "(DateTimeOriginal + SubSecTimeOriginal) or a CSV file "
                  "with columns image,time")
      ->capture_default_str();
  sub->add_option("--time-clock", args->time_clock,
                  "clock of file-name and times-file times: "
                  "gps-week-seconds, gps-seconds (since 1980-01-06) or unix "
                  "(UTC, since 1970)")
      ->check(CLI::IsMember({"gps-week-seconds", "gps-seconds", "unix"}))
      ->capture_default_str();
  sub->add_option("--time-unit", args->time_unit,
                  "unit of file-name times: s, ms, us or ns")
      ->check(CLI::IsMember({"s", "ms", "us", "ns"}))
      ->capture_default_str();
  sub->add_option("--time-regex", args->time_regex,
                  "regex whose group 1 is the time in a file name (default: "
                  "the name's last number)");
  sub->add_option("--exif-clock", args->exif_clock,
                  "the camera clock behind EXIF times: utc or gps")
      ->check(CLI::IsMember({"utc", "gps"}))
      ->capture_default_str();
  sub->add_option("--exif-utc-offset", args->exif_utc_offset_h,
                  "hours of a local-time camera clock ahead of UTC, when the "
                  "images have no OffsetTimeOriginal")
      ->check(FiniteWithin(14.0));
  sub->add_option("--pair-by", args->pair_by,
                  "pair stereo images by name (the same name once the "
                  "camera's pattern is removed), time, or auto")
      ->check(CLI::IsMember({"auto", "name", "time"}))
      ->capture_default_str();
  sub->add_option("--pair-max-dt", args->pair_max_dt_s,
                  "largest time difference (s) of a stereo pair's images")
      ->check(FiniteIn(0.0, 10.0))
      ->capture_default_str();
  sub->add_option("--camera-pattern", args->camera_patterns,
                  "CAMERA=REGEX: the images of a camera, by their path "
                  "under --images (default: CAMERA/)");
  AddAllowOutsidePathsFlag(sub, &args->allow_outside_paths);
  commands->push_back({sub, [args] { RunInit(*args); }});
}

}  // namespace zebrageo
