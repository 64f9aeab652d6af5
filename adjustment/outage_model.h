// Internal to the trajectory adjustment: what a jump of the GNSS/INS
// position means, decided by the control (issue 43).
//
// A jump where GNSS returns after an outage is the difference between two
// errors: the INS's drift accrued through the outage (growing with time and
// distance: a velocity bias, an acceleration bias, a heading error times
// the distance travelled) and the GNSS's own error when it comes back. The
// jump alone cannot say which: the error before it may be the drift (the
// GNSS after it right), the error after it may be the GNSS's (the INS
// before it right), or both. Each reading is a hypothesis about the centre
// of the GNSS/INS prior (DejumpedTrajectory::prior_position_offset, where
// the correction goes without control):
//   - as found: the jump a step (the stated sd did not grow), or the
//     closure spread back over the outage the stated sd show
//     (SpreadOutageClosures);
//   - the INS drifted through an outage of L seconds before the jump,
//     growing as t or t^2 to the jump (L from outage_min_length_s to
//     outage_max_length_s: the stated sd do not say when it began);
//   - the GNSS came back wrong by the jump, its error decaying after it;
//   - half of each.
// Each is tested against the crossings (and the road lines and whole
// dashes) as the control selection tests them (control_selection.h): the
// hypothesis that keeps the most control wins; between those that keep as
// much, the likelihood decides: of the Gauss-Markov fit of the kept
// control, and of the vehicle's motion (vehicle_motion.h: an INS drifting
// from a velocity error moves across its own heading, which the right
// reading's prior takes out). The one found stays unless another keeps
// more, or as much far more likely.
//
// Frames: ENU for the prior offsets; times in the trajectory's seconds.
#ifndef ZEBRAGEO_ADJUSTMENT_OUTAGE_MODEL_H_
#define ZEBRAGEO_ADJUSTMENT_OUTAGE_MODEL_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/trajectory_jumps.h"

namespace zebrageo {
namespace adjustment_internal {

// One reading of one jump: how the jump `position_jump_enu` at samples
// [first, last] of the trajectory is shared between the outage before it
// and the GNSS after it.
struct OutageHypothesis {
  std::string name;  // for the log and the report
  // Share of the jump that is the INS's drift (spread back over the
  // outage); the rest is the GNSS's error after it.
  double ins_share = 0.0;
  double outage_length_s = 0.0;  // 0: no outage part
  double growth_power = 2.0;     // the drift grows as (t / L)^power
  double gnss_decay_s = 0.0;     // 0: no GNSS part
  bool as_found = false;         // the dejumped trajectory's own prior
};

// The readings tried first for a jump at `jump_time_s` (the one as found
// first): the INS's drift growing as t^2 through outages of each length
// up to `floor_time_s` before it, the GNSS's error decaying over each
// time.
std::vector<OutageHypothesis> OutageHypotheses(const NeverWorseOptions& options,
                                               double jump_time_s,
                                               double floor_time_s);

// Then, at the best outage's length: the drift growing with t, and half of
// the jump the GNSS's error (either growth).
std::vector<OutageHypothesis> RefinedOutageHypotheses(
    const NeverWorseOptions& options, const OutageHypothesis& outage);

// `dejumped` with the prior offsets and innovation variances of reading
// `h` for jump `jump` (the other jumps as they are); `floor` is the first
// sample its outage may begin at.
void ApplyOutageHypothesis(const Trajectory& trajectory, const JumpEvent& jump,
                           int floor, const OutageHypothesis& h,
                           DejumpedTrajectory* dejumped);

// For each jump of at least NeverWorseOptions::outage_min_jump_m, in time
// order, the reading that explains the most control: sets
// context->dejumped's prior and the state's knot priors to it. Returns one
// sentence per jump whose reading changed ("" entries omitted).
std::vector<std::string> ChooseOutageModel(Context* context,
                                           const CrossingTable& crossings,
                                           State* state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_OUTAGE_MODEL_H_
