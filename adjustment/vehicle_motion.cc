#include "adjustment/vehicle_motion.h"

#include <algorithm>
#include <cmath>

namespace zebrageo {

Eigen::Vector2d CrabAngleResidual(const VehicleMotionSample& sample,
                                  const TrajectoryCorrection& correction,
                                  const double* vehicle) {
  Eigen::Matrix<double, 6, 1> c[3];
  for (int j = 0; j < 3; ++j) c[j] = correction.Evaluate(sample.times[j]);
  Eigen::Vector2d residual;
  const VehicleMotionError error(sample);
  error(c[0].data(), c[1].data(), c[2].data(), vehicle, residual.data());
  return residual.cwiseProduct(
      Eigen::Vector2d(sample.sigma_lateral_rad, sample.sigma_vertical_rad));
}

Eigen::Vector2d HighFrequencyCrabSpread(
    const std::vector<VehicleMotionSample>& samples,
    const TrajectoryCorrection& correction, double window_s) {
  const int n = static_cast<int>(samples.size());
  if (n == 0) return Eigen::Vector2d::Zero();
  const double zero[kVehicleSize] = {0.0, 0.0, 0.0};
  std::vector<Eigen::Vector2d> crab(n);
  for (int i = 0; i < n; ++i) {
    VehicleMotionSample unit = samples[i];
    unit.sigma_lateral_rad = 1.0;
    unit.sigma_vertical_rad = 1.0;
    crab[i] = CrabAngleResidual(unit, correction, zero);
  }
  Eigen::Vector2d spread;
  for (int axis = 0; axis < 2; ++axis) {
    std::vector<double> departures;
    int low = 0;
    int high = 0;
    for (int i = 0; i < n; ++i) {
      const double t = samples[i].times[1];
      while (samples[low].times[1] < t - window_s) ++low;
      while (high < n && samples[high].times[1] <= t + window_s) ++high;
      std::vector<double> window;
      for (int j = low; j < high; ++j) window.push_back(crab[j][axis]);
      std::nth_element(window.begin(), window.begin() + window.size() / 2,
                       window.end());
      departures.push_back(std::abs(crab[i][axis] - window[window.size() / 2]));
    }
    std::nth_element(departures.begin(),
                     departures.begin() + departures.size() / 2,
                     departures.end());
    spread[axis] = 1.4826 * departures[departures.size() / 2];
  }
  return spread;
}

VehicleMotionCost* VehicleMotionCost::Create(
    const VehicleMotionSample& sample, const TrajectoryCorrection& correction) {
  return new VehicleMotionCost(sample, correction);
}

VehicleMotionCost::VehicleMotionCost(const VehicleMotionSample& sample,
                                     const TrajectoryCorrection& correction)
    : error_(
          new ceres::AutoDiffCostFunction<VehicleMotionError, 2, kKnotSize,
                                          kKnotSize, kKnotSize, kVehicleSize>(
              new VehicleMotionError(sample))) {
  std::array<int, 3> first{};
  for (int j = 0; j < 3; ++j) {
    correction.Basis(sample.times[j], &first[j], weights_[j].data());
  }
  first_knot_ = *std::min_element(first.begin(), first.end());
  num_knots_ = *std::max_element(first.begin(), first.end()) + 4 - first_knot_;
  for (int j = 0; j < 3; ++j) offset_[j] = first[j] - first_knot_;
  set_num_residuals(2);
  for (int k = 0; k < num_knots_; ++k) {
    mutable_parameter_block_sizes()->push_back(kKnotSize);
  }
  mutable_parameter_block_sizes()->push_back(kVehicleSize);
}

bool VehicleMotionCost::Evaluate(double const* const* parameters,
                                 double* residuals, double** jacobians) const {
  // The correction at each time from its four knots.
  double c[3][kKnotSize];
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < kKnotSize; ++i) {
      c[j][i] = 0.0;
      for (int a = 0; a < 4; ++a) {
        c[j][i] += weights_[j][a] * parameters[offset_[j] + a][i];
      }
    }
  }
  const double* vehicle = parameters[num_knots_];
  const double* inner[4] = {c[0], c[1], c[2], vehicle};
  if (jacobians == nullptr) {
    return error_->Evaluate(inner, residuals, nullptr);
  }
  double d_c[3][2 * kKnotSize];
  double* inner_jacobians[4] = {d_c[0], d_c[1], d_c[2], jacobians[num_knots_]};
  if (!error_->Evaluate(inner, residuals, inner_jacobians)) return false;
  // dr/dk = sum over the times of w_j(k) dr/dc_j.
  for (int k = 0; k < num_knots_; ++k) {
    if (jacobians[k] == nullptr) continue;
    std::fill(jacobians[k], jacobians[k] + 2 * kKnotSize, 0.0);
  }
  for (int j = 0; j < 3; ++j) {
    for (int a = 0; a < 4; ++a) {
      double* J = jacobians[offset_[j] + a];
      if (J == nullptr) continue;
      for (int i = 0; i < 2 * kKnotSize; ++i) {
        J[i] += weights_[j][a] * d_c[j][i];
      }
    }
  }
  return true;
}

}  // namespace zebrageo
