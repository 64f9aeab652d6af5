#include "adjustment/trajectory_jumps.h"

#include <algorithm>
#include <cmath>

namespace zebrageo {
namespace {

bool OffsetChanges(const DejumpedTrajectory& d, int i) {
  return d.position_offset[i] != d.position_offset[i - 1] ||
         d.rotation_offset[i].angularDistance(d.rotation_offset[i - 1]) > 0.0;
}

// Share of a jump's closure at each sample of [start, jump.first) (zero
// before), from the stated variance `variance` accrued since the outage's
// start; empty where the stated sd did not grow into the jump (at least
// 1.2 times its value after it) and the jump stays a step. `floor` is the
// first sample the outage may start at (the previous jump's end).
std::vector<double> ClosureShares(const std::vector<double>& variance,
                                  const JumpEvent& jump, int floor,
                                  int* start) {
  constexpr double kGrowth = 1.2;  // sd before the jump / sd after
  const double before = variance[jump.first - 1];
  const double after = variance[jump.last];
  if (!(before > kGrowth * kGrowth * after) || jump.first - 1 <= floor) {
    return {};
  }
  // Back to where the stated sd started growing.
  int k = jump.first - 1;
  while (k > floor && variance[k - 1] < variance[k]) --k;
  const double accrued = before - variance[k];
  if (!(accrued > 0.0)) return {};
  *start = k;
  std::vector<double> share;
  for (int i = k; i < jump.first; ++i) {
    share.push_back(
        std::clamp((variance[i] - variance[k]) / accrued, 0.0, 1.0));
  }
  return share;
}

// A sideways switch's steps (DejumpedTrajectory::switch_step) free the
// correction across the track only.
void MoveSwitchInnovations(const std::vector<Eigen::Vector3d>& sideways,
                           DejumpedTrajectory* dejumped) {
  DejumpedTrajectory& d = *dejumped;
  d.cross_track_innovation_variance_m2.assign(d.innovation_variance_m2.size(),
                                              0.0);
  for (const SidewaysSwitch& s : d.switches) {
    double moved = 0.0;
    for (int k = s.first + 1; k <= s.last; ++k) {
      if (d.switch_step[k]) moved += sideways[k].norm();
    }
    for (int k = s.first + 1; k <= s.last; ++k) {
      if (!d.switch_step[k]) continue;
      // The switch's square spread over its steps as they moved: the
      // prior's centre moves with it, and the correction may follow
      // wherever control inside the switch shows it.
      d.cross_track_innovation_variance_m2[k] =
          s.size_m * s.size_m * sideways[k].norm() / moved;
    }
  }
}

}  // namespace

// A sideways switch's steps are not jumps: their variance is the
// cross-track axis's (MoveSwitchInnovations), and an outage's closure is
// the jump's alone.
std::vector<JumpEvent> JumpEvents(const DejumpedTrajectory& d) {
  std::vector<JumpEvent> events;
  const int n = static_cast<int>(d.position_offset.size());
  for (int i = 1; i < n; ++i) {
    if (!OffsetChanges(d, i)) continue;
    if (!d.switch_step.empty() && d.switch_step[i]) continue;
    if (!events.empty() && events.back().last == i - 1) {
      events.back().last = i;
    } else {
      events.push_back({i, i});
    }
  }
  return events;
}

void SpreadOutageClosures(const Trajectory& trajectory,
                          DejumpedTrajectory* dejumped) {
  DejumpedTrajectory& d = *dejumped;
  d.prior_position_offset = d.position_offset;
  d.prior_rotation_offset = d.rotation_offset;
  d.innovation_variance_m2.assign(d.position_offset.size(), 0.0);
  d.num_closed_outages = 0;
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  std::vector<double> position_variance;
  std::vector<double> attitude_variance;
  for (const TrajectorySample& s : samples) {
    position_variance.push_back(s.sd_enu_m.squaredNorm());
    attitude_variance.push_back(s.sd_attitude_rad.squaredNorm());
  }
  int floor = 0;
  for (const JumpEvent& jump : JumpEvents(d)) {
    bool closed = false;
    int start = 0;
    const std::vector<double> position_share =
        ClosureShares(position_variance, jump, floor, &start);
    const Eigen::Vector3d position_jump =
        d.position_offset[jump.last] - d.position_offset[jump.first - 1];
    for (size_t j = 0; j < position_share.size(); ++j) {
      d.prior_position_offset[start + j] += position_share[j] * position_jump;
      if (j > 0) {
        d.innovation_variance_m2[start + j] =
            0.25 * (position_share[j] - position_share[j - 1]) *
            position_jump.squaredNorm();
      }
    }
    if (position_share.empty()) {
      d.innovation_variance_m2[jump.first] = position_jump.squaredNorm();
    } else {
      closed = position_jump.norm() > 0.0;
    }
    const std::vector<double> attitude_share =
        ClosureShares(attitude_variance, jump, floor, &start);
    const Eigen::Quaterniond rotation_jump =
        d.rotation_offset[jump.last] *
        d.rotation_offset[jump.first - 1].inverse();
    for (size_t j = 0; j < attitude_share.size(); ++j) {
      const Eigen::Quaterniond part = Eigen::Quaterniond::Identity().slerp(
          attitude_share[j], rotation_jump);
      d.prior_rotation_offset[start + j] =
          (part * d.rotation_offset[start + j]).normalized();
    }
    if (!attitude_share.empty()) {
      closed = closed || rotation_jump.angularDistance(
                             Eigen::Quaterniond::Identity()) > 0.0;
    }
    d.num_closed_outages += closed;
    floor = jump.last;
  }
}

namespace {

// Each step's departure from its neighbours' motion: of the position
// (metres) and of the rotation (radians, body frame), per sample (zero at
// the first).
struct StepDepartures {
  std::vector<Eigen::Vector3d> position;
  std::vector<Eigen::Vector3d> rotation;
};
StepDepartures DepartureOfEachStep(const Trajectory& trajectory) {
  const std::vector<Pose>& poses = trajectory.poses();
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  const int n = static_cast<int>(poses.size());
  // Steps per second (velocity, angular rate in the body frame).
  std::vector<Eigen::Vector3d> velocity(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> rate(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    const double dt = samples[i].time - samples[i - 1].time;
    velocity[i] = (poses[i].p_enu - poses[i - 1].p_enu) / dt;
    const Eigen::AngleAxisd step(poses[i - 1].q_enu_body.inverse() *
                                 poses[i].q_enu_body);
    rate[i] = step.angle() * step.axis() / dt;
  }
  auto median_of_neighbours = [&](const std::vector<Eigen::Vector3d>& v,
                                  int i) {
    Eigen::Vector3d m;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> values;
      for (int k = std::max(1, i - 3); k <= std::min(n - 1, i + 3); ++k) {
        if (k != i) values.push_back(v[k][axis]);
      }
      std::nth_element(values.begin(), values.begin() + values.size() / 2,
                       values.end());
      m[axis] = values[values.size() / 2];
    }
    return m;
  };
  // A step across a gap of the trajectory (survey/trajectory.h) is not one:
  // the vehicle's motion during the gap is unknown, so it is never taken
  // for a jump.
  std::vector<bool> across_gap(n, false);
  for (const TrajectoryGap& gap : FindTrajectoryGaps(SampleTimes(samples))) {
    across_gap[gap.before + 1] = true;
  }
  StepDepartures departures;
  departures.position.assign(n, Eigen::Vector3d::Zero());
  departures.rotation.assign(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    if (across_gap[i]) continue;
    const double dt = samples[i].time - samples[i - 1].time;
    departures.position[i] =
        (velocity[i] - median_of_neighbours(velocity, i)) * dt;
    departures.rotation[i] = (rate[i] - median_of_neighbours(rate, i)) * dt;
  }
  return departures;
}

// A jump stands out of the trajectory's own motion: at 10 Hz the body's
// oscillations on its suspension (a tenth of a degree at 1-2 Hz) depart
// from the neighbouring steps by more than a 100 Hz trajectory's do, and
// are not jumps. A threshold (0: disabled) is raised to kJumpNoiseFactor
// times the median departure of `steps` when that is larger.
double NoiseRaisedThreshold(double threshold,
                            const std::vector<Eigen::Vector3d>& steps) {
  constexpr double kJumpNoiseFactor = 8.0;
  if (!(threshold > 0.0)) return 0.0;
  std::vector<double> norms;
  for (size_t i = 1; i < steps.size(); ++i) norms.push_back(steps[i].norm());
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2,
                   norms.end());
  return std::max(threshold, kJumpNoiseFactor * norms[norms.size() / 2]);
}

}  // namespace

