// The posterior covariance of the corrected positions (covariance.h).
#include "adjustment/covariance.h"

#include <ceres/covariance.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace zebrageo {
namespace adjustment_internal {

std::vector<Eigen::Matrix3d> SampleCovariance(
    const Context& context, State* state, AdjustmentProblem* problem,
    std::vector<Eigen::Vector3d>* sd_track_m) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  std::vector<Eigen::Matrix3d> sample_covariance;
  if (problem == nullptr || !options.covariance.compute_covariance ||
      state->correction.num_knots() >
          options.covariance.max_knots_for_covariance) {
    return sample_covariance;
  }
  ceres::Covariance::Options covariance_options;
  covariance_options.num_threads = options.solver.num_threads;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  auto& knots = state->correction.knots();
  const int n = static_cast<int>(knots.size());
  std::vector<std::pair<const double*, const double*>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < std::min(n, i + 4); ++j) {
      pairs.emplace_back(knots[i].data(), knots[j].data());
    }
  }
  if (!covariance.Compute(pairs, problem->problem())) {
    context.Warn(
        "the posterior covariance could not be computed (rank deficient): "
        "trajectory_corrected.csv keeps the input sd_*");
    return sample_covariance;
  }
  const double sigma0 = context.summary->sigma0;
  const double scale = std::max(1.0, sigma0 * sigma0);
  sample_covariance.reserve(trajectory.size());
  if (sd_track_m != nullptr) sd_track_m->clear();
  // An along-track correction held at the input keeps the input's
  // uncertainty, which the lines' error model sizes (State::
  // along_track_held).
  const double held_along_variance =
      state->along_track_held
          ? std::pow(state->model.position_level_sigma_m[0], 2)
          : 0.0;
  for (int s = 0; s < trajectory.size(); ++s) {
    const TrajectorySample& sample = trajectory.samples()[s];
    int first = 0;
    double w[4];
    state->correction.Basis(sample.time, &first, w);
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const int i = std::min(first + a, first + b);
        const int j = std::max(first + a, first + b);
        Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
        covariance.GetCovarianceBlock(knots[i].data(), knots[j].data(),
                                      block.data());
        Eigen::Matrix3d position = block.block<3, 3>(3, 3);
        if (first + a > first + b) position.transposeInPlace();
        C += w[a] * w[b] * position;
      }
    }
    C(0, 0) += held_along_variance;
    if (sd_track_m != nullptr) {
      sd_track_m->push_back((scale * C).diagonal().cwiseMax(0.0).cwiseSqrt());
    }
    // The knots are in the track frame at each sample (along-track, left,
    // up): the samples' sd_* are east, north, up.
    const Eigen::Matrix3d R_enu_track =
        state->correction.Frame(context.dejumped.poses[s]);
    sample_covariance.push_back(scale * R_enu_track * C *
                                R_enu_track.transpose());
  }
  context.summary->covariance_computed = true;
  return sample_covariance;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
