// Where the adjustment holds one axis of the trajectory's position weakly
// (issue 51): stretches whose posterior sd along-track, cross-track or up
// exceeds a threshold. A stretch without zebra control is only the worst
// case: road lines hold cross-track and height but never along-track, and
// crossings along the track hold it only by their band ends, so a stretch
// can be controlled in two axes and free in the third.
#ifndef ZEBRAGEO_ADJUSTMENT_WEAK_CONTROL_H_
#define ZEBRAGEO_ADJUSTMENT_WEAK_CONTROL_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace zebrageo {

// The axes of the track frame, in the order of the knots' position.
enum class TrackAxis { kAlongTrack = 0, kCrossTrack = 1, kUp = 2 };

// "along_track", "cross_track", "up".
const char* TrackAxisName(TrackAxis axis);

// One stretch of trajectory where `axis` is weakly held.
struct WeakStretch {
  TrackAxis axis = TrackAxis::kAlongTrack;
  double begin_time_s = 0.0;
  double end_time_s = 0.0;
  double length_m = 0.0;
  double threshold_m = 0.0;  // the sd above which the axis counts as weak
  double max_sd_m = 0.0;     // posterior sd of the axis over the stretch
  double median_sd_m = 0.0;  // (NaN without the posterior covariance)
  // No control holding the axis lies within reach of any of its samples
  // (else only the sd says it is weak).
  bool held_by_no_control = false;
};

namespace adjustment_internal {

// The stretches of the samples (`times_s`, positions `p_enu`) where an
// axis is weak over at least `min_length_m` of trajectory, by axis then
// time: its posterior sd (`sd_track_m`: along, cross, up; may be empty)
// above threshold_m[axis], or no control holding it (`held`, per sample
// and axis; may be empty).
std::vector<WeakStretch> WeakStretches(
    const std::vector<double>& times_s,
    const std::vector<Eigen::Vector3d>& p_enu,
    const std::vector<Eigen::Vector3d>& sd_track_m,
    const std::vector<std::array<bool, 3>>& held,
    const Eigen::Vector3d& threshold_m, double min_length_m);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_WEAK_CONTROL_H_
