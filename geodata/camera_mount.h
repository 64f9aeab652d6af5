// How a calibration's first (left) camera sits on the vehicle: its lever arm
// and its mount rotation, as a mapping engineer states them, turned into
// rig.yaml's T_body_cam. Every calibration import (import-opencv-stereo,
// import-kalibr, import-ros-camera-info) takes the mount this way; the other
// cameras follow from the calibration's relative poses.
//
// Frames: body = the trajectory's FRD (x forward, y right, z down), camera =
// OpenCV (x right, y down, z along the optical axis); T_body_cam maps camera
// coordinates into the body frame (SURVEY_FORMAT.md).
//
// Mount angles. The reference is the camera looking straight ahead along
// the body x axis, its image upright: camera z = body x, camera x = body y,
// camera y = body z, i.e. R_body_cam_level = [0 0 1; 1 0 0; 0 1 0]. Roll,
// pitch and yaw turn that camera about the BODY axes, in the order and sense
// of the trajectory's attitude (R_ned_body = Rz(heading) Ry(pitch) Rx(roll)):
//
//   R_body_cam = Rz(yaw) * Ry(pitch) * Rx(roll) * R_body_cam_level
//
// applied right to left: first roll about body x (the optical axis of the
// level camera; positive turns the image's right side down), then pitch
// about body y (positive raises the optical axis: a camera looking at the
// road has a negative pitch; --pitch-down-deg D is pitch = -D), then yaw
// about body z (positive turns the optical axis to the right). These are the
// Z-Y-X Euler angles of the camera's own forward-right-down frame (x along
// the optical axis, y the image's right, z the image's down) in the body
// frame, so a camera's mount reads like a vehicle's attitude.
//
// The simulator (simulator/motion.cc MakeRig) builds the same nominal
// camera (pitched down by camera_pitch_down_deg) and then turns it by small
// random angles about the CAMERA's own axes; those angles are not these: for
// such a rig, give the rotation matrix (or read the angles this convention
// gives for it: MountAngles, printed by every import).
#ifndef ZEBRAGEO_GEODATA_CAMERA_MOUNT_H_
#define ZEBRAGEO_GEODATA_CAMERA_MOUNT_H_

#include <Eigen/Geometry>
#include <string>

namespace zebrageo {

// A lever arm component beyond this is not a camera on a vehicle (a value
// in millimetres?).
inline constexpr double kMaxLeverArmM = 100.0;

// R_body_cam of the camera looking straight ahead, image upright.
Eigen::Matrix3d LevelForwardCameraRotation();

// R_body_cam of the mount angles above (radians).
Eigen::Matrix3d MountRotation(double roll_rad, double pitch_rad,
                              double yaw_rad);

// Roll, pitch, yaw (radians) of R_body_cam in the convention above: pitch
// in [-pi/2, pi/2], roll and yaw in (-pi, pi]. At pitch +-pi/2 (a camera
// looking straight down or up) roll and yaw are not separable: roll is 0.
Eigen::Vector3d MountAngles(const Eigen::Matrix3d& R_body_cam);

// "" or what keeps R from being a rotation (not orthonormal within 1e-6,
// as rig.yaml's reader requires, or a reflection).
std::string RotationProblem(const Eigen::Matrix3d& R);

struct CameraMount {
  // Position of the camera's projection centre in the body frame (metres).
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_body_cam = LevelForwardCameraRotation();
  // False when the user stated no rotation (the level forward camera).
  bool rotation_stated = false;

  Eigen::Isometry3d T_body_cam() const;
};

// Reads a mount file (YAML, a few lines; docs/geodata.md):
//   lever_arm: [x, y, z]                       # metres, body FRD
//   roll_deg: r, pitch_deg: p, yaw_deg: y      # any of them; or
//   pitch_down_deg: d                          # instead of pitch_deg; or
//   R_body_cam: [r11, r12, r13, ..., r33]      # row-major; or
//   T_body_cam: [16 numbers]                   # as in rig.yaml (no lever_arm)
// Throws InputError naming the file, the line and the problem.
CameraMount ReadCameraMountFile(const std::string& path);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_CAMERA_MOUNT_H_
