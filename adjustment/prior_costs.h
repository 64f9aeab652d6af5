// Prior residuals of the trajectory adjustment: a database vertex with its
// crossing's offset, linear priors on knots and blocks, and the
// Gauss-Markov priors of the knots and of the exposures' offsets
// (cost_functions.h lists every family).
// Frames: ENU (the survey's working frame), body (FRD), camera (OpenCV).
// Knot blocks are [dtheta (rad, ENU rotation vector), dp (m, ENU)] of
// trajectory_correction.h; rotation vectors are applied with
// ceres::AngleAxisRotatePoint (Hamilton, active). Every residual is
// whitened by its sqrt_information (r = S e), so a residual of 1 is one
// standard deviation.
#ifndef ZEBRAGEO_ADJUSTMENT_PRIOR_COSTS_H_
#define ZEBRAGEO_ADJUSTMENT_PRIOR_COSTS_H_

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

namespace zebrageo {

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

#endif  // ZEBRAGEO_ADJUSTMENT_PRIOR_COSTS_H_
