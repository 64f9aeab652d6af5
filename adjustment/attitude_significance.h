// Internal to the trajectory adjustment: which axes of the attitude
// correction the control determines (AdjustmentOptions::
// attitude_significance). A crossing seen from a few metres measures the
// heading to about a tenth of a degree, a good INS gives it to a few
// hundredths: the posterior barely tightens, and a correction of a fraction
// of its own sd is noise that makes the attitude worse as often as better.
// An axis is significant when at some knot its correction departs from the
// prior's centre (the input attitude) by attitude_significance posterior
// sd; the others are held at the input (State::attitude_held) and the
// adjustment solved again.
#ifndef ZEBRAGEO_ADJUSTMENT_ATTITUDE_SIGNIFICANCE_H_
#define ZEBRAGEO_ADJUSTMENT_ATTITUDE_SIGNIFICANCE_H_

#include <Eigen/Core>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_problem.h"
#include "adjustment/adjustment_state.h"

namespace zebrageo {
namespace adjustment_internal {

// Per attitude axis (along-track, cross-track, up): the largest
// |correction - prior centre| / posterior sd over the knots, the posterior
// scaled by sigma0^2 when sigma0 > 1. Empty (false) when the covariance is
// not computed (options, too many knots, rank deficient).
bool AttitudeSignificance(const Context& context, const State& state,
                          AdjustmentProblem* problem,
                          Eigen::Vector3d* significance);

// Holds the axes below attitude_significance, and every axis with fewer
// than two control crossings (their covariance is then not computed):
// State::attitude_held, logged and in the summary. Returns whether any was
// newly held: the caller solves again.
bool HoldInsignificantAttitude(const Context& context, State* state,
                               AdjustmentProblem* problem);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ATTITUDE_SIGNIFICANCE_H_
