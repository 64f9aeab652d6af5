// Internal to the trajectory adjustment: the results (trajectory_adjuster.h,
// AdjustmentResult) from the final state.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OUTPUTS_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OUTPUTS_H_

#include <functional>
#include <string>
#include <vector>

#include "adjustment/adjustment_state.h"
#include "adjustment/control_guard.h"
#include "adjustment/trajectory_adjuster.h"
#include "adjustment/trajectory_jumps.h"

namespace zebrageo {
namespace adjustment_internal {

// What the outputs read besides the state.
struct OutputContext {
  const AdjustmentOptions* options = nullptr;
  const AdjustmentInput* input = nullptr;
  const DejumpedTrajectory* dejumped = nullptr;
  // false: the trajectory was not corrected (no usable control): every
  // output carries the input trajectory exactly.
  bool adjusted = true;
  // Posterior covariance of each sample's position (ENU), or empty.
  std::vector<Eigen::Matrix3d> sample_covariance;
  // Where the guard keeps the input trajectory (control_guard.h), or null.
  const GuardResult* guard = nullptr;
  std::function<void(const std::string&)> warn;
};

// The corrected body pose at `time`: the correction applied to the
// de-jumped INS trajectory (blended into the input where the guard keeps
// it), or the input trajectory itself when not adjusted. False outside the
// trajectory.
bool OutputPoseAt(const OutputContext& context, const State& state, double time,
                  Pose* pose);

// The exposures' fast position offsets (ENU) at `time`: an exposure's own
// at its time, linear between exposures, zero outside them or without
// jitter.
Eigen::Vector3d ExposureOffsetAt(const State& state, double time);

// Corrected samples and poses, camera poses, bands, control point results
// and the summary's figures derived from them. False (summary.message set)
// when the corrected trajectory is not finite.
bool FillOutputs(const OutputContext& context, State* state,
                 AdjustmentResult* result);

// RMS crab angles (lateral, vertical) the vehicle-motion constraint leaves,
// degrees (the unit of adjustment.json's rms table).
Eigen::Vector2d CrabRmsDeg(const State& state);

// The summary's RMS of each observation type before (`before`,
// `crab_before_deg`: the INS trajectory and the database points) and after
// the adjustment, the vehicle block and the final error model.
void SummariseFinalState(const OutputContext& context, const State& state,
                         const StateRms& before, const StateRms& after,
                         const Eigen::Vector2d& crab_before_deg,
                         AdjustmentSummary* summary);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OUTPUTS_H_
