// Residuals of the trajectory adjustment. Frames: ENU (the survey's working
// frame), body (FRD), camera (OpenCV). Knot blocks are [dtheta (rad, ENU
// rotation vector), dp (m, ENU)] of trajectory_correction.h; rotation vectors
// are applied with ceres::AngleAxisRotatePoint (Hamilton, active).
// Every residual is whitened by its sqrt_information (r = S e), so a
// residual of 1 is one standard deviation.
#ifndef ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_
#define ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>

#include "adjustment/trajectory_correction.h"
#include "survey/camera.h"
#include "survey/trajectory.h"

namespace zebrageo {

// Size of a camera's mounting correction block: [dphi (rad, rotation vector
// in the camera frame), dt (m, body frame)], applied as
//   R_body_cam = R_body_cam_nominal * Exp(dphi),
//   t_body_cam = t_body_cam_nominal + dt.
constexpr int kRigCorrectionSize = 6;

// Reprojection of a 3D point (ENU) into a camera of the rig at an exposure
// time t, through the corrected trajectory:
//   c       = sum_j w_j knot_j                       (B-spline at t)
//   dtheta  = R_enu_track c[0:3], dp = R_enu_track c[3:6]
//   X_body  = R_ins^T Exp(-dtheta) (X_enu - p_ins - dp)
//   X_cam   = Exp(-dphi) R_nom^T (X_body - t_nom - dt)
//   r       = S (project(K, D, X_cam) - uv)          (pixels, whitened)
// R_ins, p_ins: the INS pose interpolated at t, R_enu_track the frame of the
// correction there (TrajectoryCorrection::Frame; constants); w_j: basis weights
// at t. PoseReprojectionError is the residual as a function of the correction c
// at t (6), the point (3) and the camera's mounting correction (6);
// SplineReprojectionCost chains it to the 4 knots (dr/dk_j = w_j dr/dc) so
// automatic differentiation runs on 15 dimensions instead of 33.
class PoseReprojectionError {
 public:
  PoseReprojectionError(const Eigen::Vector2d& uv,
                        const Eigen::Matrix2d& sqrt_information,
                        const Pose& ins_pose,
                        const Eigen::Matrix3d& R_enu_track,
                        const Eigen::Isometry3d& T_body_cam,
                        const double* intrinsics)
      : uv_(uv),
        sqrt_information_(sqrt_information),
        R_body_enu_ins_(ins_pose.q_enu_body.toRotationMatrix().transpose()),
        p_enu_ins_(ins_pose.p_enu),
        R_enu_track_(R_enu_track),
        R_cam_body_(T_body_cam.linear().transpose()),
        t_body_cam_(T_body_cam.translation()) {
    for (int i = 0; i < kNumIntrinsics; ++i) intrinsics_[i] = intrinsics[i];
  }

  template <typename T>
  bool operator()(const T* const c, const T* const point_enu,
                  const T* const rig_correction, T* residuals) const {
    T d[3];
    T minus_dtheta[3];
    for (int i = 0; i < 3; ++i) {
      d[i] = point_enu[i] - p_enu_ins_[i] -
             (R_enu_track_(i, 0) * c[3] + R_enu_track_(i, 1) * c[4] +
              R_enu_track_(i, 2) * c[5]);
      minus_dtheta[i] =
          -(R_enu_track_(i, 0) * c[0] + R_enu_track_(i, 1) * c[1] +
            R_enu_track_(i, 2) * c[2]);
    }
    T v[3];
    ceres::AngleAxisRotatePoint(minus_dtheta, d, v);
    T y[3];
    for (int r = 0; r < 3; ++r) {
      y[r] = R_body_enu_ins_(r, 0) * v[0] + R_body_enu_ins_(r, 1) * v[1] +
             R_body_enu_ins_(r, 2) * v[2] - t_body_cam_[r] -
             rig_correction[3 + r];
    }
    T z[3];
    for (int r = 0; r < 3; ++r) {
      z[r] = R_cam_body_(r, 0) * y[0] + R_cam_body_(r, 1) * y[1] +
             R_cam_body_(r, 2) * y[2];
    }
    const T minus_dphi[3] = {-rig_correction[0], -rig_correction[1],
                             -rig_correction[2]};
    T p_cam[3];
    ceres::AngleAxisRotatePoint(minus_dphi, z, p_cam);
    T intrinsics[kNumIntrinsics];
    for (int i = 0; i < kNumIntrinsics; ++i) intrinsics[i] = T(intrinsics_[i]);
    T uv[2];
    if (!ProjectToPixel(intrinsics, p_cam, uv)) return false;
    const T e0 = uv[0] - uv_.x();
    const T e1 = uv[1] - uv_.y();
    residuals[0] = sqrt_information_(0, 0) * e0 + sqrt_information_(0, 1) * e1;
    residuals[1] = sqrt_information_(1, 0) * e0 + sqrt_information_(1, 1) * e1;
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& uv,
                                     const Eigen::Matrix2d& sqrt_information,
                                     const Pose& ins_pose,
                                     const Eigen::Matrix3d& R_enu_track,
                                     const Eigen::Isometry3d& T_body_cam,
                                     const double* intrinsics) {
    return new ceres::AutoDiffCostFunction<PoseReprojectionError, 2, kKnotSize,
                                           3, kRigCorrectionSize>(
        new PoseReprojectionError(uv, sqrt_information, ins_pose, R_enu_track,
                                  T_body_cam, intrinsics));
  }

