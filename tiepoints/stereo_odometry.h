// Camera motion between consecutive exposures measured from the images, for
// the tie points' geometric checks.
//
// The tie points' epipolar gate and triangulation need the relative pose of
// two exposures to a pixel. A smooth GNSS/INS gives it; one whose positions
// jitter from sample to sample by centimetres (an unsmoothed GNSS, or GPS +
// dead reckoning) does not: 10 cm between exposures is 8 px at 10 m, so
// every true temporal match fails the gate and the exposures the ties were
// meant to hold together are left to the jittering trajectory. The stereo
// rig measures that motion itself: features of one exposure triangulated by
// the calibrated stereo pair (no trajectory involved), found again in the
// next exposure's image, give the camera's motion by PnP with RANSAC.
//
// Frames: T_cb_ca maps camera coordinates at exposure a into camera
// coordinates at exposure b; points in the camera frame (x right, y down, z
// forward), metres; image points as normalised coordinates (x/z, y/z).
#ifndef ZEBRAGEO_TIEPOINTS_STEREO_ODOMETRY_H_
#define ZEBRAGEO_TIEPOINTS_STEREO_ODOMETRY_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace zebrageo {

struct StereoOdometryOptions {
  // Lowe's ratio for the correspondences between exposures: looser than
  // the tie points' own, since PnP with RANSAC verifies them.
  double max_descriptor_ratio = 0.9;
  // Stereo points are used out to this range (metres): the depth error
  // grows with the square of the range.
  double max_range_m = 25.0;
  // A stereo correspondence's reprojection error in the second camera
  // (pixels) and a PnP inlier's (pixels).
  double max_stereo_error_px = 1.0;
  double max_pnp_error_px = 1.5;
  // A motion is accepted with at least this many PnP inliers, and at least
  // this share of the putative correspondences.
  int min_inliers = 8;
  double min_inlier_share = 0.3;
  // The measured motion may depart from the trajectory's by at most this
  // much (metres; radians): beyond, the images were misread (a repeated
  // pattern) rather than the trajectory wrong by that much over a fraction
  // of a second.
  double max_translation_change_m = 0.5;
  double max_rotation_change_rad = 0.035;  // 2 degrees

  std::string Check() const;
};

// The point seen at normalised coordinates x_a in camera a and x_b in
// camera b of a stereo pair (T_cb_ca from the rig's calibration), in camera
// a's frame; false when the rays do not meet within max_stereo_error_px
// (focal_px converts) or the point is not 1 to max_range_m in front.
bool TriangulateStereoPoint(const StereoOdometryOptions& options,
                            const Eigen::Isometry3d& T_cb_ca,
                            const Eigen::Vector2d& x_a,
                            const Eigen::Vector2d& x_b, double focal_px,
                            Eigen::Vector3d* p_ca);

struct CameraMotion {
  bool valid = false;
  Eigen::Isometry3d T_cb_ca = Eigen::Isometry3d::Identity();
  int inliers = 0;
  int correspondences = 0;
};

// The motion of a camera from exposure a to exposure b: points_ca (stereo
// points of exposure a) seen at normalised coordinates x_b in exposure b.
// T_cb_ca_prior (the trajectory's) bounds the result.
CameraMotion CameraMotionFromStereoPoints(
    const StereoOdometryOptions& options,
    const std::vector<Eigen::Vector3d>& points_ca,
    const std::vector<Eigen::Vector2d>& x_b,
    const Eigen::Isometry3d& T_cb_ca_prior, double focal_px);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TIEPOINTS_STEREO_ODOMETRY_H_
