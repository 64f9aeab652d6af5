// Camera model: OpenCV pinhole with distortion [k1, k2, p1, p2, k3], exactly
// as cv::projectPoints. Pixel (0, 0) is the centre of the top-left pixel.
//
// Frames: camera = OpenCV (x right, y down, z along the optical axis).
// Intrinsic parameter block (for Ceres): [fx, fy, cx, cy, k1, k2, p1, p2, k3].
#ifndef ZEBRAGEO_SURVEY_CAMERA_H_
#define ZEBRAGEO_SURVEY_CAMERA_H_

#include <Eigen/Core>
#include <array>
#include <string>

namespace zebrageo {

constexpr int kNumIntrinsics = 9;

// OpenCV distortion of normalised coordinates (x, y) = (X/Z, Y/Z).
template <typename T>
inline void DistortNormalized(const T* intrinsics, const T& x, const T& y,
                              T* x_distorted, T* y_distorted) {
  const T& k1 = intrinsics[4];
  const T& k2 = intrinsics[5];
  const T& p1 = intrinsics[6];
  const T& p2 = intrinsics[7];
  const T& k3 = intrinsics[8];
  const T r2 = x * x + y * y;
  const T radial = T(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
  const T xy = x * y;
  *x_distorted = x * radial + T(2) * p1 * xy + p2 * (r2 + T(2) * x * x);
  *y_distorted = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * xy;
}

// Projects a point in the camera frame to pixels. Templated so Ceres can
// differentiate it (ceres::Jet). Returns false (uv untouched) when the point
// is not in front of the camera (Z <= 0): callers decide what that means.
template <typename T>
inline bool ProjectToPixel(const T* intrinsics, const T* p_cam, T* uv) {
  if (!(p_cam[2] > T(0))) return false;
  const T x = p_cam[0] / p_cam[2];
  const T y = p_cam[1] / p_cam[2];
  T xd, yd;
  DistortNormalized(intrinsics, x, y, &xd, &yd);
  uv[0] = intrinsics[0] * xd + intrinsics[2];
  uv[1] = intrinsics[1] * yd + intrinsics[3];
  return true;
}

class Camera {
 public:
  Camera() = default;
  Camera(std::string name, int width, int height, double fx, double fy,
         double cx, double cy, const std::array<double, 5>& distortion);

  const std::string& name() const { return name_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return intrinsics_[0]; }
  double fy() const { return intrinsics_[1]; }
  double cx() const { return intrinsics_[2]; }
  double cy() const { return intrinsics_[3]; }
  // [k1, k2, p1, p2, k3]
  std::array<double, 5> distortion() const;
  const double* intrinsics() const { return intrinsics_.data(); }
  Eigen::Matrix3d K() const;

  // False when the point is behind the camera.
  bool Project(const Eigen::Vector3d& p_cam, Eigen::Vector2d* uv) const;
  // Normalised undistorted coordinates (X/Z, Y/Z) of pixel `uv`, by Newton
  // iterations on the distortion model (converges to 1e-12 in a few steps
  // inside the image; false if it does not converge, far outside the image).
  bool UnprojectToNormalized(const Eigen::Vector2d& uv,
                             Eigen::Vector2d* xy) const;
  // Unit ray in the camera frame through pixel `uv`.
  bool UnprojectToRay(const Eigen::Vector2d& uv, Eigen::Vector3d* ray) const;
  // True when `uv` lies on the image area, [-0.5, width - 0.5] x
  // [-0.5, height - 0.5] (pixel centres are integers), less `margin_px`.
  bool IsInImage(const Eigen::Vector2d& uv, double margin_px = 0.0) const;

 private:
  std::string name_;
  int width_ = 0;
  int height_ = 0;
  std::array<double, kNumIntrinsics> intrinsics_{};
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_CAMERA_H_
