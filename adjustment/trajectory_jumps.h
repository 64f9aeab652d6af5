// Jumps of the GNSS/INS solution (GNSS coming back after an outage): the
// adjustment works on the trajectory with its jumps taken out, so that what
// remains is the INS relative motion, continuous, and the prior on the
// correction follows the jumps instead (trajectory_adjuster.h).
//
// Frames: ENU (the survey's working frame), body FRD; metres, radians.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

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
  int num_jumps = 0;
};

// A step that departs from its neighbours' motion by more than threshold_m
// (position) or threshold_rad (attitude), or by more than 8 times the
// trajectory's median departure where that is larger, is a jump. A
// threshold of 0 disables that part.
DejumpedTrajectory RemoveJumps(const Trajectory& trajectory, double threshold_m,
                               double threshold_rad);

// Pose of the de-jumped trajectory at `time` (interpolated as Trajectory);
// false outside the trajectory.
bool InterpolateDejumped(const Trajectory& trajectory,
                         const DejumpedTrajectory& dejumped, double time,
                         Pose* pose);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JUMPS_H_
