// The adjustment's starting point (adjustment_setup.h).
#include "adjustment/adjustment_setup.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "adjustment/line_discrepancies.h"
#include "adjustment/trajectory_jitter.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

std::string FormatCm(double metres) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << 100.0 * metres << " cm";
  return out.str();
}

// The vehicle-motion constraints, and their sigma (lateral, vertical). The
// chord over which the direction of travel is taken is the one that gives
// the most information per second: a trajectory whose positions jitter
// from sample to sample needs a longer chord, whose direction is less
// noisy, and fewer constraints along it (they would not be independent).
// The sigma is the stated sideslip, or the crab angles' high-frequency
// spread where that is larger (vehicle_motion.h), widened by the square
// root of the number of constraints per vehicle_motion_correlation_s.
Eigen::Vector2d ChooseVehicleMotion(const Context& context, State* state) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  std::vector<double> sample_times;
  sample_times.reserve(trajectory.size());
  for (const TrajectorySample& sample : trajectory.samples()) {
    sample_times.push_back(sample.time);
  }
  const Eigen::Vector2d stated(options.vehicle_motion.sideslip_sigma_rad,
                               options.vehicle_motion.vertical_slip_sigma_rad);
  double best_information = 0.0;
  Eigen::Vector2d best_sigma = stated;
  std::vector<VehicleMotionSample> best;
  for (double factor : {1.0, 2.0, 5.0, 10.0, 20.0}) {
    const double half_chord =
        factor * options.vehicle_motion.vehicle_motion_half_chord_s;
    const double rate = std::min(options.vehicle_motion.vehicle_motion_rate_hz,
                                 1.0 / (2.0 * half_chord));
    std::vector<VehicleMotionSample> samples = MakeVehicleMotionSamples(
        state->correction, sample_times, rate, half_chord,
        options.vehicle_motion.vehicle_motion_min_speed_mps, stated,
        [&context](double time, Pose* pose) {
          return context.InsPoseAt(time, pose);
        });
    if (samples.size() < 8) continue;
    const Eigen::Vector2d spread = HighFrequencyCrabSpread(
        samples, state->correction, std::max(1.0, 10.0 * half_chord));
    // Constraints closer than the sideslip's correlation time are not
    // independent: each counts for its share of that time.
    const double shared = std::sqrt(std::max(
        1.0, rate * options.vehicle_motion.vehicle_motion_correlation_s));
    const Eigen::Vector2d sigma = shared * spread.cwiseMax(stated);
    const double information = rate / (sigma.x() * sigma.x());
    VLOG(1) << "vehicle motion: half chord " << half_chord << " s, "
            << samples.size() << " constraints, crab spread "
            << RadToDeg(1.0) * spread.transpose() << " deg";
    // A longer chord must bring more, not as much: ties go to the shorter.
    if (information > 1.01 * best_information) {
      best_information = information;
      best_sigma = sigma;
      best = std::move(samples);
    }
  }
  state->motion = std::move(best);
  return best_sigma;
}

// 95% quantile of the chi-square distribution with k degrees of freedom
// (Wilson-Hilferty; within 1% for k >= 1).
double ChiSquare95(int k) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + 1.6448536 * std::sqrt(a);
  return k * c * c * c;
}

// The position process' sigma on one axis. Where the crossings'
// discrepancies are explained by the database's own error (chi-square test
// at 95%; the two horizontal axes together: a GNSS/INS error is rarely
// along-track alone), the INS is left alone: min_position_sigma_m. Where
// they show a drift, the process must not shrink the correction towards
// the INS: the posterior at a crossing is the control times
// sigma^2 / (sigma^2 + D), D the crossing's own variance (its offset,
// ~7 cm), and a maximum-likelihood sigma of a few crossings comparable to
// D would stop half way. The sigma of the error's level is then three
// times the discrepancies' RMS (shrinkage under 10%), at least the
// likelihood's.
double PositionSigma(const AdjustmentOptions& options,
                     const std::vector<CrossingDiscrepancy>& d,
                     const std::vector<bool>& use, int axis,
                     double likelihood_sigma) {
  const std::vector<int> tested =
      axis == 2 ? std::vector<int>{2} : std::vector<int>{0, 1};
  double chi_square = 0.0;
  double sum_square = 0.0;
  int n = 0;
  int dof = 0;
  for (size_t c = 0; c < d.size(); ++c) {
    if (!use[c]) continue;
    for (int a : tested) {
      chi_square += d[c].value_m[a] * d[c].value_m[a] /
                    std::max(d[c].variance_m2[a], 1e-12);
      ++dof;
    }
    sum_square += d[c].value_m[axis] * d[c].value_m[axis];
    ++n;
  }
  if (n == 0 || chi_square <= ChiSquare95(dof)) {
    return options.model.min_position_sigma_m;
  }
  constexpr double kNoShrinkFactor = 3.0;
  return std::clamp(
      std::max(likelihood_sigma, kNoShrinkFactor * std::sqrt(sum_square / n)),
      options.model.min_position_sigma_m, options.model.max_position_sigma_m);
}

