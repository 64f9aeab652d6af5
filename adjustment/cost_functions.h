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

// The first-order Gauss-Markov prior of three components (offset, offset
// + 1, offset + 2) of the knots: for the first knot (one block)
//   r_i = (c_0[j] - b_0[j]) / sigma_i,
// for the others (blocks k - 1, k)
//   r_i = ((c_k[j] - b_k[j]) - phi_i (c_{k-1}[j] - b_{k-1}[j]))
//         / (sigma_i sqrt(1 - phi_i^2)),
// j = offset + i, phi_i = exp(-knot_spacing / tau_i): the innovations of a
// correlated process, independent of each other (adjustment_state.h).
class KnotProcessPrior : public ceres::CostFunction {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  // The first knot's prior: b = b_0.
  static ceres::CostFunction* CreateFirst(int offset,
                                          const Eigen::Vector3d& sigma,
                                          const Vector6& b) {
    return new KnotProcessPrior(offset, sigma, Eigen::Vector3d::Zero(), b,
                                Vector6::Zero(), false);
  }
  // The innovation from knot k - 1 (first block) to knot k (second).
  static ceres::CostFunction* CreateStep(int offset,
                                         const Eigen::Vector3d& sigma,
                                         const Eigen::Vector3d& phi,
                                         const Vector6& b_previous,
                                         const Vector6& b) {
    return new KnotProcessPrior(offset, sigma, phi, b, b_previous, true);
  }

