// Internal to the trajectory adjustment: variance components. Each soft
// constraint states a sigma (the vehicle's sideslip, the tie points' pixel
// noise); after a solve its residuals say whether the data agree. Where
// they spread more than stated (robust scale of the whitened residuals
// above kInflateAbove), the sigma is widened by that scale and the
// adjustment repeated, so that a constraint that does not fit the data
// (a jittery trajectory's direction of travel, blurred tie points) cannot
// pull the trajectory away from what the control and the INS say; one that
// does not fit at all is dropped, with a warning.
#ifndef ZEBRAGEO_ADJUSTMENT_VARIANCE_COMPONENTS_H_
#define ZEBRAGEO_ADJUSTMENT_VARIANCE_COMPONENTS_H_

#include <string>
#include <vector>

#include "adjustment/adjustment_problem.h"
#include "adjustment/adjustment_state.h"

namespace zebrageo {
namespace adjustment_internal {

// 1.4826 * median(|r|): the standard deviation of normal residuals, robust
// to a few outliers. 0 for none.
double RobustScale(const std::vector<double>& residuals);

// Updates state->model from the residuals of `problem` (solved); true when
// a sigma changed or a constraint was dropped (solve again).
bool UpdateVarianceComponents(const AdjustmentOptions& options,
                              AdjustmentProblem* problem, State* state,
                              std::vector<std::string>* warnings);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_VARIANCE_COMPONENTS_H_
