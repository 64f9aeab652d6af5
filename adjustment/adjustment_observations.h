// Internal to the trajectory adjustment: the observations of the state
// (adjustment_state.h) from the adjustment's input: one control point per
// matched database vertex with its stereo and image observations, the tie
// points and the road-line points, each with the INS pose at its time.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OBSERVATIONS_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OBSERVATIONS_H_

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_state.h"

namespace zebrageo {
namespace adjustment_internal {

// One control point per matched database vertex, with its image
// observations; the crossings they belong to. Matches that name no
// reconstructed vertex, no database band, no stereo pair of the rig or an
// exposure outside the trajectory are dropped with a warning.
CrossingTable AddControlPoints(const Context& context, State* state);

// The tie tracks seen in at least two images inside the trajectory
// (summary->num_tie_tracks) and the road-line points inside it.
void AddTieAndLinePoints(const Context& context, State* state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OBSERVATIONS_H_