// With zebra control and road lines: the lines measure the error across
// the track and in height between the crossings, where one or two
// crossings (their discrepancies near zero) fit the process to its floor
// and make a metre-size multipath switch the lines show impossible, and
// the right crossing a blunder. On an axis (across, up) the crossings fit
// to the floor, the process is as large as the lines show; its correlation
// time stays the crossings' (a switch fitted as a long-correlated process
// would be too stiff).
void WidenByLines(const AdjustmentOptions& options, const State& state,
                  ErrorModel* model) {
  const std::vector<CrossingDiscrepancy> seen =
      LineDiscrepancies(state, options.road_lines.line_discrepancy_bin_s,
                        options.road_lines.line_discrepancy_min_points);
  if (seen.empty()) return;
  const std::vector<bool> all(seen.size(), true);
  const std::vector<GaussMarkovFit> fits =
      adjustment_internal::FitAxes(seen, all, PositionFitOptions(options));
  for (int axis = 1; axis < 3; ++axis) {
    // Where the crossings show a drift, their fit stands (the lines'
    // discrepancies hold the database lines' own errors too).
    if (model->position_sigma_m[axis] > options.model.min_position_sigma_m)
      continue;
    const double level =
        PositionSigma(options, seen, all, axis, fits[axis].sigma);
    // The exposures' jitter, modelled on its own, is in the lines' too.
    const double jitter = model->jitter_sigma_m[axis];
    const double sigma =
        level > options.model.min_position_sigma_m
            ? std::max(
                  options.model.min_position_sigma_m,
                  std::sqrt(std::max(0.0, fits[axis].sigma * fits[axis].sigma -
                                              jitter * jitter)))
            : options.model.min_position_sigma_m;
    VLOG(1) << "error model axis " << axis << ": crossings "
            << model->position_sigma_m[axis] << " m, road lines " << sigma
            << " m (level " << level << " m)";
    model->position_level_sigma_m[axis] =
        std::max(model->position_level_sigma_m[axis], level);
    model->position_sigma_m[axis] =
        std::max(model->position_sigma_m[axis], sigma);
  }
}

}  // namespace

void SetKnotPriors(const Context& context, const DejumpedTrajectory& dejumped,
                   State* state) {
  state->knot_prior.clear();
  state->knot_extra_variance_m2.clear();
  if (dejumped.num_jumps == 0 && dejumped.switches.empty()) return;
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  int previous_sample = 0;
  for (int k = 0; k < state->correction.num_knots(); ++k) {
    const double t = std::clamp(state->correction.KnotTime(k),
                                trajectory.start_time(), trajectory.end_time());
    const int i = std::max(0, trajectory.FindSegment(t));
    Pose pose;
    context.InsPoseAt(t, &pose);
    const Eigen::Matrix3d R_track_enu =
        state->correction.Frame(pose).transpose();
    const Eigen::AngleAxisd rotation(dejumped.prior_rotation_offset[i]);
    Eigen::Matrix<double, 6, 1> b;
    b.head<3>() = R_track_enu * (rotation.angle() * rotation.axis());
    b.tail<3>() = R_track_enu * dejumped.prior_position_offset[i];
    state->knot_prior.push_back(b);
    // What the error gains beyond its process between the two knots'
    // samples (a jump that stays a step, an outage's closure; a sideways
    // switch's across the track only).
    Eigen::Vector3d extra = Eigen::Vector3d::Zero();
    for (int j = previous_sample + 1; k > 0 && j <= i; ++j) {
      extra += Eigen::Vector3d::Constant(dejumped.innovation_variance_m2[j]);
      // In ENU (track_frame false) the cross-track axis is no axis.
      const double across = dejumped.cross_track_innovation_variance_m2[j];
      if (options.model.track_frame) {
        extra.y() += across;
      } else {
        extra += Eigen::Vector3d::Constant(across);
      }
    }
    state->knot_extra_variance_m2.push_back(extra);
    previous_sample = i;
  }
}

void InitialiseCorrection(const Context& context, State* state) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  state->correction = TrajectoryCorrection(
      trajectory.start_time(), trajectory.end_time(),
      options.model.knot_spacing_s, options.model.track_frame);
  state->rig_corrections.assign(context.input.rig->cameras.size(),
                                std::array<double, kRigCorrectionSize>{});
  context.summary->num_knots = state->correction.num_knots();
  SetKnotPriors(context, context.dejumped, state);
  if (options.vehicle_motion.sideslip_sigma_rad > 0.0) {
    state->model.motion_sigma_rad = ChooseVehicleMotion(context, state);
  }
  context.summary->num_vehicle_motion = static_cast<int>(state->motion.size());
}

