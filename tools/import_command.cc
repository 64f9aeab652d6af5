// `zebrageo import-opencv-stereo CALIB -o rig.yaml`: converts an OpenCV
// stereoCalibrate result (K1, D1, K2, D2, R, T) to the survey's rig.yaml.
#include <glog/logging.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "survey/rig.h"
#include "tools/commands.h"

namespace zebrageo {
namespace {

struct ImportArguments {
  std::string calibration;
  std::string output;
  int width = 0;
  int height = 0;
  std::vector<double> lever_arm_m = {0.0, 0.0, 0.0};
  double pitch_down_deg = 0.0;
};

// Mounting of the left camera on the vehicle: camera looking forward
// (camera z = body x, camera x = body y, camera y = body z), pitched down
// by `pitch_down_deg`, at `lever_arm_m` from the IMU origin.
Eigen::Isometry3d ForwardLookingMount(const std::vector<double>& lever_arm_m,
                                      double pitch_down_deg) {
  Eigen::Matrix3d R_body_cam_level;
  R_body_cam_level << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  // Pitching the camera down rotates it about the body's y (right) axis by
  // a negative angle (FRD: positive pitch is nose up).
  const double pitch = -pitch_down_deg * M_PI / 180.0;
  const Eigen::Matrix3d R_pitch =
      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_pitch * R_body_cam_level;
  T.translation() =
      Eigen::Vector3d(lever_arm_m[0], lever_arm_m[1], lever_arm_m[2]);
  return T;
}

}  // namespace

void AddImportOpenCvStereoCommand(CLI::App* app,
                                  std::vector<Command>* commands) {
  auto args = std::make_shared<ImportArguments>();
  CLI::App* sub = app->add_subcommand(
      "import-opencv-stereo",
      "Convert an OpenCV stereoCalibrate file (YAML/XML with K1, D1, K2, D2, "
      "R, T) to rig.yaml. The left camera is mounted looking forward, "
      "pitched down by --pitch-down-deg, at --lever-arm (body FRD, metres).");
  sub->add_option("calibration", args->calibration, "OpenCV FileStorage file")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("-o,--output", args->output, "rig.yaml to write")->required();
  sub->add_option("--width", args->width,
                  "image width in pixels (if not in the file)");
  sub->add_option("--height", args->height,
                  "image height in pixels (if not in the file)");
  sub->add_option("--lever-arm", args->lever_arm_m,
                  "left camera position in the body frame x y z (m)")
      ->expected(3);
  sub->add_option("--pitch-down-deg", args->pitch_down_deg,
                  "downward pitch of the left camera (degrees)");
  commands->push_back(
      {sub, [args] {
         const Rig rig = ImportOpenCvStereo(
             args->calibration, args->width, args->height,
             ForwardLookingMount(args->lever_arm_m, args->pitch_down_deg));
         WriteRig(rig, args->output);
         LOG(INFO) << "wrote " << args->output << " (" << rig.cameras.size()
                   << " cameras)";
       }});
}

}  // namespace zebrageo