DejumpedTrajectory RemoveJumps(const Trajectory& trajectory, double threshold_m,
                               double threshold_rad,
                               const SidewaysSwitchOptions& switches) {
  const std::vector<Pose>& poses = trajectory.poses();
  const int n = static_cast<int>(poses.size());
  DejumpedTrajectory out;
  out.poses = poses;
  out.position_offset.assign(n, Eigen::Vector3d::Zero());
  out.rotation_offset.assign(n, Eigen::Quaterniond::Identity());
  std::vector<Eigen::Vector3d> sideways;
  if (n < 8 || (threshold_m <= 0.0 && threshold_rad <= 0.0)) {
    out.switches = FindSidewaysSwitches(trajectory, switches, {}, &sideways);
    Eigen::Vector3d position_jump = Eigen::Vector3d::Zero();
    out.switch_step.assign(n, false);
    for (int i = 1; i < n; ++i) {
      out.switch_step[i] = !sideways[i].isZero();
      position_jump += sideways[i];
      out.position_offset[i] = position_jump;
      out.poses[i].p_enu = poses[i].p_enu - position_jump;
    }
    SpreadOutageClosures(trajectory, &out);
    MoveSwitchInnovations(sideways, &out);
    return out;
  }
  const StepDepartures departures = DepartureOfEachStep(trajectory);
  const std::vector<Eigen::Vector3d>& position_step = departures.position;
  const std::vector<Eigen::Vector3d>& rotation_step = departures.rotation;
  threshold_m = NoiseRaisedThreshold(threshold_m, position_step);
  threshold_rad = NoiseRaisedThreshold(threshold_rad, rotation_step);
  std::vector<bool> position_jumps(n, false);
  for (int i = 1; i < n; ++i) {
    position_jumps[i] =
        threshold_m > 0.0 && position_step[i].norm() > threshold_m;
  }
  out.switches =
      FindSidewaysSwitches(trajectory, switches, position_jumps, &sideways);
  Eigen::Vector3d position_jump = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation_jump = Eigen::Quaterniond::Identity();
  out.switch_step.assign(n, false);
  for (int i = 1; i < n; ++i) {
    bool jumped = false;
    if (threshold_m > 0.0) {
      const Eigen::Vector3d& step = position_step[i];
      if (step.norm() > threshold_m) {
        position_jump += step;
        jumped = true;
      }
    }
    if (threshold_rad > 0.0) {
      const Eigen::Vector3d& step = rotation_step[i];
      if (step.norm() > threshold_rad) {
        // In the ENU frame: R_i = J R_i', J = R_{i-1} Exp(step) R_{i-1}^T.
        const Eigen::Quaterniond body_step(
            Eigen::AngleAxisd(step.norm(), step.normalized()));
        const Eigen::Quaterniond J = poses[i - 1].q_enu_body * body_step *
                                     poses[i - 1].q_enu_body.inverse();
        rotation_jump = (J * rotation_jump).normalized();
        jumped = true;
      }
    }
    out.num_jumps += jumped;
    // A switch's sideways step, unless the step was a jump already.
    if (!jumped && !sideways[i].isZero()) {
      out.switch_step[i] = true;
      position_jump += sideways[i];
    }
    out.position_offset[i] = position_jump;
    out.rotation_offset[i] = rotation_jump;
    out.poses[i].p_enu = poses[i].p_enu - position_jump;
    out.poses[i].q_enu_body =
        (rotation_jump.inverse() * poses[i].q_enu_body).normalized();
  }
  SpreadOutageClosures(trajectory, &out);
  MoveSwitchInnovations(sideways, &out);
  return out;
}

bool InterpolateDejumped(const Trajectory& trajectory,
                         const DejumpedTrajectory& dejumped, double time,
                         Pose* pose) {
  const int i = trajectory.FindSegment(time);
  if (i < 0) return false;
  const double t0 = trajectory.samples()[i].time;
  const double t1 = trajectory.samples()[i + 1].time;
  *pose = InterpolatePoses(dejumped.poses[i], dejumped.poses[i + 1],
                           (time - t0) / (t1 - t0));
  return true;
}

}  // namespace zebrageo
