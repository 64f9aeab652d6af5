// The stereo rig: cameras, their mounting on the vehicle and stereo pairs.
//
// T_body_cam maps camera coordinates into the body frame (FRD):
// p_body = R * p_cam + t, t = lever arm in metres from the IMU origin.
#ifndef ZEBRAGEO_SURVEY_RIG_H_
#define ZEBRAGEO_SURVEY_RIG_H_

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "survey/camera.h"

namespace zebrageo {

struct RigCamera {
  Camera camera;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();
};

struct Rig {
  std::vector<RigCamera> cameras;
  // Indices into `cameras`: {left, right} of each stereo pair, in the order
  // of rig.yaml (the `pair` column of reconstructed_bands.csv).
  std::vector<std::array<int, 2>> stereo_pairs;

  // Index of the camera named `name`, or -1.
  int FindCamera(const std::string& name) const;
};

// Reads rig.yaml (SURVEY_FORMAT.md). Throws InputError with the line of the
// offending node: missing fields, wrong sizes, non-finite numbers, a
// T_body_cam whose rotation is not orthonormal (|R^T R - I| > 1e-6 or
// det != +1) or whose last row is not 0 0 0 1, duplicate camera names,
// stereo pairs naming unknown cameras.
Rig ReadRig(const std::string& path, const std::string& display_name);
Rig ParseRig(const std::string& yaml_text, const std::string& display_name);
// Writes rig.yaml in plain YAML (no OpenCV tags), round-trip exact.
void WriteRig(const Rig& rig, const std::string& path);

// Converts an OpenCV stereoCalibrate result (FileStorage YAML or XML with K1,
// D1, K2, D2, R, T; optionally image width/height) to a Rig. OpenCV's R, T
// map left-camera coordinates into the right camera: p_right = R p_left + T.
// `T_body_left` places the left camera on the vehicle; the right camera is
// T_body_right = T_body_left * [R | T]^-1.
Rig ImportOpenCvStereo(const std::string& path, int width, int height,
                       const Eigen::Isometry3d& T_body_left);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RIG_H_
