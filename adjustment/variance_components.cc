#include "adjustment/variance_components.h"

#include <ceres/covariance.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// A group's sigma is widened only when its residuals' robust scale exceeds
// this: with hundreds of residuals the scale is known to a few percent, so
// 1.5 is far outside its noise, and a constraint that merely fits a little
// worse than stated is left alone.
constexpr double kInflateAbove = 1.5;
// A vehicle-motion constraint wider than this says nothing the positions
// do not (its spread is the jitter of the trajectory, not the vehicle's
// sideslip): it is dropped.
constexpr double kMaxMotionSigmaRad = 3.0 * kPi / 180.0;

std::string Degrees(double radians) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << RadToDeg(radians);
  return out.str();
}

// The attitude prior's variance components (Helmert): per axis, the sum of
// the squared whitened innovations over their redundancy, the part of each
// not determined by the other observations, 1 - var_posterior / var_prior
// (Ceres' covariance of the knots). Where the data pull the attitude away
// from the INS beyond what its stated sigma allows (the ratio above the
// 95% chi-square quantile per degree of freedom), its sigma is widened by
// the square root of the ratio. Widening only: the trajectory's own sd is
// the floor. False when nothing changed or the covariance is not
// available.
bool UpdateAttitudeComponents(const AdjustmentOptions& options,
                              AdjustmentProblem* problem, State* state) {
  auto& knots = state->correction.knots();
  const int n = static_cast<int>(knots.size());
  if (n < 2 || n > options.covariance.max_knots_for_covariance) return false;
  ceres::Covariance::Options covariance_options;
  covariance_options.num_threads = options.solver.num_threads;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (int k = 0; k < n; ++k) {
    pairs.emplace_back(knots[k].data(), knots[k].data());
    if (k > 0) pairs.emplace_back(knots[k - 1].data(), knots[k].data());
  }
  if (!covariance.Compute(pairs, problem->problem())) return false;
  const double dt = state->correction.knot_spacing();
  ErrorModel& model = state->model;
  bool changed = false;
  for (int axis = 0; axis < 3; ++axis) {
    const double sigma = model.attitude_sigma_rad[axis];
    const double phi = std::exp(-dt / model.attitude_tau_s[axis]);
    const Eigen::Matrix<double, 6, 1> zero =
        Eigen::Matrix<double, 6, 1>::Zero();
    auto b = [&](int k) -> const Eigen::Matrix<double, 6, 1>& {
      return state->knot_prior.empty() ? zero : state->knot_prior[k];
    };
    double omega = 0.0;
    double redundancy = 0.0;
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> previous, current, cross;
    for (int k = 0; k < n; ++k) {
      covariance.GetCovarianceBlock(knots[k].data(), knots[k].data(),
                                    current.data());
      double innovation = knots[k][axis] - b(k)[axis];
      double prior_variance = sigma * sigma;
      double posterior_variance = current(axis, axis);
      if (k > 0) {
        covariance.GetCovarianceBlock(knots[k - 1].data(), knots[k].data(),
                                      cross.data());
        innovation -= phi * (knots[k - 1][axis] - b(k - 1)[axis]);
        prior_variance *= 1.0 - phi * phi;
        posterior_variance +=
            phi * phi * previous(axis, axis) - 2.0 * phi * cross(axis, axis);
      }
      omega += innovation * innovation / prior_variance;
      redundancy +=
          std::clamp(1.0 - posterior_variance / prior_variance, 0.0, 1.0);
      previous = current;
    }
    if (redundancy < 0.5) continue;
    const double ratio = omega / redundancy;
    const double dof = std::max(1.0, redundancy);
    // 95% chi-square quantile per degree of freedom (Wilson-Hilferty).
    const double a = 2.0 / (9.0 * dof);
    const double c = 1.0 - a + 1.6448536 * std::sqrt(a);
    VLOG(1) << "variance components: attitude axis " << axis << " omega "
            << omega << " redundancy " << redundancy << " ratio " << ratio;
    if (ratio > std::min(c * c * c, kInflateAbove)) {
      const double widened = std::min(options.model.max_attitude_sigma_rad,
                                      sigma * std::sqrt(ratio));
      if (widened > 1.05 * sigma) {
        model.attitude_sigma_rad[axis] = widened;
        changed = true;
      }
    }
  }
  return changed;
}

}  // namespace

double RobustScale(const std::vector<double>& residuals) {
  std::vector<double> magnitude;
  magnitude.reserve(residuals.size());
  for (double r : residuals) magnitude.push_back(std::abs(r));
  return 1.4826 * Median(magnitude);
}

bool UpdateVarianceComponents(const AdjustmentOptions& options,
                              AdjustmentProblem* problem, State* state,
                              std::vector<std::string>* warnings) {
  bool changed = UpdateAttitudeComponents(options, problem, state);
  ErrorModel& model = state->model;
  if (!state->motion.empty()) {
    const std::vector<double> r = problem->Residuals(problem->blocks().motion);
    std::vector<double> lateral, vertical;
    for (size_t i = 0; i + 1 < r.size(); i += 2) {
      lateral.push_back(r[i]);
      vertical.push_back(r[i + 1]);
    }
    const Eigen::Vector2d scale(RobustScale(lateral), RobustScale(vertical));
    for (int axis = 0; axis < 2; ++axis) {
      if (scale[axis] > kInflateAbove) {
        model.motion_sigma_rad[axis] *= scale[axis];
        changed = true;
      }
    }
    VLOG(1) << "variance components: vehicle motion scale " << scale.transpose()
            << ", sigma " << RadToDeg(1.0) * model.motion_sigma_rad.transpose()
            << " deg";
    if (model.motion_sigma_rad.x() > kMaxMotionSigmaRad) {
      const std::string warning =
          "the trajectory's direction of travel departs from its heading by " +
          Degrees(model.motion_sigma_rad.x()) +
          " deg (robust RMS) where the vehicle's sideslip is a tenth of a "
          "degree: its positions are too noisy for the vehicle-motion "
          "constraint, which is not used";
      LogAdjustmentWarning(options, warning);
      warnings->push_back(warning);
      state->motion.clear();
      changed = true;
    }
  }
  if (!state->ties.empty()) {
    const double scale =
        RobustScale(problem->Residuals(problem->blocks().tie_images));
    if (scale > kInflateAbove) {
      model.tie_sigma_px *= scale;
      changed = true;
    }
    VLOG(1) << "variance components: tie scale " << scale << ", sigma "
            << model.tie_sigma_px << " px";
  }
  return changed;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
