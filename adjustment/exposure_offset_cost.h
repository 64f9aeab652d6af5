// The exposure's fast position offset (the GNSS/INS jitter,
// trajectory_jitter.h) added to any residual on the spline at an exposure
// (cost_functions.h lists every family).
// Frames: ENU (the survey's working frame), body (FRD), camera (OpenCV).
// Knot blocks are [dtheta (rad, ENU rotation vector), dp (m, ENU)] of
// trajectory_correction.h; rotation vectors are applied with
// ceres::AngleAxisRotatePoint (Hamilton, active). Every residual is
// whitened by its sqrt_information (r = S e), so a residual of 1 is one
// standard deviation.
#ifndef ZEBRAGEO_ADJUSTMENT_EXPOSURE_OFFSET_COST_H_
#define ZEBRAGEO_ADJUSTMENT_EXPOSURE_OFFSET_COST_H_

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

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_EXPOSURE_OFFSET_COST_H_