 private:
  Eigen::Vector2d uv_;
  Eigen::Matrix2d sqrt_information_;
  Eigen::Matrix3d R_body_enu_ins_;
  Eigen::Vector3d p_enu_ins_;
  Eigen::Matrix3d R_enu_track_;
  Eigen::Matrix3d R_cam_body_;
  Eigen::Vector3d t_body_cam_;
  std::array<double, kNumIntrinsics> intrinsics_;
};

// PoseReprojectionError with the camera mounting held at rig.yaml's (no
// self-calibration): 9 differentiated dimensions instead of 15.
struct FixedRigPoseReprojectionError {
  explicit FixedRigPoseReprojectionError(PoseReprojectionError error)
      : error(std::move(error)) {}
  template <typename T>
  bool operator()(const T* const c, const T* const point_enu,
                  T* residuals) const {
    const T zero[kRigCorrectionSize] = {T(0), T(0), T(0), T(0), T(0), T(0)};
    return error(c, point_enu, zero, residuals);
  }
  PoseReprojectionError error;
};

// The reprojection residual on the spline. Blocks: 4 consecutive knots (6
// each), the point (3, ENU) and, when kSelfCalibrating, the camera's
// mounting correction (6).
template <bool kSelfCalibrating>
class SplineReprojectionCostT;

namespace internal {
// Chains dr/dc to the knots: dr/dk_j = w_j dr/dc.
inline void ChainToKnots(const double* weights, const double* d_c,
                         double** jacobians) {
  for (int j = 0; j < 4; ++j) {
    if (jacobians[j] == nullptr) continue;
    for (int i = 0; i < 2 * kKnotSize; ++i)
      jacobians[j][i] = weights[j] * d_c[i];
  }
}
inline void SplineCorrection(const double* weights, double const* const* knots,
                             double* c) {
  for (int i = 0; i < kKnotSize; ++i) {
    c[i] = weights[0] * knots[0][i] + weights[1] * knots[1][i] +
           weights[2] * knots[2][i] + weights[3] * knots[3][i];
  }
}
}  // namespace internal

template <>
class SplineReprojectionCostT<true>
    : public ceres::SizedCostFunction<2, kKnotSize, kKnotSize, kKnotSize,
                                      kKnotSize, 3, kRigCorrectionSize> {
 public:
  SplineReprojectionCostT(const PoseReprojectionError& error,
                          const double weights[4])
      : pose_error_(
            new ceres::AutoDiffCostFunction<PoseReprojectionError, 2, kKnotSize,
                                            3, kRigCorrectionSize>(
                new PoseReprojectionError(error))) {
    for (int j = 0; j < 4; ++j) weights_[j] = weights[j];
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double c[kKnotSize];
    internal::SplineCorrection(weights_, parameters, c);
    const double* inner[3] = {c, parameters[4], parameters[5]};
    if (jacobians == nullptr) {
      return pose_error_->Evaluate(inner, residuals, nullptr);
    }
    double d_c[2 * kKnotSize];
    double* inner_jacobians[3] = {d_c, jacobians[4], jacobians[5]};
    if (!pose_error_->Evaluate(inner, residuals, inner_jacobians)) return false;
    internal::ChainToKnots(weights_, d_c, jacobians);
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> pose_error_;
  double weights_[4];
};

template <>
class SplineReprojectionCostT<false>
    : public ceres::SizedCostFunction<2, kKnotSize, kKnotSize, kKnotSize,
                                      kKnotSize, 3> {
 public:
  SplineReprojectionCostT(const PoseReprojectionError& error,
                          const double weights[4])
      : pose_error_(
            new ceres::AutoDiffCostFunction<FixedRigPoseReprojectionError, 2,
                                            kKnotSize, 3>(
                new FixedRigPoseReprojectionError(error))) {
    for (int j = 0; j < 4; ++j) weights_[j] = weights[j];
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double c[kKnotSize];
    internal::SplineCorrection(weights_, parameters, c);
    const double* inner[2] = {c, parameters[4]};
    if (jacobians == nullptr) {
      return pose_error_->Evaluate(inner, residuals, nullptr);
    }
    double d_c[2 * kKnotSize];
    double* inner_jacobians[2] = {d_c, jacobians[4]};
    if (!pose_error_->Evaluate(inner, residuals, inner_jacobians)) return false;
    internal::ChainToKnots(weights_, d_c, jacobians);
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> pose_error_;
  double weights_[4];
};

// Factory of the spline reprojection residual: with the mounting-correction
// block (self-calibration) or without it.
struct SplineReprojectionCost {
  static ceres::CostFunction* Create(
      const Eigen::Vector2d& uv, const Eigen::Matrix2d& sqrt_information,
      const double weights[4], const Pose& ins_pose,
      const Eigen::Matrix3d& R_enu_track, const Eigen::Isometry3d& T_body_cam,
      const double* intrinsics, bool self_calibrating) {
    const PoseReprojectionError error(uv, sqrt_information, ins_pose,
                                      R_enu_track, T_body_cam, intrinsics);
    if (self_calibrating) {
      return new SplineReprojectionCostT<true>(error, weights);
    }
    return new SplineReprojectionCostT<false>(error, weights);
  }
};

// Prior on a 3D point (a database vertex, ENU), plus the systematic offset
// of its crossing: r = S (X - (X_db + o)). Blocks: point (3), offset (3).
struct PointPriorError {
  PointPriorError(const Eigen::Vector3d& prior_enu,
                  const Eigen::Matrix3d& sqrt_information)
      : prior_enu(prior_enu), sqrt_information(sqrt_information) {}

  template <typename T>
  bool operator()(const T* const point_enu, const T* const offset,
                  T* residuals) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> X(point_enu);
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> o(offset);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residuals);
    r = sqrt_information.cast<T>() * (X - prior_enu.cast<T>() - o);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& prior_enu,
                                     const Eigen::Matrix3d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<PointPriorError, 3, 3, 3>(
        new PointPriorError(prior_enu, sqrt_information));
  }

  Eigen::Vector3d prior_enu;
  Eigen::Matrix3d sqrt_information;
};

// ceres::SizedCostFunction<M, M, ..., M> with N parameter blocks of size M.
template <int M, int N, int... Sizes>
struct RepeatedBlocksCostFunction
    : RepeatedBlocksCostFunction<M, N - 1, M, Sizes...> {};
template <int M, int... Sizes>
struct RepeatedBlocksCostFunction<M, 0, Sizes...> {
  using type = ceres::SizedCostFunction<M, Sizes...>;
};

// A whitened linear combination of N parameter blocks of size M:
//   r = S (sum_j a_j x_j - b)
// The trajectory priors are of this form, on knots (M = 6):
//   GNSS/INS absolute:  a = {1},         b = the INS solution's jumps (or 0)
//   drift rate:         a = {-1, 1}      (k_{i+1} - k_i)
//   drift rate change:  a = {1, -2, 1}   (second difference)
// and the crossing-offset and rig-correction priors (N = 1). Analytic
// Jacobians: dr/dx_j = a_j S.
template <int N, int M>
class LinearPrior : public RepeatedBlocksCostFunction<M, N>::type {
 public:
  static_assert(N >= 1 && M >= 1, "LinearPrior needs N, M >= 1");
  using Matrix = Eigen::Matrix<double, M, M>;
  using Vector = Eigen::Matrix<double, M, 1>;
  LinearPrior(const Matrix& sqrt_information, const std::array<double, N>& a,
              const Vector& b = Vector::Zero())
      : S_(sqrt_information), a_(a), b_(b) {}

  // Owned by the caller (Ceres' problem takes ownership when added).
  static ceres::CostFunction* Create(const Matrix& sqrt_information,
                                     const std::array<double, N>& a,
                                     const Vector& b = Vector::Zero()) {
    return new LinearPrior(sqrt_information, a, b);
  }

  bool Evaluate(double const* const* x, double* residuals,
                double** jacobians) const override {
    Vector sum = -b_;
    for (int j = 0; j < N; ++j) sum += a_[j] * Eigen::Map<const Vector>(x[j]);
    Eigen::Map<Vector> r(residuals);
    r = S_ * sum;
    if (jacobians != nullptr) {
      for (int j = 0; j < N; ++j) {
        if (jacobians[j] == nullptr) continue;
        Eigen::Map<Eigen::Matrix<double, M, M, Eigen::RowMajor>> J(
            jacobians[j]);
        J = a_[j] * S_;
      }
    }
    return true;
  }

 private:
  Matrix S_;
  std::array<double, N> a_;
  Vector b_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_
