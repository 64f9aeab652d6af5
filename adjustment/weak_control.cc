// Stretches where one axis of the position is weakly held (weak_control.h).
#include "adjustment/weak_control.h"

#include <algorithm>
#include <cmath>

#include "survey/math_util.h"

namespace zebrageo {

const char* TrackAxisName(TrackAxis axis) {
  switch (axis) {
    case TrackAxis::kAlongTrack:
      return "along_track";
    case TrackAxis::kCrossTrack:
      return "cross_track";
    case TrackAxis::kUp:
      return "up";
  }
  return "unknown";
}

namespace adjustment_internal {

std::vector<WeakStretch> WeakStretches(
    const std::vector<double>& times_s,
    const std::vector<Eigen::Vector3d>& p_enu,
    const std::vector<Eigen::Vector3d>& sd_track_m,
    const std::vector<std::array<bool, 3>>& held,
    const Eigen::Vector3d& threshold_m, double min_length_m) {
  std::vector<WeakStretch> stretches;
  const int n = static_cast<int>(times_s.size());
  const bool with_sd = static_cast<int>(sd_track_m.size()) == n;
  const bool with_held = static_cast<int>(held.size()) == n;
  if (n == 0 || static_cast<int>(p_enu.size()) != n ||
      (!with_sd && !with_held)) {
    return stretches;
  }
  // Distance along the trajectory at each sample.
  std::vector<double> distance(n, 0.0);
  for (int i = 1; i < n; ++i) {
    distance[i] = distance[i - 1] + (p_enu[i] - p_enu[i - 1]).norm();
  }
  for (int axis = 0; axis < 3; ++axis) {
    const auto weak = [&](int i) {
      return (with_sd && sd_track_m[i][axis] > threshold_m[axis]) ||
             (with_held && !held[i][axis]);
    };
    int start = -1;
    for (int i = 0; i <= n; ++i) {
      const bool here = i < n && weak(i);
      if (here && start < 0) start = i;
      if (here || start < 0) continue;
      const int end = i - 1;
      if (distance[end] - distance[start] >= min_length_m) {
        WeakStretch s;
        s.axis = static_cast<TrackAxis>(axis);
        s.begin_time_s = times_s[start];
        s.end_time_s = times_s[end];
        s.length_m = distance[end] - distance[start];
        s.threshold_m = threshold_m[axis];
        std::vector<double> sd;
        s.held_by_no_control = with_held;
        for (int k = start; k <= end; ++k) {
          if (with_sd) sd.push_back(sd_track_m[k][axis]);
          if (with_held && held[k][axis]) s.held_by_no_control = false;
        }
        s.max_sd_m = sd.empty() ? NAN : *std::max_element(sd.begin(), sd.end());
        s.median_sd_m = sd.empty() ? NAN : Median(sd);
        stretches.push_back(s);
      }
      start = -1;
    }
  }
  return stretches;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
