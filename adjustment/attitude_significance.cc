// Attitude axes the control does not determine (attitude_significance.h).
#include "adjustment/attitude_significance.h"

#include <ceres/covariance.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

namespace zebrageo {
namespace adjustment_internal {

bool AttitudeSignificance(const Context& context, const State& state,
                          AdjustmentProblem* problem,
                          Eigen::Vector3d* significance) {
  const AdjustmentOptions& options = context.options;
  const auto& knots = state.correction.knots();
  const int n = static_cast<int>(knots.size());
  if (problem == nullptr || !options.covariance.compute_covariance ||
      n > options.covariance.max_knots_for_covariance) {
    return false;
  }
  ceres::Covariance::Options covariance_options;
  covariance_options.num_threads = options.solver.num_threads;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const Knot& k : knots) pairs.emplace_back(k.data(), k.data());
  if (!covariance.Compute(pairs, problem->problem())) return false;
  const double sigma0 = context.summary->sigma0;
  const double scale = std::max(1.0, sigma0 * sigma0);
  significance->setZero();
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix<double, kKnotSize, kKnotSize, Eigen::RowMajor> block;
    covariance.GetCovarianceBlock(knots[k].data(), knots[k].data(),
                                  block.data());
    for (int a = 0; a < 3; ++a) {
      const double sd = std::sqrt(scale * block(a, a));
      const double centre =
          state.knot_prior.empty() ? 0.0 : state.knot_prior[k][a];
      const double departure = std::abs(knots[k][a] - centre);
      if (sd > 0.0 && std::isfinite(sd)) {
        (*significance)[a] = std::max((*significance)[a], departure / sd);
      }
    }
  }
  return true;
}

bool HoldInsignificantAttitude(const Context& context, State* state,
                               AdjustmentProblem* problem) {
  const double threshold = context.options.model.attitude_significance;
  if (threshold <= 0.0) return false;
  // One crossing, seen on one approach, measures the heading only together
  // with the rate of the cross-track drift (both turn its bands the same
  // way as the vehicle nears it), and the tilt with the vertical drift's:
  // the split is the priors', not the data's. Two crossings apart measure
  // the drift between them. So with one, every axis is held (significance
  // 0, not computed).
  std::set<int> crossings;
  for (const ControlPoint& p : state->points) {
    if (p.status == ControlStatus::kControl) crossings.insert(p.crossing);
  }
  Eigen::Vector3d significance = Eigen::Vector3d::Zero();
  if (crossings.size() >= 2 &&
      !AttitudeSignificance(context, *state, problem, &significance)) {
    return false;
  }
  context.summary->attitude_significance = significance;
  static const char* const kAxes[3] = {"along-track", "cross-track", "up"};
  std::ostringstream held;
  held.setf(std::ios::fixed);
  held.precision(2);
  bool any = false;
  for (int a = 0; a < 3; ++a) {
    if (state->attitude_held[a] || significance[a] >= threshold) continue;
    state->attitude_held[a] = true;
    context.summary->attitude_held[a] = 1;
    held << (any ? ", " : "") << "about " << kAxes[a] << " (" << significance[a]
         << " sd)";
    any = true;
  }
  if (any) {
    LOG(INFO) << "adjustment: attitude corrections below " << threshold
              << " posterior sd, held at the input's: " << held.str();
  }
  return any;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
