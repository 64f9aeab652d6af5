// Internal to the trajectory adjustment: the posterior covariance of the
// corrected trajectory's positions, from the knots' covariance (Ceres,
// SPARSE_QR) propagated through the B-spline basis and scaled by sigma0^2
// when sigma0 > 1.
#ifndef ZEBRAGEO_ADJUSTMENT_COVARIANCE_H_
#define ZEBRAGEO_ADJUSTMENT_COVARIANCE_H_

#include <Eigen/Core>
#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_problem.h"
#include "adjustment/adjustment_state.h"

namespace zebrageo {
namespace adjustment_internal {

// Posterior covariance of each trajectory sample's position (ENU, m^2), or
// empty when not computed (compute_covariance off, more knots than
// max_knots_for_covariance, no problem, or rank deficient: a warning).
// Sets summary->covariance_computed. `sd_track_m` (may be null) receives
// the same per sample as sd along-track, cross-track and up (the knots'
// frame), or is left empty.
std::vector<Eigen::Matrix3d> SampleCovariance(
    const Context& context, State* state, AdjustmentProblem* problem,
    std::vector<Eigen::Vector3d>* sd_track_m = nullptr);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_COVARIANCE_H_
