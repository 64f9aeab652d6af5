// The fast part of the GNSS/INS position error. An unsmoothed GNSS (or
// GPS + dead-reckoning) solution jitters from sample to sample by
// centimetres, decorrelating within a second: no smooth correction follows
// that, yet every exposure's pose carries it. The adjustment gives each
// exposure its own position offset, a first-order Gauss-Markov process
// whose sigma and correlation time are read off the trajectory itself
// (adjustment_state.h): its positions' departure from a smooth vehicle path
// (a local quadratic over +-window_s; a vehicle's path is smooth at that
// scale, so a clean trajectory departs from it by a fraction of a
// millimetre).
//
// Frames: track frame of the INS pose (along-track, left, up), metres,
// seconds.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JITTER_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JITTER_H_

#include <Eigen/Core>
#include <vector>

#include "survey/trajectory.h"

namespace zebrageo {

struct PositionJitter {
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d tau_s = Eigen::Vector3d::Constant(0.5);
};

// From the poses (the trajectory's samples, jumps removed) and their
// times: the departures' increments over one sample and over lag_s
// (robust variances), fitted by a Gauss-Markov process, per axis. The
// increments, not the departures themselves: the smooth fit takes up the
// jitter's slow part, its short increments are the jitter's alone.
PositionJitter EstimatePositionJitter(const std::vector<double>& times,
                                      const std::vector<Pose>& poses,
                                      double window_s, double lag_s);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_JITTER_H_