  bool Evaluate(double const* const* x, double* residuals,
                double** jacobians) const override {
    const double* current = step_ ? x[1] : x[0];
    for (int i = 0; i < 3; ++i) {
      const int j = offset_ + i;
      double e = current[j] - b_[j];
      if (step_) e -= phi_[i] * (x[0][j] - b_previous_[j]);
      residuals[i] = s_[i] * e;
    }
    if (jacobians == nullptr) return true;
    for (int block = 0; block < (step_ ? 2 : 1); ++block) {
      if (jacobians[block] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> J(
          jacobians[block]);
      J.setZero();
      const bool is_current = !step_ || block == 1;
      for (int i = 0; i < 3; ++i) {
        J(i, offset_ + i) = is_current ? s_[i] : -phi_[i] * s_[i];
      }
    }
    return true;
  }

 private:
  KnotProcessPrior(int offset, const Eigen::Vector3d& sigma,
                   const Eigen::Vector3d& phi, const Vector6& b,
                   const Vector6& b_previous, bool step)
      : offset_(offset),
        phi_(phi),
        b_(b),
        b_previous_(b_previous),
        step_(step) {
    for (int i = 0; i < 3; ++i) {
      const double innovation =
          step ? std::sqrt(std::max(1e-12, 1.0 - phi[i] * phi[i])) : 1.0;
      s_[i] = 1.0 / (sigma[i] * innovation);
    }
    set_num_residuals(3);
    mutable_parameter_block_sizes()->assign(step ? 2 : 1, kKnotSize);
  }

  int offset_;
  Eigen::Vector3d phi_;
  Vector6 b_;
  Vector6 b_previous_;
  bool step_;
  Eigen::Vector3d s_;
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

// A residual whose first four blocks are the knots of the spline at an
// exposure (SplineReprojectionCost, LinePointCost), with the exposure's
// fast position offset delta (3, track frame: the jitter of the GNSS/INS
// positions, adjustment_state.h) added to the correction there:
//   c = sum_j w_j k_j + [0, delta] = sum_j w_j (k_j + [0, delta])
// since the weights sum to 1. The inner cost sees the shifted knots; the
// offset block comes last, dr/ddelta = sum_j dr/dk_j[:, 3:6].
class WithExposureOffset : public ceres::CostFunction {
 public:
  // Takes ownership of `inner`.
  explicit WithExposureOffset(ceres::CostFunction* inner) : inner_(inner) {
    *mutable_parameter_block_sizes() = inner->parameter_block_sizes();
    mutable_parameter_block_sizes()->push_back(3);
    set_num_residuals(inner->num_residuals());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int blocks = static_cast<int>(inner_->parameter_block_sizes().size());
    const double* delta = parameters[blocks];
    std::array<std::array<double, kKnotSize>, 4> knots;
    std::vector<const double*> inner(parameters, parameters + blocks);
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < kKnotSize; ++i) {
        knots[j][i] = parameters[j][i] + (i >= 3 ? delta[i - 3] : 0.0);
      }
      inner[j] = knots[j].data();
    }
    if (jacobians == nullptr) {
      return inner_->Evaluate(inner.data(), residuals, nullptr);
    }
    const int m = num_residuals();
    // The knots' Jacobians are needed for delta's even when Ceres does not
    // ask for them.
    std::vector<std::vector<double>> own(4);
    std::vector<double*> inner_jacobians(jacobians, jacobians + blocks);
    for (int j = 0; j < 4; ++j) {
      if (inner_jacobians[j] == nullptr) {
        own[j].resize(m * kKnotSize);
        inner_jacobians[j] = own[j].data();
      }
    }
    if (!inner_->Evaluate(inner.data(), residuals, inner_jacobians.data())) {
      return false;
    }
    if (jacobians[blocks] != nullptr) {
      for (int r = 0; r < m; ++r) {
        for (int i = 0; i < 3; ++i) {
          double sum = 0.0;
          for (int j = 0; j < 4; ++j) {
            sum += inner_jacobians[j][r * kKnotSize + 3 + i];
          }
          jacobians[blocks][r * 3 + i] = sum;
        }
      }
    }
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
};

// The first-order Gauss-Markov prior of a sequence of 3-vectors (the
// exposures' fast position offsets): for the first, r = x_0 / sigma; then
//   r = (x_k - phi x_{k-1}) / (sigma sqrt(1 - phi^2)),
// per component, phi = exp(-dt / tau) with dt the time between the two.
class VectorProcessPrior : public ceres::CostFunction {
 public:
  static ceres::CostFunction* CreateFirst(const Eigen::Vector3d& sigma) {
    return new VectorProcessPrior(sigma, Eigen::Vector3d::Zero(), false);
  }
  static ceres::CostFunction* CreateStep(const Eigen::Vector3d& sigma,
                                         const Eigen::Vector3d& phi) {
    return new VectorProcessPrior(sigma, phi, true);
  }

  bool Evaluate(double const* const* x, double* residuals,
                double** jacobians) const override {
    const double* current = step_ ? x[1] : x[0];
    for (int i = 0; i < 3; ++i) {
      double e = current[i];
      if (step_) e -= phi_[i] * x[0][i];
      residuals[i] = s_[i] * e;
    }
    if (jacobians == nullptr) return true;
    for (int block = 0; block < (step_ ? 2 : 1); ++block) {
      if (jacobians[block] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(
          jacobians[block]);
      J.setZero();
      const bool is_current = !step_ || block == 1;
      for (int i = 0; i < 3; ++i) {
        J(i, i) = is_current ? s_[i] : -phi_[i] * s_[i];
      }
    }
    return true;
  }

 private:
  VectorProcessPrior(const Eigen::Vector3d& sigma, const Eigen::Vector3d& phi,
                     bool step)
      : phi_(phi), step_(step) {
    for (int i = 0; i < 3; ++i) {
      const double innovation =
          step ? std::sqrt(std::max(1e-12, 1.0 - phi[i] * phi[i])) : 1.0;
      s_[i] = 1.0 / (sigma[i] * innovation);
    }
    set_num_residuals(3);
    mutable_parameter_block_sizes()->assign(step ? 2 : 1, 3);
  }

  Eigen::Vector3d phi_;
  bool step_;
  Eigen::Vector3d s_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_
