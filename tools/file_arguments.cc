#include "tools/file_arguments.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "pipeline/exit_codes.h"
#include "survey/math_util.h"

namespace zebrageo {

const char kMountHelp[] =
    "The left (first) camera's mount: --lever-arm (body FRD, metres) and its "
    "rotation, as angles about the body axes of a camera looking straight "
    "ahead along body x (R_body_cam = Rz(yaw) Ry(pitch) Rx(roll) "
    "R_level; positive roll turns the image's right side down, positive "
    "pitch raises the optical axis, positive yaw turns it right; "
    "--pitch-down-deg D is --mount-pitch-deg -D), as --mount-rotation "
    "(R_body_cam, row-major, as in rig.yaml's T_body_cam) or as a --mount "
    "file. State every angle the mount has: zebrageo does not estimate a "
    "boresight misalignment, and an unstated yaw or roll of half a degree "
    "gives wrong matches (docs/geodata.md).";

CLI::Validator OutputFileValidator() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        namespace fs = std::filesystem;
        std::error_code error;
        if (fs::is_directory(path, error)) {
          return path + " is a folder: give the name of the file to write";
        }
        const fs::path parent = fs::path(path).parent_path();
        if (!parent.empty() && !fs::is_directory(parent, error)) {
          return "folder " + parent.string() +
                 " does not exist (create it "
                 "first)";
        }
        return "";
      },
      "FILE");
}

CLI::Validator OutputFolderValidator() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        namespace fs = std::filesystem;
        std::error_code error;
        // The nearest part of the path that exists must be a folder.
        for (fs::path p = path; !p.empty(); p = p.parent_path()) {
          const fs::file_status status = fs::status(p, error);
          if (!fs::exists(status)) {
            if (p == p.parent_path()) break;
            continue;
          }
          if (fs::is_directory(status)) return "";
          return p.string() == path ? path + " is a file, not a folder"
                                    : p.string() + " is a file: the folder " +
                                          path + " cannot be created in it";
        }
        return "";
      },
      "FOLDER");
}

CLI::Validator FiniteWithin(double limit) { return FiniteIn(-limit, limit); }

CLI::Validator FiniteIn(double low, double high, bool above_low) {
  return CLI::Validator(
      [low, high, above_low](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) {
          return "'" + text + "' is not a number";
        }
        if (!std::isfinite(value)) {
          return "'" + text + "' is not a finite number";
        }
        if (value < low || value > high || (above_low && value == low)) {
          std::ostringstream problem;
          problem << text << " is outside " << (above_low ? "(" : "[") << low
                  << ", " << high << "]";
          return problem.str();
        }
        return "";
      },
      "NUMBER");
}

void AddMaxFitErrorOption(CLI::App* sub, double* max_fit_error_px) {
  sub->add_option("--max-fit-error-px", *max_fit_error_px,
                  "equidistant lenses: largest error of the OpenCV model "
                  "fitted to the equidistant one (pixels)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 100.0, true));
}

void AddMountOptions(CLI::App* sub, MountArguments* args) {
  CLI::Option* lever_arm =
      sub->add_option("--lever-arm", args->lever_arm_m,
                      "left camera's position in the body frame x y z "
                      "(FRD, metres)")
          ->expected(3)
          ->check(FiniteWithin(kMaxLeverArmM));
  args->roll = sub->add_option("--mount-roll-deg", args->roll_deg,
                               "mount roll of the left camera (degrees; "
                               "positive: the image's right side down)")
                   ->check(FiniteWithin(180.0));
  CLI::Option* pitch =
      sub->add_option("--mount-pitch-deg", args->pitch_deg,
                      "mount pitch of the left camera (degrees; positive: "
                      "optical axis up, so negative for a camera looking "
                      "at the road)")
          ->check(FiniteWithin(90.0));
  args->pitch = pitch;
  args->yaw = sub->add_option("--mount-yaw-deg", args->yaw_deg,
                              "mount yaw of the left camera (degrees; "
                              "positive: optical axis turned right)")
                  ->check(FiniteWithin(180.0));
  CLI::Option* pitch_down =
      sub->add_option("--pitch-down-deg", args->pitch_down_deg,
                      "downward pitch of the left camera (degrees): "
                      "--mount-pitch-deg with the sign turned")
          ->check(FiniteWithin(90.0))
          ->excludes(pitch);
  args->pitch_down = pitch_down;
  CLI::Option* rotation =
      sub->add_option("--mount-rotation", args->rotation,
                      "the left camera's R_body_cam, row-major "
                      "r11,r12,r13,r21,...,r33 (camera x right, y down, z "
                      "optical axis into body FRD)")
          ->expected(9)
          ->delimiter(',')
          ->check(FiniteWithin(1.0 + 1e-6));
  rotation->excludes(args->roll)
      ->excludes(args->yaw)
      ->excludes(pitch)
      ->excludes(pitch_down);
  CLI::Option* file =
      sub->add_option("--mount", args->mount_file,
                      "a YAML file with the mount: lever_arm and roll_deg, "
                      "pitch_deg, yaw_deg, or R_body_cam, or T_body_cam "
                      "(docs/geodata.md)")
          ->check(CLI::ExistingFile);
  file->excludes(lever_arm)->excludes(rotation)->excludes(args->roll);
  file->excludes(args->yaw)->excludes(pitch)->excludes(pitch_down);
}

CameraMount MountOf(const MountArguments& args) {
  if (!args.mount_file.empty()) return ReadCameraMountFile(args.mount_file);
  CameraMount mount;
  mount.lever_arm_m = Eigen::Vector3d(args.lever_arm_m[0], args.lever_arm_m[1],
                                      args.lever_arm_m[2]);
  if (!args.rotation.empty()) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        mount.R_body_cam(r, c) = args.rotation[3 * r + c];
      }
    }
    const std::string problem = RotationProblem(mount.R_body_cam);
    if (!problem.empty()) throw UsageError("--mount-rotation: " + problem);
    mount.rotation_stated = true;
    return mount;
  }
  const bool pitch_down = args.pitch_down->count() > 0;
  mount.rotation_stated = args.roll->count() > 0 || args.pitch->count() > 0 ||
                          args.yaw->count() > 0 || pitch_down;
  mount.R_body_cam = MountRotation(
      DegToRad(args.roll_deg),
      DegToRad(pitch_down ? -args.pitch_down_deg : args.pitch_deg),
      DegToRad(args.yaw_deg));
  return mount;
}

}  // namespace zebrageo
