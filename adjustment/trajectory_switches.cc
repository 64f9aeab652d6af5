#include "adjustment/trajectory_switches.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// The mean of `track` over the samples within +-half_window_s of each.
std::vector<double> SmoothedTrack(const std::vector<double>& track,
                                  const std::vector<double>& times,
                                  double half_window_s) {
  const int n = static_cast<int>(track.size());
  std::vector<double> smoothed(n, 0.0);
  int lo = 0;
  int hi = 0;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    while (hi < n && times[hi] <= times[i] + half_window_s) sum += track[hi++];
    while (times[lo] < times[i] - half_window_s) sum -= track[lo++];
    smoothed[i] = sum / (hi - lo);
  }
  return smoothed;
}

// The sum of the sideways steps up to each sample, the taken ones left out.
std::vector<double> SidewaysTrack(const std::vector<double>& side,
                                  const std::vector<bool>& taken_steps) {
  std::vector<double> track(side.size(), 0.0);
  for (size_t i = 1; i < side.size(); ++i) {
    track[i] = track[i - 1] + (taken_steps[i] ? 0.0 : side[i]);
  }
  return track;
}

// The slope (m/s) of `track` over the trend_s before (after) each sample,
// NaN where the trajectory is shorter or a blocked sample (a gap, an
// outage) lies in that window.
struct Trends {
  std::vector<double> before;
  std::vector<double> after;
};

Trends TrackTrends(const std::vector<double>& track,
                   const std::vector<double>& times,
                   const std::vector<bool>& blocked, double trend_s) {
  const int n = static_cast<int>(track.size());
  std::vector<int> blocked_before(n + 1, 0);  // blocked samples before i
  for (int i = 0; i < n; ++i) {
    blocked_before[i + 1] = blocked_before[i] + (blocked[i] ? 1 : 0);
  }
  auto clear = [&](int a, int b) {  // no blocked sample in [a, b]
    return blocked_before[b + 1] == blocked_before[a];
  };
  // Sample times carry rounding: 2 s of a 20 Hz trajectory may be 1.99999.
  const double span = trend_s * (1.0 - 1e-9);
  Trends trends;
  trends.before.assign(n, std::numeric_limits<double>::quiet_NaN());
  trends.after = trends.before;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k + 1 < i && times[i] - times[k + 1] >= span) ++k;
    if (times[i] - times[k] >= span && clear(k, i)) {
      trends.before[i] = (track[i] - track[k]) / (times[i] - times[k]);
    }
  }
  k = n - 1;
  for (int i = n - 1; i >= 0; --i) {
    while (k - 1 > i && times[k - 1] - times[i] >= span) --k;
    if (times[k] - times[i] >= span && clear(i, k)) {
      trends.after[i] = (track[k] - track[i]) / (times[k] - times[i]);
    }
  }
  return trends;
}

// The pair of samples (i < j) at most max_duration_s apart, with no gap
// and no step of a switch found already between them, over which `track`
// changes most beyond the sideways trend around them: a steady crab or a slow
// drift moves the positions sideways steadily, a switch steps between two
// stretches. The trend is the smaller of the slopes before i and after j (the
// other may be a neighbouring switch's), both required: near the ends of the
// trajectory or of a blocked stretch nothing is found. Pairs sampled every
// `stride` samples. Returns the change (0 when none).
double LargestChange(const std::vector<double>& track,
                     const std::vector<double>& times, const Trends& trends,
                     const std::vector<bool>& blocked,
                     const std::vector<bool>& taken_steps, int stride,
                     double max_duration_s, int* best_i, int* best_j) {
  const int n = static_cast<int>(track.size());
  double best = 0.0;
  for (int i = 0; i < n; i += stride) {
    if (blocked[i]) continue;
    for (int j = i + 1; j < n && times[j] - times[i] <= max_duration_s; ++j) {
      if (blocked[j] || taken_steps[j]) break;
      if ((j - i) % stride != 0 && j + 1 < n) continue;
      // Both trends known, the smaller: the other may be a neighbouring
      // switch's.
      const double before = trends.before[i];
      const double after = trends.after[j];
      if (!std::isfinite(before) || !std::isfinite(after)) continue;
      const double slope = std::abs(before) < std::abs(after) ? before : after;
      const double change =
          std::abs(track[j] - track[i] - slope * (times[j] - times[i]));
      if (change > best) {
        best = change;
        *best_i = i;
        *best_j = j;
      }
    }
  }
  return best;
}

// Blocks the samples where the stated horizontal sd grew to more than 1.2
// times its least value over the 10 s before: an outage (no GNSS, so no
// multipath switch), whose dead-reckoning drift the INS owns up to and
// the jump at its end closes (SpreadOutageClosures).
void BlockGrowingStatedSd(const std::vector<TrajectorySample>& samples,
                          const std::vector<double>& times,
                          std::vector<bool>* blocked) {
  constexpr double kGrowth = 1.2;
  constexpr double kWindowS = 10.0;
  const int n = static_cast<int>(samples.size());
  std::deque<int> window;  // indices of increasing sd (a sliding minimum)
  auto sd = [&](int i) { return samples[i].sd_enu_m.head<2>().norm(); };
  for (int i = 0; i < n; ++i) {
    while (!window.empty() && sd(window.back()) >= sd(i)) window.pop_back();
    window.push_back(i);
    while (times[window.front()] < times[i] - kWindowS) window.pop_front();
    if (sd(i) > kGrowth * sd(window.front())) (*blocked)[i] = true;
  }
}

