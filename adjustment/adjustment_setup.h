// Internal to the trajectory adjustment: the state's starting point before
// the solves: the zero correction with the prior's centre at each knot
// (the INS jumps), the vehicle-motion constraints and their sigma, and the
// GNSS/INS error model estimated from the control (error_model.h).
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_SETUP_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_SETUP_H_

#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/control_selection.h"
#include "adjustment/error_model.h"

namespace zebrageo {
namespace adjustment_internal {

// The zero correction over the trajectory, the prior's centre at each knot
// (the jumps taken out before it) and the vehicle-motion constraints
// (state->motion, state->model.motion_sigma_rad).
void InitialiseCorrection(const Context& context, State* state);

// The prior's centre at each knot and what the error gains between knots
// beyond its process (State::knot_prior, knot_extra_variance_m2), from
// `dejumped`'s prior offsets and innovation variances; empty without jumps
// or switches.
void SetKnotPriors(const Context& context, const DejumpedTrajectory& dejumped,
                   State* state);

// The error model the adjustment starts from: the position process fitted
// to the consistent crossings' discrepancies, the attitude from the
// trajectory's own claimed sd, the exposures' jitter where the positions
// show one. Without control crossings (RoadLinesOnly), the position
// process is fitted to the road lines' discrepancies instead.
ErrorModel InitialErrorModel(const Context& context,
                             const std::vector<CrossingDiscrepancy>& d,
                             const State& state);

// The position process of `model` (its position_* members): fitted to the
// discrepancies of the crossings with a control or check point left (with
// road lines, on an axis across the track or in height where those fit to
// the floor, as large as the lines show), or without any (RoadLinesOnly)
// to the road lines' (`d` may then be empty).
void FitPositionModel(const Context& context,
                      const std::vector<CrossingDiscrepancy>& d,
                      const State& state, ErrorModel* model);

// Whether road lines are the only control: no zebra control or check
// point left, matched line points, and line_control_without_crossings.
bool RoadLinesOnly(const AdjustmentOptions& options, const State& state);

// Whether the along-track correction is held at the input's
// (State::along_track_held): road lines alone, none of them holding the
// position along the track (a crossing's edge does, a lane line does not).
bool AlongTrackHeld(const AdjustmentOptions& options, const State& state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_SETUP_H_
