// Residuals of the trajectory adjustment that place a point in a camera or
// the body frame through the corrected trajectory: the reprojection of a
// point (control vertex, tie point) and a control vertex as its stereo pair
// reconstructed it (cost_functions.h lists every family).
// Frames: ENU (the survey's working frame), body (FRD), camera (OpenCV).
// Knot blocks are [dtheta (rad, ENU rotation vector), dp (m, ENU)] of
// trajectory_correction.h; rotation vectors are applied with
// ceres::AngleAxisRotatePoint (Hamilton, active). Every residual is
// whitened by its sqrt_information (r = S e), so a residual of 1 is one
// standard deviation.
#ifndef ZEBRAGEO_ADJUSTMENT_REPROJECTION_COSTS_H_
#define ZEBRAGEO_ADJUSTMENT_REPROJECTION_COSTS_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

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
// X_body = R_ins^T Exp(-dtheta) (X_enu - p_ins - dp): an ENU point in the
// body frame of the corrected trajectory at one time (see above), shared by
// the reprojection and the stereo-vertex residuals.
template <typename T>
void CorrectedBodyPoint(const T* c, const T* point_enu,
                        const Eigen::Vector3d& p_enu_ins,
                        const Eigen::Matrix3d& R_enu_track,
                        const Eigen::Matrix3d& R_body_enu_ins, T* x_body) {
  T d[3];
  T minus_dtheta[3];
  for (int i = 0; i < 3; ++i) {
    d[i] = point_enu[i] - p_enu_ins[i] -
           (R_enu_track(i, 0) * c[3] + R_enu_track(i, 1) * c[4] +
            R_enu_track(i, 2) * c[5]);
    minus_dtheta[i] = -(R_enu_track(i, 0) * c[0] + R_enu_track(i, 1) * c[1] +
                        R_enu_track(i, 2) * c[2]);
  }
  T v[3];
  ceres::AngleAxisRotatePoint(minus_dtheta, d, v);
  for (int r = 0; r < 3; ++r) {
    x_body[r] = R_body_enu_ins(r, 0) * v[0] + R_body_enu_ins(r, 1) * v[1] +
                R_body_enu_ins(r, 2) * v[2];
  }
}

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
    T x_body[3];
    CorrectedBodyPoint(c, point_enu, p_enu_ins_, R_enu_track_, R_body_enu_ins_,
                       x_body);
    T y[3];
    for (int r = 0; r < 3; ++r) {
      y[r] = x_body[r] - t_body_cam_[r] - rig_correction[3 + r];
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

// A control vertex as the stereo pair of one exposure reconstructed it:
// its body-frame position and covariance (reconstructed_bands.csv), against
// the point (ENU) placed in the body frame by the corrected trajectory:
//   dtheta = R_enu_track c[0:3], dp = R_enu_track c[3:6]
//   r      = S (R_ins^T Exp(-dtheta) (X_enu - p_ins - dp) - p_body)
// S the whitening of the body covariance. Each exposure's observation then
// depends on that exposure's pose alone: unlike the reprojection of one
// point into several exposures, a small error of the INS relative motion
// between exposures cannot shift the point along the viewing direction
// (the motion parallax of a point 10-15 m ahead is a weak, easily biased
// measure of its depth; the rig's stereo baseline is not).
class StereoVertexError {
 public:
  StereoVertexError(const Eigen::Vector3d& p_body,
                    const Eigen::Matrix3d& sqrt_information,
                    const Pose& ins_pose, const Eigen::Matrix3d& R_enu_track)
      : p_body_(p_body),
        sqrt_information_(sqrt_information),
        R_body_enu_ins_(ins_pose.q_enu_body.toRotationMatrix().transpose()),
        p_enu_ins_(ins_pose.p_enu),
        R_enu_track_(R_enu_track) {}

  template <typename T>
  bool operator()(const T* const c, const T* const point_enu,
                  T* residuals) const {
    T x_body[3];
    CorrectedBodyPoint(c, point_enu, p_enu_ins_, R_enu_track_, R_body_enu_ins_,
                       x_body);
    T e[3];
    for (int r = 0; r < 3; ++r) e[r] = x_body[r] - p_body_[r];
    for (int r = 0; r < 3; ++r) {
      residuals[r] = sqrt_information_(r, 0) * e[0] +
                     sqrt_information_(r, 1) * e[1] +
                     sqrt_information_(r, 2) * e[2];
    }
    return true;
  }

 private:
  Eigen::Vector3d p_body_;
  Eigen::Matrix3d sqrt_information_;
  Eigen::Matrix3d R_body_enu_ins_;
  Eigen::Vector3d p_enu_ins_;
  Eigen::Matrix3d R_enu_track_;
};

// StereoVertexError chained to the 4 knots at the exposure, then the point.
class SplineStereoVertexCost
    : public ceres::SizedCostFunction<3, kKnotSize, kKnotSize, kKnotSize,
                                      kKnotSize, 3> {
 public:
  SplineStereoVertexCost(const StereoVertexError& error,
                         const double weights[4])
      : error_(
            new ceres::AutoDiffCostFunction<StereoVertexError, 3, kKnotSize, 3>(
                new StereoVertexError(error))) {
    for (int j = 0; j < 4; ++j) weights_[j] = weights[j];
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double c[kKnotSize];
    internal::SplineCorrection(weights_, parameters, c);
    const double* inner[2] = {c, parameters[4]};
    if (jacobians == nullptr) {
      return error_->Evaluate(inner, residuals, nullptr);
    }
    double d_c[3 * kKnotSize];
    double* inner_jacobians[2] = {d_c, jacobians[4]};
    if (!error_->Evaluate(inner, residuals, inner_jacobians)) return false;
    for (int j = 0; j < 4; ++j) {
      if (jacobians[j] == nullptr) continue;
      for (int i = 0; i < 3 * kKnotSize; ++i) {
        jacobians[j][i] = weights_[j] * d_c[i];
      }
    }
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> error_;
  double weights_[4];
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_REPROJECTION_COSTS_H_
