#include "survey/camera.h"

#include <Eigen/LU>
#include <cmath>
#include <utility>

namespace zebrageo {

Camera::Camera(std::string name, int width, int height, double fx, double fy,
               double cx, double cy, const std::array<double, 5>& distortion)
    : name_(std::move(name)), width_(width), height_(height) {
  intrinsics_ = {fx,
                 fy,
                 cx,
                 cy,
                 distortion[0],
                 distortion[1],
                 distortion[2],
                 distortion[3],
                 distortion[4]};
}

std::array<double, 5> Camera::distortion() const {
  return {intrinsics_[4], intrinsics_[5], intrinsics_[6], intrinsics_[7],
          intrinsics_[8]};
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d K;
  K << fx(), 0.0, cx(), 0.0, fy(), cy(), 0.0, 0.0, 1.0;
  return K;
}

bool Camera::Project(const Eigen::Vector3d& p_cam, Eigen::Vector2d* uv) const {
  return ProjectToPixel(intrinsics_.data(), p_cam.data(), uv->data());
}

bool Camera::UnprojectToNormalized(const Eigen::Vector2d& uv,
                                   Eigen::Vector2d* xy) const {
  const double k1 = intrinsics_[4], k2 = intrinsics_[5], p1 = intrinsics_[6],
               p2 = intrinsics_[7], k3 = intrinsics_[8];
  const Eigen::Vector2d target((uv.x() - cx()) / fx(), (uv.y() - cy()) / fy());
  // Newton on distort(x) = target from the undistorted guess. Unlike
  // OpenCV's fixed-point undistortPoints, it converges quadratically, so
  // project(unproject(uv)) == uv to ~1e-12 px wherever the model is
  // invertible.
  Eigen::Vector2d x = target;
  constexpr int kMaxIterations = 30;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    const double r2 = x.squaredNorm();
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    Eigen::Vector2d distorted;
    DistortNormalized(intrinsics_.data(), x.x(), x.y(), &distorted.x(),
                      &distorted.y());
    const Eigen::Vector2d residual = distorted - target;
    Eigen::Matrix2d J;
    J(0, 0) = radial + 2.0 * x.x() * x.x() * dradial + 2.0 * p1 * x.y() +
              6.0 * p2 * x.x();
    J(0, 1) =
        2.0 * x.x() * x.y() * dradial + 2.0 * p1 * x.x() + 2.0 * p2 * x.y();
    J(1, 0) =
        2.0 * x.x() * x.y() * dradial + 2.0 * p1 * x.x() + 2.0 * p2 * x.y();
    J(1, 1) = radial + 2.0 * x.y() * x.y() * dradial + 6.0 * p1 * x.y() +
              2.0 * p2 * x.x();
    // A non-positive determinant means we are past the fold of the
    // distortion polynomial, where pixels have no physical ray.
    const double det = J.determinant();
    if (!(det > 1e-6)) return false;
    if (residual.norm() < 1e-15) {
      *xy = x;
      return true;
    }
    x -= J.inverse() * residual;
    if (!x.allFinite()) return false;
  }
  Eigen::Vector2d distorted;
  DistortNormalized(intrinsics_.data(), x.x(), x.y(), &distorted.x(),
                    &distorted.y());
  if ((distorted - target).norm() > 1e-12) return false;
  *xy = x;
  return true;
}

bool Camera::UnprojectToRay(const Eigen::Vector2d& uv,
                            Eigen::Vector3d* ray) const {
  Eigen::Vector2d xy;
  if (!UnprojectToNormalized(uv, &xy)) return false;
  *ray = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
  return true;
}

bool Camera::IsInImage(const Eigen::Vector2d& uv, double margin_px) const {
  return uv.x() >= -0.5 + margin_px && uv.y() >= -0.5 + margin_px &&
         uv.x() <= width_ - 0.5 - margin_px &&
         uv.y() <= height_ - 0.5 - margin_px;
}

}  // namespace zebrageo
