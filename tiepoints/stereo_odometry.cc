#include "tiepoints/stereo_odometry.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>

#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Pixel distance between a camera-frame point's projection and a
// normalised observation.
double ReprojectionErrorPx(const Eigen::Vector3d& p_cam,
                           const Eigen::Vector2d& x, double focal_px) {
  if (!(p_cam.z() > 0.0)) return HUGE_VAL;
  return (p_cam.head<2>() / p_cam.z() - x).norm() * focal_px;
}

double RotationAngleRad(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R).angle();
}

}  // namespace

std::string StereoOdometryOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_range_m, 1.0);
  OPTION_GT(check, max_stereo_error_px, 0.0);
  OPTION_GT(check, max_pnp_error_px, 0.0);
  OPTION_GE(check, min_inliers, 6);
  OPTION_IN(check, max_descriptor_ratio, "(", 0.0, 1.0, "]");
  OPTION_IN(check, min_inlier_share, "[", 0.0, 1.0, "]");
  OPTION_GT(check, max_translation_change_m, 0.0);
  OPTION_GT(check, max_rotation_change_rad, 0.0);
  return check.problem();
}

bool TriangulateStereoPoint(const StereoOdometryOptions& options,
                            const Eigen::Isometry3d& T_cb_ca,
                            const Eigen::Vector2d& x_a,
                            const Eigen::Vector2d& x_b, double focal_px,
                            Eigen::Vector3d* p_ca) {
  // Midpoint of the two rays, in camera a's frame.
  const Eigen::Isometry3d T_ca_cb = T_cb_ca.inverse();
  const Eigen::Vector3d d_a = x_a.homogeneous().normalized();
  const Eigen::Vector3d d_b =
      (T_ca_cb.linear() * x_b.homogeneous()).normalized();
  const Eigen::Vector3d c_b = T_ca_cb.translation();
  Eigen::Matrix2d A;
  A << 1.0, -d_a.dot(d_b), d_a.dot(d_b), -1.0;
  const Eigen::Vector2d rhs(d_a.dot(c_b), d_b.dot(c_b));
  if (std::abs(A.determinant()) < 1e-12) return false;  // parallel rays
  const Eigen::Vector2d s = A.inverse() * rhs;
  const Eigen::Vector3d p = 0.5 * (s[0] * d_a + c_b + s[1] * d_b);
  if (!p.allFinite() || p.z() < 1.0 || p.norm() > options.max_range_m) {
    return false;
  }
  if (ReprojectionErrorPx(p, x_a, focal_px) > options.max_stereo_error_px ||
      ReprojectionErrorPx(T_cb_ca * p, x_b, focal_px) >
          options.max_stereo_error_px) {
    return false;
  }
  *p_ca = p;
  return true;
}

CameraMotion CameraMotionFromStereoPoints(
    const StereoOdometryOptions& options,
    const std::vector<Eigen::Vector3d>& points_ca,
    const std::vector<Eigen::Vector2d>& x_b,
    const Eigen::Isometry3d& T_cb_ca_prior, double focal_px) {
  CameraMotion motion;
  motion.correspondences = static_cast<int>(points_ca.size());
  if (motion.correspondences < options.min_inliers ||
      points_ca.size() != x_b.size()) {
    return motion;
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < points_ca.size(); ++i) {
    object.emplace_back(points_ca[i].x(), points_ca[i].y(), points_ca[i].z());
    image.emplace_back(x_b[i].x(), x_b[i].y());
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  // Normalised coordinates: the camera matrix is the identity and the
  // threshold is in focal lengths. OpenCV's RANSAC draws from a fixed seed,
  // so the result is deterministic.
  // Minimal samples by AP3P: with the iterative kernel started from the
  // prior, a quarter of mismatches sent OpenCV's RANSAC to a wrong pose.
  // Then refined on the inliers, Levenberg-Marquardt from that pose.
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  bool solved = cv::solvePnPRansac(
      object, image, K, cv::noArray(), rvec, tvec,
      /*useExtrinsicGuess=*/false, /*iterationsCount=*/300,
      static_cast<float>(options.max_pnp_error_px / focal_px),
      /*confidence=*/0.999, inliers, cv::SOLVEPNP_AP3P);
  if (!solved || static_cast<int>(inliers.size()) < 4) return motion;
  std::vector<cv::Point3d> object_in;
  std::vector<cv::Point2d> image_in;
  for (int i : inliers) {
    object_in.push_back(object[i]);
    image_in.push_back(image[i]);
  }
  solved = cv::solvePnP(object_in, image_in, K, cv::noArray(), rvec, tvec,
                        /*useExtrinsicGuess=*/true, cv::SOLVEPNP_ITERATIVE);
  if (!solved) return motion;
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d R_eigen;
  Eigen::Vector3d t_eigen;
  cv::cv2eigen(R, R_eigen);
  cv::cv2eigen(tvec, t_eigen);
  if (!R_eigen.allFinite() || !t_eigen.allFinite()) return motion;
  motion.T_cb_ca.linear() = R_eigen;
  motion.T_cb_ca.translation() = t_eigen;
  // Inliers of the final pose (RANSAC's set was for its own sample).
  motion.inliers = 0;
  for (size_t i = 0; i < points_ca.size(); ++i) {
    motion.inliers += ReprojectionErrorPx(motion.T_cb_ca * points_ca[i], x_b[i],
                                          focal_px) <= options.max_pnp_error_px;
  }
  const Eigen::Isometry3d change = T_cb_ca_prior.inverse() * motion.T_cb_ca;
  motion.valid =
      motion.inliers >= options.min_inliers &&
      motion.inliers >= options.min_inlier_share * motion.correspondences &&
      change.translation().norm() <= options.max_translation_change_m &&
      RotationAngleRad(change.linear()) <= options.max_rotation_change_rad;
  return motion;
}

}  // namespace zebrageo
