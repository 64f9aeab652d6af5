#include "adjustment/input_guard.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// A vertex placed from its stereo observations with the poses `pose_at`
// gives (covariance-weighted as StereoPosition); false when a pose is
// missing.
template <typename PoseAt>
bool PlaceVertex(const AdjustmentOptions& options,
                 const std::vector<StereoObservation>& observations,
                 const PoseAt& pose_at, Eigen::Vector3d* X) {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (const StereoObservation& o : observations) {
    Pose pose;
    if (!pose_at(o, &pose)) return false;
    const Eigen::Matrix3d R = pose.q_enu_body.toRotationMatrix();
    const Eigen::Matrix3d W =
        (R * ObservationCovariance(options, o) * R.transpose()).inverse();
    information += W;
    weighted += W * (R * o.p_body + pose.p_enu);
  }
  if (observations.empty()) return false;
  *X = information.inverse() * weighted;
  return X->allFinite();
}

}  // namespace

std::vector<GuardCrossing> GuardCrossingsOf(const Context& context,
                                            const State& state) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  std::map<int, GuardCrossing> by_crossing;
  std::map<int, Eigen::Vector3d> sigma2_sum;
  const auto input_pose = [&trajectory](const StereoObservation& o,
                                        Pose* pose) {
    return trajectory.InterpolatePose(o.time, pose);
  };
  const auto adjusted_pose = [&state](const StereoObservation& o, Pose* pose) {
    *pose = CorrectedPose(state, o.time, o.ins_pose, o.exposure);
    return true;
  };
  for (const ControlPoint& p : state.points) {
    if (p.stereo.empty()) continue;
    Eigen::Vector3d X_in, X_adj;
    if (!PlaceVertex(options, p.stereo, input_pose, &X_in) ||
        !PlaceVertex(options, p.stereo, adjusted_pose, &X_adj)) {
      continue;
    }
    const bool first = by_crossing.count(p.crossing) == 0;
    GuardCrossing& c = by_crossing[p.crossing];
    if (first) {
      c.id = p.crossing_id;
      c.first_time_s = p.stereo.front().time;
      c.last_time_s = p.stereo.front().time;
      c.used = false;
      sigma2_sum[p.crossing] = Eigen::Vector3d::Zero();
    }
    for (const StereoObservation& o : p.stereo) {
      c.first_time_s = std::min(c.first_time_s, o.time);
      c.last_time_s = std::max(c.last_time_s, o.time);
    }
    c.used = c.used || p.status != ControlStatus::kRejected;
    c.database_enu.push_back(p.database_enu);
    c.input_enu.push_back(X_in);
    c.adjusted_enu.push_back(X_adj);
    sigma2_sum[p.crossing] += p.sigma_m.cwiseAbs2();
  }
  const double offset2 = options.never_worse.guard_crossing_sigma_m *
                         options.never_worse.guard_crossing_sigma_m;
  std::vector<GuardCrossing> crossings;
  for (auto& [index, c] : by_crossing) {
    const double n = static_cast<double>(c.database_enu.size());
    // The median of n vertices: pi/2 times the variance of their mean.
    c.sigma_m = (Eigen::Vector3d::Constant(offset2) +
                 (kPi / 2.0) * sigma2_sum[index] / (n * n))
                    .cwiseSqrt();
    crossings.push_back(std::move(c));
  }
  return crossings;
}

GuardResult GuardAdjustment(const Context& context, const State& state) {
  GuardResult guard = GuardAgainstInput(GuardCrossingsOf(context, state),
                                        context.options.never_worse);
  for (const GuardVerdict& v : guard.verdicts) {
    VLOG(1) << "guard: crossing " << v.id << (v.used ? "" : " (rejected)")
            << ": input " << v.input_misfit_m << " m, adjusted "
            << v.adjusted_misfit_m << " m from the database, z " << v.z
            << (v.worse ? " WORSE" : "");
  }
  const double origin = context.input.trajectory->start_time();
  for (const KeptStretch& stretch : guard.kept) {
    context.Warn(KeptStretchText(stretch, origin));
  }
  return guard;
}

Pose GuardedPose(const GuardResult& guard, double time, const Pose& adjusted,
                 const Pose& input) {
  const double w = guard.AdjustedWeight(time);
  if (w >= 1.0) return adjusted;
  if (w <= 0.0) return input;
  Pose pose;
  pose.p_enu = (1.0 - w) * input.p_enu + w * adjusted.p_enu;
  pose.q_enu_body = input.q_enu_body.slerp(w, adjusted.q_enu_body).normalized();
  return pose;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