// `flags` with every sample within half_window_s of a flagged one flagged.
std::vector<bool> Dilated(const std::vector<bool>& flags,
                          const std::vector<double>& times,
                          double half_window_s) {
  const int n = static_cast<int>(flags.size());
  std::vector<bool> out = flags;
  double last = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    if (flags[i]) last = times[i];
    if (times[i] - last <= half_window_s) out[i] = true;
  }
  last = std::numeric_limits<double>::infinity();
  for (int i = n - 1; i >= 0; --i) {
    if (flags[i]) last = times[i];
    if (last - times[i] <= half_window_s) out[i] = true;
  }
  return out;
}

}  // namespace

std::string SidewaysSwitchOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, min_switch_m, 0.0);  // 0 disables
  OPTION_GT(check, max_duration_s, 0.0);
  OPTION_GT(check, trend_s, 0.0);
  OPTION_GE(check, smoothing_s, 0.0);
  OPTION_LT(check, smoothing_s, max_duration_s);
  return check.problem();
}

std::vector<SidewaysSwitch> FindSidewaysSwitches(
    const Trajectory& trajectory, const SidewaysSwitchOptions& options,
    const std::vector<bool>& jump_steps,
    std::vector<Eigen::Vector3d>* sideways_steps_enu) {
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  const std::vector<Pose>& poses = trajectory.poses();
  const int n = static_cast<int>(poses.size());
  sideways_steps_enu->assign(n, Eigen::Vector3d::Zero());
  if (!(options.min_switch_m > 0.0) || n < 8) return {};
  const std::vector<double> times = SampleTimes(samples);
  // A step across a gap is blocked: the motion during the gap is unknown.
  std::vector<bool> blocked(n, false);
  for (const TrajectoryGap& gap : FindTrajectoryGaps(times)) {
    blocked[gap.before + 1] = true;
  }
  BlockGrowingStatedSd(samples, times, &blocked);
  // The smoothing would spread what happens there to its neighbours.
  blocked = Dilated(blocked, times, options.smoothing_s);
  // Each step's motion across the heading at its start (body FRD: y to
  // the right), horizontal.
  std::vector<Eigen::Vector3d> right(n, Eigen::Vector3d::Zero());
  std::vector<double> side(n, 0.0);
  std::vector<double> length(n, 0.0);
  std::vector<double> crab;
  for (int i = 1; i < n; ++i) {
    if (blocked[i] || (!jump_steps.empty() && jump_steps[i])) continue;
    Eigen::Vector3d step = poses[i].p_enu - poses[i - 1].p_enu;
    step.z() = 0.0;
    Eigen::Vector3d r = poses[i - 1].q_enu_body * Eigen::Vector3d::UnitY();
    r.z() = 0.0;
    if (!(r.norm() > 1e-6)) continue;
    right[i] = r.normalized();
    side[i] = step.dot(right[i]);
    length[i] = step.norm();
    if (length[i] > 1e-3) crab.push_back(side[i] / length[i]);
  }
  if (crab.size() < 8) return {};
  // The INS's yaw misalignment to the direction of travel moves the
  // positions sideways in proportion to the distance: not a switch.
  const double crab_rate = Median(crab);
  for (int i = 1; i < n; ++i) side[i] -= crab_rate * length[i];
  // Pairs sampled at about 20 Hz: a switch takes a second or more.
  const int stride = std::max(
      1, static_cast<int>(std::lround(0.05 / MedianSampleInterval(times))));
  // The steps of the switches found so far are taken out of the track
  // before the next is looked for, so that the trend over a window across
  // one is the road's, not the switch's: switches a couple of seconds
  // apart (multipath that comes and goes) are found one after the other.
  std::vector<bool> taken_steps(n, false);
  std::vector<SidewaysSwitch> switches;
  for (int found = 0; found < n; ++found) {
    const std::vector<double> smoothed = SmoothedTrack(
        SidewaysTrack(side, taken_steps), times, options.smoothing_s);
    const Trends trends =
        TrackTrends(smoothed, times, blocked, options.trend_s);
    int i = -1;
    int j = -1;
    const double change =
        LargestChange(smoothed, times, trends, blocked, taken_steps, stride,
                      options.max_duration_s, &i, &j);
    if (!(change >= options.min_switch_m)) break;
    SidewaysSwitch s;
    s.first = i;
    s.last = j;
    for (int k = i + 1; k <= j; ++k) {
      (*sideways_steps_enu)[k] = side[k] * right[k];
      s.size_m += side[k];
      taken_steps[k] = true;
    }
    switches.push_back(s);
  }
  std::sort(switches.begin(), switches.end(),
            [](const SidewaysSwitch& a, const SidewaysSwitch& b) {
              return a.first < b.first;
            });
  return switches;
}

}  // namespace zebrageo
