// Stereo calibrations from other tools into the survey's Rig (rig.yaml):
// Kalibr's camchain.yaml and a pair of ROS camera_info YAML files, beside
// the OpenCV stereoCalibrate import of survey/rig.h.
//
// Frames: camera = OpenCV (x right, y down, z forward), in every format
// here. `T_body_cam0` places the first (left) camera on the vehicle (body
// FRD, metres); the calibration gives the others relative to it:
//  - Kalibr: T_cn_cnm1 maps camera n-1 coordinates into camera n,
//    p_cn = T_cn_cnm1 p_cnm1, so T_body_cn = T_body_cnm1 * T_cn_cnm1^-1.
//    T_cam_imu is ignored: Kalibr's IMU axes are the sensor's own, not the
//    vehicle's FRD body frame, so the mount is given as for OpenCV.
//  - ROS: each file's rectification_matrix R maps its camera into the
//    common rectified frame, and the right projection_matrix holds
//    Tx = -fx' * baseline: p_rect_right = p_rect_left + (Tx/fx', Ty/fy', 0),
//    so p_right = R_right^T (R_left p_left + b).
//
// Distortion: rig.yaml has OpenCV's [k1, k2, p1, p2, k3]. Kalibr radtan
// [k1, k2, r1, r2] and ROS plumb_bob are that model. Kalibr's and ROS's
// equidistant model (Kannala-Brandt, as cv::fisheye: theta_d = theta (1 +
// k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)) is not: its radial
// curve is fitted by k1, k2, k3 (least squares over the image's field of
// view), and refused when the fit departs by more than max_fit_error_px
// anywhere in the image (a wide fisheye).
#ifndef ZEBRAGEO_GEODATA_CALIBRATION_IMPORT_H_
#define ZEBRAGEO_GEODATA_CALIBRATION_IMPORT_H_

#include <Eigen/Geometry>
#include <array>
#include <string>

#include "survey/rig.h"

namespace zebrageo {

struct CalibrationImportOptions {
  // Largest departure (pixels, anywhere in the image) of the radtan model
  // fitted to an equidistant one; sub-pixel band corners need < 0.05 px.
  double max_fit_error_px = 0.05;

  std::string Check() const;
};

// Reads a Kalibr camchain.yaml (pinhole cameras, radtan or equidistant).
// Two cameras are named "left" and "right" and paired; more keep Kalibr's
// names (cam0, cam1, ...) and are paired in order (cam0-cam1, cam2-cam3).
// Throws InputError naming the file, the line and the problem.
Rig ImportKalibrCamchain(const std::string& path,
                         const Eigen::Isometry3d& T_body_cam0,
                         const CalibrationImportOptions& options);

// Reads a left and a right ROS camera_info YAML (camera_calibration_parsers'
// layout: image_width, image_height, camera_matrix, distortion_model,
// distortion_coefficients, rectification_matrix, projection_matrix).
Rig ImportRosCameraInfoPair(const std::string& left_path,
                            const std::string& right_path,
                            const Eigen::Isometry3d& T_body_left,
                            const CalibrationImportOptions& options);

// The calibration formats zebrageo init reads.
enum class CalibrationFormat { kOpenCv, kKalibr, kRos, kRig };

// The format of a calibration file from its content: an OpenCV FileStorage
// ("%YAML:1.0" or <opencv_storage>), a Kalibr camchain (cam0), a ROS
// camera_info (image_width, camera_matrix) or a zebrageo rig.yaml
// (cameras). Throws InputError naming the file when it is none of them.
CalibrationFormat DetectCalibrationFormat(const std::string& path);

// OpenCV distortion fitted to an equidistant camera over its image.
struct EquidistantFit {
  std::array<double, 5> distortion{};  // k1, k2, 0, 0, k3
  double max_error_px = 0.0;           // over the image, at the image scale
};
EquidistantFit FitRadtanToEquidistant(double fx, double fy, double cx,
                                      double cy, int width, int height,
                                      const std::array<double, 4>& k);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_CALIBRATION_IMPORT_H_
