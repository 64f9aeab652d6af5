// Internal to the trajectory adjustment: the guard of control_guard.h fed
// from the adjustment's state (every matched crossing's vertices placed
// from their stereo observations with the input trajectory and with the
// adjusted one), and the output poses it blends.
#ifndef ZEBRAGEO_ADJUSTMENT_INPUT_GUARD_H_
#define ZEBRAGEO_ADJUSTMENT_INPUT_GUARD_H_

#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/control_guard.h"

namespace zebrageo {
namespace adjustment_internal {

// Every crossing with a point of `state` (control, check, rejected), its
// vertices placed with the input trajectory and with the adjusted one
// (the correction of `state`).
std::vector<GuardCrossing> GuardCrossingsOf(const Context& context,
                                            const State& state);

// The guard's verdict on the adjusted `state`; its stretches warned about.
GuardResult GuardAdjustment(const Context& context, const State& state);

// `adjusted` where the guard stands by the adjusted trajectory, `input`
// where it keeps the input, blended between (positions linearly, rotations
// by slerp) with the guard's weight at `time`.
Pose GuardedPose(const GuardResult& guard, double time, const Pose& adjusted,
                 const Pose& input);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_INPUT_GUARD_H_