void FitPositionModel(const Context& context,
                      const std::vector<CrossingDiscrepancy>& crossings,
                      const State& state, ErrorModel* out) {
  const AdjustmentOptions& options = context.options;
  ErrorModel& model = *out;
  std::vector<bool> use(crossings.size(), false);
  for (const ControlPoint& p : state.points) {
    if (p.status != ControlStatus::kRejected &&
        p.crossing < static_cast<int>(crossings.size())) {
      use[p.crossing] = crossings[p.crossing].valid;
    }
  }
  // Without a control crossing, the road lines' own discrepancies: the
  // error model is fitted on what they show across them and in height.
  std::vector<CrossingDiscrepancy> lines;
  if (RoadLinesOnly(options, state)) {
    lines = LineDiscrepancies(state, options.road_lines.line_discrepancy_bin_s,
                              options.road_lines.line_discrepancy_min_points);
    use.assign(lines.size(), true);
  }
  const std::vector<CrossingDiscrepancy>& d = lines.empty() ? crossings : lines;
  for (int axis = 0; axis < 3; ++axis) {
    model.position_sigma_m[axis] =
        std::clamp(1.0, options.model.min_position_sigma_m,
                   options.model.max_position_sigma_m);
    model.position_tau_s[axis] = options.model.position_tau_s;
  }
  if (options.model.estimate_position_model) {
    const std::vector<GaussMarkovFit> fits =
        adjustment_internal::FitAxes(d, use, PositionFitOptions(options));
    for (int axis = 0; axis < 3; ++axis) {
      model.position_level_sigma_m[axis] =
          PositionSigma(options, d, use, axis, fits[axis].sigma);
      // The variation about that level: the likelihood's, where the
      // control shows a drift at all.
      model.position_sigma_m[axis] = model.position_level_sigma_m[axis] >
                                             options.model.min_position_sigma_m
                                         ? fits[axis].sigma
                                         : options.model.min_position_sigma_m;
      model.position_tau_s[axis] = fits[axis].tau_s;
    }
  }
  if (lines.empty() && !state.lines.empty() &&
      options.model.estimate_position_model) {
    WidenByLines(options, state, &model);
  }
  if (!lines.empty()) {
    // Nothing measures the along-track error (the correction is held there,
    // State::along_track_held); the cross-track one the lines show is the
    // best guess of its size, added to the posterior along-track.
    model.position_sigma_m[0] = model.position_sigma_m[1];
    model.position_level_sigma_m[0] = model.position_level_sigma_m[1];
    model.position_tau_s[0] = model.position_tau_s[1];
  }
}

ErrorModel InitialErrorModel(const Context& context,
                             const std::vector<CrossingDiscrepancy>& crossings,
                             const State& state) {
  const AdjustmentOptions& options = context.options;
  ErrorModel model;
  std::vector<double> sd[3];
  for (const TrajectorySample& s : context.input.trajectory->samples()) {
    for (int axis = 0; axis < 3; ++axis) {
      sd[axis].push_back(s.sd_attitude_rad[axis]);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    model.attitude_sigma_rad[axis] =
        std::clamp(Median(sd[axis]), options.model.min_attitude_sigma_rad,
                   options.model.max_attitude_sigma_rad);
    model.attitude_tau_s[axis] = options.model.attitude_tau_s;
  }
  model.motion_sigma_rad = state.model.motion_sigma_rad;
  model.tie_sigma_px = options.tie_points.tie_sigma_px;
  std::vector<double> times;
  for (const TrajectorySample& sample : context.input.trajectory->samples()) {
    times.push_back(sample.time);
  }
  const PositionJitter jitter =
      EstimatePositionJitter(times, context.dejumped.poses,
                             options.trajectory_faults.jitter_window_s, 0.1);
  if (jitter.sigma_m.maxCoeff() > options.trajectory_faults.min_jitter_m) {
    model.jitter_sigma_m = jitter.sigma_m;
    model.jitter_tau_s = jitter.tau_s;
    context.Warn(
        "the trajectory's positions jitter from sample to sample (robust RMS "
        "along-track " +
        FormatCm(jitter.sigma_m.x()) + ", cross-track " +
        FormatCm(jitter.sigma_m.y()) + ", up " + FormatCm(jitter.sigma_m.z()) +
        " about a smooth path): each exposure's position is corrected on its "
        "own where the data allow");
  }
  // After the jitter: the road lines' discrepancies hold it too.
  FitPositionModel(context, crossings, state, &model);
  LOG(INFO) << "adjustment: GNSS/INS error model: position sigma "
            << model.position_sigma_m.transpose() << " m, tau "
            << model.position_tau_s.transpose() << " s; attitude sigma "
            << RadToDeg(1.0) * model.attitude_sigma_rad.transpose()
            << " deg; jitter " << model.jitter_sigma_m.transpose() << " m, tau "
            << model.jitter_tau_s.transpose() << " s";
  return model;
}

bool RoadLinesOnly(const AdjustmentOptions& options, const State& state) {
  return options.road_lines.line_control_without_crossings &&
         !state.lines.empty() &&
         std::none_of(state.points.begin(), state.points.end(),
                      [](const ControlPoint& p) {
                        return p.status != ControlStatus::kRejected;
                      });
}

bool AlongTrackHeld(const AdjustmentOptions& options, const State& state) {
  return RoadLinesOnly(options, state) &&
         std::none_of(
             state.lines.begin(), state.lines.end(),
             [](const State::Line& line) { return line.point.along_track; });
}

}  // namespace adjustment_internal
}  // namespace zebrageo
