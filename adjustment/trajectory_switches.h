// Sideways switches of the GNSS/INS solution (multipath): a land vehicle
// moves along its heading, so where the trajectory's positions move a
// decimetre-scale or larger distance across the heading within a few
// seconds, the GNSS error switched there, not the vehicle. The
// sample-to-sample jump detection (trajectory_jumps.h) misses such a switch
// when it is spread over a second or more; the adjustment takes it out of
// the trajectory as it does a jump, so that a correction measured on one
// side of it is not carried, with the error the switch added, to the other.
//
// Frames: ENU (the survey's working frame), body FRD; metres.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_SWITCHES_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_SWITCHES_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "survey/trajectory.h"

namespace zebrageo {

struct SidewaysSwitchOptions {
  // A switch moves the positions at least min_switch_m across the heading
  // within max_duration_s. Measured on the trajectories at hand (3 s
  // windows): a real fused GNSS/INS pose on a highway (comma2k19) 0.13 m,
  // the field cases 0.10-0.34 m, positions jittering at the sample rate
  // (simulated, 6-7.5 deg RMS) up to 0.42 m; multipath switches of 1.2-1.4
  // m, 1.0-1.4 m. 0 disables the detection.
  double min_switch_m = 0.6;
  double max_duration_s = 4.0;
  // The positions are averaged over +-smoothing_s before the sideways
  // track is measured, so that noise at the sample rate does not add up.
  double smoothing_s = 0.5;
  // The change is counted beyond the sideways trend over trend_s before and
  // after it (the smaller; both must be known): a crab that differs from
  // the trajectory's median one (a simulated jitter kept 0.9 m sideways
  // over 5 s of straight road) is steady, a switch is a step.
  double trend_s = 2.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("min_switch_m", min_switch_m);
    v("max_duration_s", max_duration_s);
    v("smoothing_s", smoothing_s);
    v("trend_s", trend_s);
  }
};

// A switch: the positions moved sideways over the steps into samples
// first + 1 .. last.
struct SidewaysSwitch {
  int first = 0;
  int last = 0;
  double size_m = 0.0;  // signed, to the right of the heading
};

// The switches of `trajectory`, in time order, and, per sample (ENU, zero
// outside a switch), the sideways part of the step into it beyond the
// trajectory's constant crab angle (the INS's yaw misalignment to its
// direction of travel), which the switches' steps take out. Steps across
// a gap of the trajectory, or within smoothing_s of one or of a sample
// whose stated sd grew (an outage), are never part of one; the steps
// flagged in `jump_steps` (jumps, handled as such; may be empty) move
// nothing sideways.
std::vector<SidewaysSwitch> FindSidewaysSwitches(
    const Trajectory& trajectory, const SidewaysSwitchOptions& options,
    const std::vector<bool>& jump_steps,
    std::vector<Eigen::Vector3d>* sideways_steps_enu);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_SWITCHES_H_
