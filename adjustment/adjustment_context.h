// Internal to the trajectory adjustment (trajectory_adjuster.h): the
// context its steps share (control selection, problem building, blunder
// loop, covariance, outputs; see adjustment_state.h for the state they
// change) and the crossings of the matched control.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_CONTEXT_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_CONTEXT_H_

#include <glog/logging.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "adjustment/trajectory_jumps.h"
#include "survey/trajectory.h"

namespace zebrageo {
namespace adjustment_internal {

// What every step of the adjustment reads (the options, the input, the
// INS trajectory without its jumps) and where it reports: warnings go to
// the log and to summary->warnings.
struct Context {
  const AdjustmentOptions& options;
  const AdjustmentInput& input;
  DejumpedTrajectory dejumped;
  AdjustmentSummary* summary;
  // Checked between solves and the solver's iterations.
  CancellationToken cancel;

  void Warn(const std::string& warning) const {
    LogAdjustmentWarning(options, warning);
    summary->warnings.push_back(warning);
  }
  bool InsPoseAt(double time, Pose* pose) const {
    return InterpolateDejumped(*input.trajectory, dejumped, time, pose);
  }
};

// The matched database crossings, in the order their control points first
// appear (the index of ControlPoint::crossing).
struct CrossingTable {
  std::vector<std::string> names;
  std::vector<double> first_time;
  // One band period across the crossing (ENU), from the database.
  std::vector<Eigen::Vector3d> period_enu;
};

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_CONTEXT_H_
