// Command-line arguments the import, export and init commands share:
// files to write, numbers that must be finite, the camera mount. Checked
// while parsing, so a mistake is a usage error (exit 2) naming the option
// before anything is read or written.
#ifndef ZEBRAGEO_TOOLS_FILE_ARGUMENTS_H_
#define ZEBRAGEO_TOOLS_FILE_ARGUMENTS_H_

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "geodata/camera_mount.h"
#include "survey/trajectory.h"

namespace zebrageo {

// A file the command writes: not an existing folder, and in a folder that
// exists (written atomically there: nothing half-written on failure).
CLI::Validator OutputFileValidator();

// A folder the command creates (or fills): not a file, and no file where
// one of its missing parents would be created.
CLI::Validator OutputFolderValidator();

// A finite number within [-limit, limit] ("nan", "inf" and typos refused).
CLI::Validator FiniteWithin(double limit);
// A finite number within [low, high], or (low, high] when `above_low`.
// CLI::Range lets "nan" through (every comparison with NaN is false).
CLI::Validator FiniteIn(double low, double high, bool above_low = false);

// --max-fit-error-px of the calibration imports (finite, > 0).
void AddMaxFitErrorOption(CLI::App* sub, double* max_fit_error_px);

// The mount options of a calibration import (geodata/camera_mount.h).
struct MountArguments {
  std::vector<double> lever_arm_m = {0.0, 0.0, 0.0};
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
  double pitch_down_deg = 0.0;
  std::vector<double> rotation;  // row-major R_body_cam
  std::string mount_file;
  // Which were given.
  CLI::Option* roll = nullptr;
  CLI::Option* pitch = nullptr;
  CLI::Option* yaw = nullptr;
  CLI::Option* pitch_down = nullptr;
};

// Adds --lever-arm, --mount-roll-deg, --mount-pitch-deg, --mount-yaw-deg,
// --pitch-down-deg, --mount-rotation and --mount to `sub`.
void AddMountOptions(CLI::App* sub, MountArguments* args);

// The mount the arguments state. Throws UsageError (a rotation matrix that
// is not one) or InputError (the mount file).
CameraMount MountOf(const MountArguments& args);

// The trajectory import's arguments (import-trajectory, init).
struct TrajectoryArguments {
  // Prefix of the format options' names: "" for import-trajectory
  // (--format, --columns...), "trajectory-" for init.
  std::string prefix;
  std::string input;
  std::string format = "auto";
  std::string smrmsg;
  std::string output;
  std::string columns;
  std::string angles = "deg";
  std::string time = "week-seconds";
  std::string delimiter = "comma";
  std::string leap_seconds = "/usr/share/zoneinfo/leap-seconds.list";
  std::string crs;
  std::vector<std::string> grid_dirs;
};

// Adds --smrmsg, --[prefix]columns, angles, time, delimiter, crs,
// --leap-seconds and --grid-dir (tools/import_command.cc).
void AddTrajectoryFormatOptions(CLI::App* sub, TrajectoryArguments* args);
// The samples the arguments name, on GPS seconds of week. Throws
// InputError or UsageError.
std::vector<TrajectorySample> ImportTrajectory(const TrajectoryArguments& args);

// What the help of each import says about the mount.
extern const char kMountHelp[];

}  // namespace zebrageo

#endif  // ZEBRAGEO_TOOLS_FILE_ARGUMENTS_H_
