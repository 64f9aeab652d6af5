// Jumps of the GNSS/INS solution (GNSS coming back after an outage): the
// adjustment works on the trajectory with its jumps taken out, so that what
// remains is the INS relative motion, continuous, and the prior on the
// correction follows the jumps instead (trajectory_adjuster.h): the input's
// error steps at a jump, or, where the jump closes an outage, grew through
// it.
//
// Frames: ENU (the survey's working frame), body FRD; metres, radians.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "adjustment/trajectory_switches.h"
#include "survey/trajectory.h"

namespace zebrageo {

// The GNSS/INS trajectory with its jumps removed: sample-to-sample steps
// that depart from the motion of the neighbouring samples (a robust median
// of their steps) by more than the thresholds are taken out, so what
// remains is the INS relative motion, continuous. `offset_enu` and
// `rotation_offset` give, per sample, what was taken out (original =
// offset * dejumped for rotations, original = dejumped + offset for
// positions).
struct DejumpedTrajectory {
  std::vector<Pose> poses;
  std::vector<Eigen::Vector3d> position_offset;
  std::vector<Eigen::Quaterniond> rotation_offset;
  // The centre of the GNSS/INS prior at each sample (where the correction
  // goes without control): the offsets, with each outage's closure spread
  // back over the outage (SpreadOutageClosures).
  std::vector<Eigen::Vector3d> prior_position_offset;
  std::vector<Eigen::Quaterniond> prior_rotation_offset;
  // Variance the GNSS/INS error gains from the sample before to each
  // sample beyond its correlated process (m^2, per axis): where a jump stays
  // a step, its square (the input's error steps there, the INS does not);
  // through an outage closed by a jump, a quarter of the closure's square
  // spread as the closure is, since the stated variance says where the
  // drift accrued but not its exact shape; zero elsewhere.
  std::vector<double> innovation_variance_m2;
  // The same for the cross-track axis alone (m^2): a sideways switch's
  // square, at its steps (its error steps across the track only).
  std::vector<double> cross_track_innovation_variance_m2;
  int num_jumps = 0;
  int num_closed_outages = 0;
  // Sideways switches taken out as jumps (trajectory_switches.h), and per
  // sample whether the step into it is one of their steps (not a jump).
  std::vector<SidewaysSwitch> switches;
  std::vector<bool> switch_step;
};

// Samples [first, last] over which the offsets change: one jump, which may
// take a few samples.
struct JumpEvent {
  int first = 0;
  int last = 0;
};

// The jumps of `dejumped` in time order (a sideways switch's steps are
// not jumps).
std::vector<JumpEvent> JumpEvents(const DejumpedTrajectory& dejumped);

// A step that departs from its neighbours' motion by more than threshold_m
// (position) or threshold_rad (attitude), or by more than 8 times the
// trajectory's median departure where that is larger, is a jump. A
// threshold of 0 disables that part. The sideways switches
// (FindSidewaysSwitches with `switches`) are taken out as jumps spread over
// their steps: their error steps there, as a jump's does.
DejumpedTrajectory RemoveJumps(
    const Trajectory& trajectory, double threshold_m, double threshold_rad,
    const SidewaysSwitchOptions& switches = SidewaysSwitchOptions());

// A jump where the GNSS returns after an outage (the stated sd grew before
// it and falls back at it) is the closure of the INS's dead reckoning: the
// drift it accrued through the outage, measured at its end. The INS before
// the jump is then not right up to it and wrong after, as a step in the
// prior's centre would say: its error grew through the outage. As a
// fixed-interval smoother does, the closure is spread back over the
// outage in proportion to the variance the solution states it accrued
// there (position and attitude each by their own sd), so that without
// control the corrected trajectory is continuous and meets the GNSS at
// both ends. A jump with no growth of the stated sd before it (a multipath
// switch, an outage the solution does not own up to) stays a step. Sets
// the prior offsets and closure variances of `dejumped`.
void SpreadOutageClosures(const Trajectory& trajectory,
                          DejumpedTrajectory* dejumped);

// Pose of the de-jumped trajectory at `time` (interpolated as Trajectory);
// false outside the trajectory.
bool InterpolateDejumped(const Trajectory& trajectory,
                         const DejumpedTrajectory& dejumped, double time,
                         Pose* pose);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_
