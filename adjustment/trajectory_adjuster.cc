// The trajectory adjustment's steps, in order (trajectory_adjuster.h):
// control points from the matches, control selection, check crossings,
// tie and line points, the correction and its error model, the solves with
// their blunder loop and variance components, the covariance, the outputs.
#include "adjustment/trajectory_adjuster.h"

#include <ceres/covariance.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "adjustment/adjustment_outputs.h"
#include "adjustment/adjustment_problem.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/control_selection.h"
#include "adjustment/error_model.h"
#include "adjustment/trajectory_jitter.h"
#include "adjustment/trajectory_jumps.h"
#include "adjustment/variance_components.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

using adjustment_internal::AdjustmentProblem;
using adjustment_internal::ControlPoint;
using adjustment_internal::CrossingDiscrepancy;
using adjustment_internal::CrossingVerdict;
using adjustment_internal::ErrorModel;
using adjustment_internal::ImageObservation;
using adjustment_internal::OutputContext;
using adjustment_internal::State;
using adjustment_internal::TiePoint;

std::string FormatCm(double metres) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << 100.0 * metres << " cm";
  return out.str();
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// What every step reads.
struct Context {
  const AdjustmentOptions& options;
  const AdjustmentInput& input;
  DejumpedTrajectory dejumped;
  AdjustmentSummary* summary;

  void Warn(const std::string& warning) const {
    LOG(WARNING) << warning;
    summary->warnings.push_back(warning);
  }
  bool InsPoseAt(double time, Pose* pose) const {
    return InterpolateDejumped(*input.trajectory, dejumped, time, pose);
  }
};

struct CrossingTable {
  std::vector<std::string> names;
  std::vector<double> first_time;
  // One band period across the crossing (ENU), from the database.
  std::vector<Eigen::Vector3d> period_enu;
};

// The band period vector of a database crossing: the least-squares slope
// of its bands' centres against their numbers (zero with fewer than two
// bands).
Eigen::Vector3d BandPeriodEnu(const RoadmarkDatabase& roadmarks,
                              const LocalFrame& frame,
                              const std::string& crossing_id) {
  std::vector<std::pair<double, Eigen::Vector3d>> centres;
  for (const RoadmarkBand& band : roadmarks.bands) {
    if (band.crossing_id != crossing_id) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Geodetic& corner : band.corners) {
      centre += frame.EnuFromGeodetic(corner) / 4.0;
    }
    centres.emplace_back(band.band, centre);
  }
  if (centres.size() < 2) return Eigen::Vector3d::Zero();
  double mean_n = 0.0;
  Eigen::Vector3d mean_c = Eigen::Vector3d::Zero();
  for (const auto& [n, c] : centres) {
    mean_n += n / centres.size();
    mean_c += c / centres.size();
  }
  double snn = 0.0;
  Eigen::Vector3d snc = Eigen::Vector3d::Zero();
  for (const auto& [n, c] : centres) {
    snn += (n - mean_n) * (n - mean_n);
    snc += (n - mean_n) * (c - mean_c);
  }
  return snn > 0.0 ? Eigen::Vector3d(snc / snn) : Eigen::Vector3d::Zero();
}

// One control point per matched database vertex, with its image
// observations; the crossings they belong to.
CrossingTable AddControlPoints(const Context& context, State* state) {
  const AdjustmentInput& input = context.input;
  const AdjustmentOptions& options = context.options;
  const Rig& rig = *input.rig;
  std::unordered_map<int64_t, double> exposure_time;
  for (const Exposure& e : input.exposures->exposures) {
    exposure_time[e.exposure_id] = e.time;
  }
  std::map<std::tuple<int64_t, int64_t, int>, const ReconstructedVertex*>
      vertex_of;
  for (const ReconstructedVertex& v : *input.vertices) {
    vertex_of[{v.exposure_id, v.band_id, v.vertex}] = &v;
  }
  std::map<std::pair<std::string, int>, const RoadmarkBand*> band_of;
  for (const RoadmarkBand& b : input.roadmarks->bands) {
    band_of[{b.crossing_id, b.band}] = &b;
  }
  CrossingTable crossings;
  std::map<std::tuple<std::string, int, int>, int> point_of;
  std::map<std::string, int> crossing_of;
  int unknown_vertices = 0, unknown_bands = 0, bad_pairs = 0,
      outside_trajectory = 0;
  for (const VertexMatch& m : *input.matches) {
    const auto v = vertex_of.find({m.exposure_id, m.band_id, m.vertex});
    if (v == vertex_of.end()) {
      ++unknown_vertices;
      continue;
    }
    const auto b = band_of.find({m.crossing_id, m.band});
    if (b == band_of.end() || m.db_vertex < 0 || m.db_vertex > 3) {
      ++unknown_bands;
      continue;
    }
    const ReconstructedVertex& vertex = *v->second;
    if (vertex.pair < 0 ||
        vertex.pair >= static_cast<int>(rig.stereo_pairs.size())) {
      ++bad_pairs;
      continue;
    }
    const auto t = exposure_time.find(m.exposure_id);
    Pose ins_pose;
    if (t == exposure_time.end() || !context.InsPoseAt(t->second, &ins_pose)) {
      ++outside_trajectory;
      continue;
    }
    auto [it, inserted] = point_of.try_emplace(
        std::make_tuple(m.crossing_id, m.band, m.db_vertex),
        static_cast<int>(state->points.size()));
    if (inserted) {
      const RoadmarkBand& band = *b->second;
      ControlPoint p;
      p.crossing_id = m.crossing_id;
      p.band = m.band;
      p.db_vertex = m.db_vertex;
      auto [c, new_crossing] = crossing_of.try_emplace(
          m.crossing_id, static_cast<int>(crossings.names.size()));
      if (new_crossing) {
        crossings.names.push_back(m.crossing_id);
        crossings.first_time.push_back(t->second);
        crossings.period_enu.push_back(
            BandPeriodEnu(*input.roadmarks, *input.frame, m.crossing_id));
      }
      p.crossing = c->second;
      crossings.first_time[p.crossing] =
          std::min(crossings.first_time[p.crossing], t->second);
      p.database_enu = input.frame->EnuFromGeodetic(band.corners[m.db_vertex]);
      const double sxy =
          std::max(band.sigma_xy_m, options.min_database_sigma_m);
      const double sz = std::max(band.sigma_z_m, options.min_database_sigma_m);
      p.sigma_m = Eigen::Vector3d(sxy, sxy, sz);
      p.estimate = p.database_enu;
      state->points.push_back(p);
    }
    ControlPoint& p = state->points[it->second];
    const auto& pair = rig.stereo_pairs[vertex.pair];
    const int exposure = state->ExposureIndex(t->second);
    p.stereo.push_back(
        {t->second, exposure, ins_pose, vertex.p_body, vertex.covariance_body});
    p.observations.push_back(
        {t->second, pair[0], vertex.uv_left, ins_pose, 1.0, exposure});
    p.observations.push_back(
        {t->second, pair[1], vertex.uv_right, ins_pose, 1.0, exposure});
  }
  if (unknown_vertices > 0) {
    context.Warn(std::to_string(unknown_vertices) +
                 " rows of matches.csv name a vertex that is not in "
                 "reconstructed_bands.csv: ignored");
  }
  if (unknown_bands > 0) {
    context.Warn(std::to_string(unknown_bands) +
                 " rows of matches.csv name a database band or vertex that "
                 "is not in the road-mark database: ignored");
  }
  if (bad_pairs > 0) {
    context.Warn(std::to_string(bad_pairs) +
                 " matched vertices name a stereo pair that is not in "
                 "rig.yaml: ignored");
  }
  if (outside_trajectory > 0) {
    context.Warn(std::to_string(outside_trajectory) +
                 " matched vertices belong to exposures outside the "
                 "trajectory: ignored");
  }
  state->crossing_offsets.assign(crossings.names.size(),
                                 Eigen::Vector3d::Zero());
  return crossings;
}

// Check crossings: every k-th consistent crossing in time order, as long
// as min_control_crossings remain.
void MarkCheckCrossings(const Context& context, const CrossingTable& crossings,
                        State* state) {
  const AdjustmentOptions& options = context.options;
  const int num_crossings = static_cast<int>(crossings.names.size());
  std::vector<char> usable(num_crossings, 0);
  for (const ControlPoint& p : state->points) {
    if (p.status == ControlStatus::kControl) usable[p.crossing] = 1;
  }
  std::vector<int> order;
  for (int c = 0; c < num_crossings; ++c) {
    if (usable[c]) order.push_back(c);
  }
  if (options.check_crossing_share <= 0.0 || order.empty()) return;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return crossings.first_time[a] < crossings.first_time[b];
  });
  const int k = std::max(
      2, static_cast<int>(std::lround(1.0 / options.check_crossing_share)));
  std::vector<int> checks;
  for (size_t i = k / 2; i < order.size(); i += k) checks.push_back(order[i]);
  if (static_cast<int>(order.size() - checks.size()) <
      options.min_control_crossings) {
    if (!checks.empty()) {
      context.Warn("only " + std::to_string(order.size()) +
                   " crossings matched: none held out as check points, the "
                   "accuracy reported is not independently checked");
    }
    return;
  }
  std::vector<char> is_check(num_crossings, 0);
  for (int c : checks) is_check[c] = 1;
  for (ControlPoint& p : state->points) {
    if (p.status == ControlStatus::kControl && is_check[p.crossing]) {
      p.status = ControlStatus::kCheck;
    }
  }
}

void AddTieAndLinePoints(const Context& context, State* state) {
  const AdjustmentInput& input = context.input;
  const Rig& rig = *input.rig;
  if (input.tie_tracks != nullptr) {
    for (size_t i = 0; i < input.tie_tracks->size(); ++i) {
      const TieTrack& track = (*input.tie_tracks)[i];
      TiePoint tie;
      tie.estimate = track.p_enu;
      tie.source = static_cast<int>(i);
      for (const TieObservation& o : track.observations) {
        Pose ins_pose;
        if (o.camera < 0 || o.camera >= static_cast<int>(rig.cameras.size()) ||
            !context.InsPoseAt(o.time, &ins_pose)) {
          continue;
        }
        tie.observations.push_back({o.time, o.camera, o.uv, ins_pose, o.scale,
                                    state->ExposureIndex(o.time)});
      }
      if (tie.observations.size() >= 2) state->ties.push_back(tie);
    }
  }
  context.summary->num_tie_tracks = static_cast<int>(state->ties.size());
  if (input.line_points != nullptr) {
    for (const LineControlPoint& line : *input.line_points) {
      Pose ins_pose;
      if (context.InsPoseAt(line.time, &ins_pose)) {
        state->lines.push_back(
            {line, ins_pose, state->ExposureIndex(line.time)});
      }
    }
  }
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
  const Eigen::Vector2d stated(DegToRad(options.sideslip_sigma_deg),
                               DegToRad(options.vertical_slip_sigma_deg));
  double best_information = 0.0;
  Eigen::Vector2d best_sigma = stated;
  std::vector<VehicleMotionSample> best;
  for (double factor : {1.0, 2.0, 5.0, 10.0, 20.0}) {
    const double half_chord = factor * options.vehicle_motion_half_chord_s;
    const double rate =
        std::min(options.vehicle_motion_rate_hz, 1.0 / (2.0 * half_chord));
    std::vector<VehicleMotionSample> samples = MakeVehicleMotionSamples(
        state->correction, sample_times, rate, half_chord,
        options.vehicle_motion_min_speed_mps, stated,
        [&context](double time, Pose* pose) {
          return context.InsPoseAt(time, pose);
        });
    if (samples.size() < 8) continue;
    const Eigen::Vector2d spread = HighFrequencyCrabSpread(
        samples, state->correction, std::max(1.0, 10.0 * half_chord));
    // Constraints closer than the sideslip's correlation time are not
    // independent: each counts for its share of that time.
    const double shared =
        std::sqrt(std::max(1.0, rate * options.vehicle_motion_correlation_s));
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

// The zero correction over the trajectory, the prior's centre at each knot
// (the jumps taken out before it) and the vehicle-motion constraints.
void InitialiseCorrection(const Context& context, State* state) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  state->correction =
      TrajectoryCorrection(trajectory.start_time(), trajectory.end_time(),
                           options.knot_spacing_s, options.track_frame);
  state->rig_corrections.assign(context.input.rig->cameras.size(),
                                std::array<double, kRigCorrectionSize>{});
  context.summary->num_knots = state->correction.num_knots();
  if (context.dejumped.num_jumps > 0) {
    for (int k = 0; k < state->correction.num_knots(); ++k) {
      const double t =
          std::clamp(state->correction.KnotTime(k), trajectory.start_time(),
                     trajectory.end_time());
      const int i = std::max(0, trajectory.FindSegment(t));
      Pose pose;
      context.InsPoseAt(t, &pose);
      const Eigen::Matrix3d R_track_enu =
          state->correction.Frame(pose).transpose();
      const Eigen::AngleAxisd rotation(context.dejumped.rotation_offset[i]);
      Eigen::Matrix<double, 6, 1> b;
      b.head<3>() = R_track_enu * (rotation.angle() * rotation.axis());
      b.tail<3>() = R_track_enu * context.dejumped.position_offset[i];
      state->knot_prior.push_back(b);
    }
  }
  if (options.sideslip_sigma_deg > 0.0) {
    state->model.motion_sigma_rad = ChooseVehicleMotion(context, state);
  }
  context.summary->num_vehicle_motion = static_cast<int>(state->motion.size());
}

GaussMarkovFitOptions PositionFitOptions(const AdjustmentOptions& options) {
  GaussMarkovFitOptions fit;
  fit.min_sigma = options.min_position_sigma_m;
  fit.max_sigma = options.max_position_sigma_m;
  fit.default_tau_s = options.position_tau_s;
  fit.min_samples_for_tau = options.min_crossings_for_tau;
  return fit;
}

// Crossings that disagree with the others and the error model are
// rejected whole (control_selection.h), with a warning naming each.
void RejectInconsistentCrossings(const Context& context,
                                 const CrossingTable& crossings,
                                 const std::vector<CrossingDiscrepancy>& d,
                                 State* state) {
  const std::vector<CrossingVerdict> verdicts =
      adjustment_internal::SelectConsistentCrossings(
          d, crossings.names, PositionFitOptions(context.options),
          context.options.crossing_consistency_chi_square);
  for (size_t c = 0; c < verdicts.size(); ++c) {
    if (verdicts[c].consistent) continue;
    context.Warn(verdicts[c].reason + ": not used as control");
    for (ControlPoint& p : state->points) {
      if (p.crossing == static_cast<int>(c)) {
        p.status = ControlStatus::kRejected;
        p.normalized_residual = std::sqrt(verdicts[c].chi_square);
      }
    }
  }
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
    return options.min_position_sigma_m;
  }
  constexpr double kNoShrinkFactor = 3.0;
  return std::clamp(
      std::max(likelihood_sigma, kNoShrinkFactor * std::sqrt(sum_square / n)),
      options.min_position_sigma_m, options.max_position_sigma_m);
}

// The error model the adjustment starts from: the position process fitted
// to the consistent crossings' discrepancies, the attitude from the
// trajectory's own claimed sd.
ErrorModel InitialErrorModel(const Context& context,
                             const std::vector<CrossingDiscrepancy>& d,
                             const State& state) {
  const AdjustmentOptions& options = context.options;
  ErrorModel model;
  std::vector<bool> use(d.size(), false);
  for (const ControlPoint& p : state.points) {
    if (p.status != ControlStatus::kRejected)
      use[p.crossing] = d[p.crossing].valid;
  }
  for (int axis = 0; axis < 3; ++axis) {
    model.position_sigma_m[axis] = std::clamp(1.0, options.min_position_sigma_m,
                                              options.max_position_sigma_m);
    model.position_tau_s[axis] = options.position_tau_s;
  }
  if (options.estimate_position_model) {
    const std::vector<GaussMarkovFit> fits =
        adjustment_internal::FitAxes(d, use, PositionFitOptions(options));
    for (int axis = 0; axis < 3; ++axis) {
      model.position_level_sigma_m[axis] =
          PositionSigma(options, d, use, axis, fits[axis].sigma);
      // The variation about that level: the likelihood's, where the
      // control shows a drift at all.
      model.position_sigma_m[axis] =
          model.position_level_sigma_m[axis] > options.min_position_sigma_m
              ? fits[axis].sigma
              : options.min_position_sigma_m;
      model.position_tau_s[axis] = fits[axis].tau_s;
    }
  }
  std::vector<double> sd[3];
  for (const TrajectorySample& s : context.input.trajectory->samples()) {
    for (int axis = 0; axis < 3; ++axis) {
      sd[axis].push_back(s.sd_attitude_rad[axis]);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    model.attitude_sigma_rad[axis] =
        std::clamp(Median(sd[axis]), options.min_attitude_sigma_rad,
                   options.max_attitude_sigma_rad);
    model.attitude_tau_s[axis] = options.attitude_tau_s;
  }
  model.motion_sigma_rad = state.model.motion_sigma_rad;
  model.tie_sigma_px = options.tie_sigma_px;
  std::vector<double> times;
  for (const TrajectorySample& sample : context.input.trajectory->samples()) {
    times.push_back(sample.time);
  }
  const PositionJitter jitter = EstimatePositionJitter(
      times, context.dejumped.poses, options.jitter_window_s, 0.1);
  if (jitter.sigma_m.maxCoeff() > options.min_jitter_m) {
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
  LOG(INFO) << "adjustment: GNSS/INS error model: position sigma "
            << model.position_sigma_m.transpose() << " m, tau "
            << model.position_tau_s.transpose() << " s; attitude sigma "
            << RadToDeg(1.0) * model.attitude_sigma_rad.transpose()
            << " deg; jitter " << model.jitter_sigma_m.transpose() << " m, tau "
            << model.jitter_tau_s.transpose() << " s";
  return model;
}

// The solves: least squares, then robust, then the blunder loop.
class Solver {
 public:
  Solver(const Context& context, State* state,
         const std::function<void(int, int)>& progress)
      : context_(context), state_(state), progress_(progress) {}

  AdjustmentProblem* problem() { return problem_.get(); }

  // False (summary.message set) when a solve fails.
  bool Adjust() {
    const AdjustmentOptions& options = context_.options;
    // Least squares first (the drift makes every observation look like an
    // outlier at the start), then robustly.
    if (!SolveTwice()) return false;
    for (int iteration = 0; iteration < options.max_blunder_iterations;
         ++iteration) {
      if (!RejectBlunders()) break;
      if (!HasControl()) return true;
      adjustment_internal::ResetState(state_);
      if (!SolveTwice()) return false;
    }
    context_.summary->sigma0 = problem_->Sigma0();
    return true;
  }

  bool HasControl() const {
    return std::any_of(state_->points.begin(), state_->points.end(),
                       [](const ControlPoint& p) {
                         return p.status == ControlStatus::kControl;
                       });
  }

 private:
  bool SolveTwice() { return Solve(false) && Solve(true); }

  bool Solve(bool robust) {
    AdjustmentSummary& summary = *context_.summary;
    problem_ = std::make_unique<AdjustmentProblem>(
        context_.options, *context_.input.rig, robust, state_);
    const ceres::Solver::Summary s = problem_->Solve();
    ++summary.solves;
    summary.iterations += static_cast<int>(s.iterations.size()) - 1;
    summary.num_residuals = s.num_residuals;
    if (progress_) progress_(summary.solves, summary.solves + 2);
    if (!s.IsSolutionUsable() || !std::isfinite(s.final_cost)) {
      summary.message = "Ceres failed: " + s.message;
      return false;
    }
    return true;
  }

  // Rejects the worst control vertices and crossings; false when none
  // exceeds the threshold.
  bool RejectBlunders() {
    const AdjustmentOptions& options = context_.options;
    State& state = *state_;
    adjustment_internal::EvaluateControlPoints(options, *context_.input.rig,
                                               state_);
    const int num_crossings = static_cast<int>(state.crossing_offsets.size());
    double worst = 0.0;
    for (const ControlPoint& p : state.points) {
      if (p.status == ControlStatus::kControl) {
        worst = std::max(worst, p.normalized_residual);
      }
    }
    // A whole crossing off: its estimated offset against the offset prior.
    std::vector<double> crossing_w(num_crossings, 0.0);
    if (options.crossing_offset_sigma_m > 0.0) {
      for (int c = 0; c < num_crossings; ++c) {
        crossing_w[c] =
            state.crossing_offsets[c].norm() / options.crossing_offset_sigma_m;
      }
    }
    for (const ControlPoint& p : state.points) {
      if (p.status == ControlStatus::kControl) {
        worst = std::max(worst, crossing_w[p.crossing]);
      }
    }
    VLOG(1) << "blunder test: worst normalised residual " << worst;
    for (int c = 0; c < num_crossings; ++c) {
      VLOG(1) << "  crossing " << c << " offset "
              << state.crossing_offsets[c].transpose() << " (" << crossing_w[c]
              << " sigma)";
    }
    if (worst <= options.blunder_threshold) return false;
    for (ControlPoint& p : state.points) {
      if (p.status == ControlStatus::kControl &&
          crossing_w[p.crossing] > options.blunder_threshold &&
          crossing_w[p.crossing] >= 0.5 * worst) {
        p.status = ControlStatus::kRejected;
        p.normalized_residual =
            std::max(p.normalized_residual, crossing_w[p.crossing]);
      }
    }
    // Reject the worst vertices (those within half of the worst), then
    // whole crossings that lost too many.
    std::vector<int> rejected_in(num_crossings, 0),
        control_in(num_crossings, 0);
    for (ControlPoint& p : state.points) {
      if (p.status != ControlStatus::kControl) continue;
      ++control_in[p.crossing];
      if (p.normalized_residual > options.blunder_threshold &&
          p.normalized_residual >= 0.5 * worst) {
        p.status = ControlStatus::kRejected;
        ++rejected_in[p.crossing];
      }
    }
    for (ControlPoint& p : state.points) {
      if (p.status == ControlStatus::kControl &&
          rejected_in[p.crossing] >
              options.reject_crossing_share * control_in[p.crossing]) {
        p.status = ControlStatus::kRejected;
      }
    }
    return true;
  }

  const Context& context_;
  State* state_;
  std::function<void(int, int)> progress_;
  std::unique_ptr<AdjustmentProblem> problem_;
};

// Posterior covariance of each trajectory sample's position (ENU), or
// empty when not computed.
std::vector<Eigen::Matrix3d> SampleCovariance(const Context& context,
                                              State* state,
                                              AdjustmentProblem* problem) {
  const AdjustmentOptions& options = context.options;
  const Trajectory& trajectory = *context.input.trajectory;
  std::vector<Eigen::Matrix3d> sample_covariance;
  if (problem == nullptr || !options.compute_covariance ||
      state->correction.num_knots() > options.max_knots_for_covariance) {
    return sample_covariance;
  }
  ceres::Covariance::Options covariance_options;
  covariance_options.num_threads = options.solver.num_threads;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  auto& knots = state->correction.knots();
  const int n = static_cast<int>(knots.size());
  std::vector<std::pair<const double*, const double*>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < std::min(n, i + 4); ++j) {
      pairs.emplace_back(knots[i].data(), knots[j].data());
    }
  }
  if (!covariance.Compute(pairs, problem->problem())) {
    context.Warn(
        "the posterior covariance could not be computed (rank deficient): "
        "trajectory_corrected.csv keeps the input sd_*");
    return sample_covariance;
  }
  const double sigma0 = context.summary->sigma0;
  const double scale = std::max(1.0, sigma0 * sigma0);
  sample_covariance.reserve(trajectory.size());
  for (const TrajectorySample& sample : trajectory.samples()) {
    int first = 0;
    double w[4];
    state->correction.Basis(sample.time, &first, w);
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const int i = std::min(first + a, first + b);
        const int j = std::max(first + a, first + b);
        Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
        covariance.GetCovarianceBlock(knots[i].data(), knots[j].data(),
                                      block.data());
        Eigen::Matrix3d position = block.block<3, 3>(3, 3);
        if (first + a > first + b) position.transposeInPlace();
        C += w[a] * w[b] * position;
      }
    }
    sample_covariance.push_back(scale * C);
  }
  context.summary->covariance_computed = true;
  return sample_covariance;
}

// Check points: their residuals from the adjustment that did not see them,
// then control in the final adjustment.
void HoldOutCheckPoints(const Context& context, State* state) {
  const AdjustmentOptions& options = context.options;
  const Rig& rig = *context.input.rig;
  adjustment_internal::EvaluateControlPoints(options, rig, state);
  for (ControlPoint& p : state->points) {
    if (p.status != ControlStatus::kCheck) continue;
    p.held_out = true;
    p.held_out_normalized_residual = p.normalized_residual;
    Eigen::Matrix3d covariance;
    p.held_out_triangulated = adjustment_internal::StereoPosition(
        options, *state, p.stereo, &p.held_out_enu, &covariance);
    std::vector<double> errors;
    for (const ImageObservation& o : p.observations) {
      Eigen::Vector2d e;
      if (p.held_out_triangulated && adjustment_internal::PixelResidual(
                                         rig, *state, o, p.held_out_enu, &e)) {
        errors.push_back(e.norm());
      }
    }
    p.held_out_rms_px = Rms(errors);
    p.status = ControlStatus::kControl;
  }
}

// RMS crab angles (lateral, vertical) the vehicle-motion constraint leaves,
// degrees.
Eigen::Vector2d CrabRmsDeg(const State& state) {
  std::vector<double> lateral, vertical;
  for (const VehicleMotionSample& sample : state.motion) {
    const Eigen::Vector2d crab =
        CrabAngleResidual(sample, state.correction, state.vehicle.data());
    lateral.push_back(RadToDeg(crab.x()));
    vertical.push_back(RadToDeg(crab.y()));
  }
  return Eigen::Vector2d(Rms(lateral), Rms(vertical));
}

void SummariseModel(const State& state, AdjustmentSummary* summary) {
  summary->position_sigma_m = state.model.position_sigma_m;
  summary->position_tau_s = state.model.position_tau_s;
  summary->attitude_sigma_rad = state.model.attitude_sigma_rad;
  summary->motion_sigma_rad = state.model.motion_sigma_rad;
  summary->tie_sigma_px = state.model.tie_sigma_px;
}

}  // namespace

AdjustmentResult AdjustTrajectory(
    const AdjustmentOptions& options, const AdjustmentInput& input,
    const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  AdjustmentResult result;
  AdjustmentSummary& summary = result.summary;
  const std::string error = options.Check();
  if (!error.empty()) {
    summary.message = "invalid AdjustmentOptions: " + error;
    return result;
  }
  if (input.rig == nullptr || input.frame == nullptr ||
      input.trajectory == nullptr || input.exposures == nullptr ||
      input.roadmarks == nullptr || input.vertices == nullptr ||
      input.matches == nullptr) {
    summary.message = "AdjustmentInput: a required input is missing";
    return result;
  }
  summary.num_exposures = static_cast<int>(input.exposures->exposures.size());
  // The INS trajectory the correction applies to: without its jumps.
  Context context{options, input,
                  RemoveJumps(*input.trajectory, options.jump_threshold_m,
                              DegToRad(options.jump_threshold_deg)),
                  &summary};
  summary.num_jumps = context.dejumped.num_jumps;
  if (summary.num_jumps > 0) {
    context.Warn(std::to_string(summary.num_jumps) +
                 " jumps in the GNSS/INS trajectory (GNSS returning after an "
                 "outage?): corrected as continuous INS motion");
  }

  State state;
  for (const Exposure& e : input.exposures->exposures) {
    state.exposure_times.push_back(e.time);
  }
  std::sort(state.exposure_times.begin(), state.exposure_times.end());
  state.exposure_times.erase(
      std::unique(state.exposure_times.begin(), state.exposure_times.end()),
      state.exposure_times.end());
  state.exposure_offsets.assign(state.exposure_times.size(),
                                Eigen::Vector3d::Zero());
  const CrossingTable crossings = AddControlPoints(context, &state);
  InitialiseCorrection(context, &state);
  for (double time : state.exposure_times) {
    Pose pose;
    state.exposure_frames.push_back(context.InsPoseAt(time, &pose)
                                        ? state.correction.Frame(pose)
                                        : Eigen::Matrix3d::Identity());
  }
  AddTieAndLinePoints(context, &state);
  const std::vector<CrossingDiscrepancy> discrepancies =
      adjustment_internal::CrossingDiscrepancies(options, state,
                                                 crossings.period_enu);
  RejectInconsistentCrossings(context, crossings, discrepancies, &state);
  MarkCheckCrossings(context, crossings, &state);
  state.model = InitialErrorModel(context, discrepancies, state);
  const adjustment_internal::StateRms before =
      adjustment_internal::MeasureState(*input.rig, state);
  const Eigen::Vector2d crab_before_deg = CrabRmsDeg(state);

  // Without zebra control nothing holds the trajectory in place: ties, road
  // lines and the vehicle's motion are relative (lines are matched with the
  // trajectory the zebras corrected). The input trajectory is kept.
  Solver solver(context, &state, progress);
  bool adjusted = solver.HasControl() ||
                  std::any_of(state.points.begin(), state.points.end(),
                              [](const ControlPoint& p) {
                                return p.status == ControlStatus::kCheck;
                              });
  std::string why_not = "no control point (no matched band vertex)";
  if (adjusted) {
    const bool any_check = std::any_of(
        state.points.begin(), state.points.end(), [](const ControlPoint& p) {
          return p.status == ControlStatus::kCheck;
        });
    adjusted = solver.Adjust();
    if (adjusted && any_check && options.check_points_in_final) {
      HoldOutCheckPoints(context, &state);
      adjustment_internal::ResetState(&state);
      adjusted = solver.Adjust();
    }
    if (adjusted && options.estimate_variance_components) {
      for (int i = 0; i < options.max_variance_iterations; ++i) {
        if (!adjustment_internal::UpdateVarianceComponents(
                options, solver.problem(), &state, &summary.warnings)) {
          break;
        }
        adjustment_internal::ResetState(&state);
        if (!(adjusted = solver.Adjust())) break;
      }
    }
    if (!adjusted) why_not = summary.message;
    if (adjusted && !solver.HasControl()) {
      adjusted = false;
      why_not =
          "every control point was rejected as a blunder: the control "
          "disagrees with the trajectory and with itself";
    }
  }
  if (!adjusted) {
    context.Warn(why_not +
                 ": the trajectory is not corrected, poses come from the "
                 "input trajectory");
    adjustment_internal::ResetState(&state);
  }
  adjustment_internal::EvaluateControlPoints(options, *input.rig, &state);
  const adjustment_internal::StateRms after =
      adjustment_internal::MeasureState(*input.rig, state);

  OutputContext output;
  output.options = &options;
  output.input = &input;
  output.dejumped = &context.dejumped;
  output.adjusted = adjusted;
  output.warn = [&context](const std::string& w) { context.Warn(w); };
  if (adjusted) {
    output.sample_covariance =
        SampleCovariance(context, &state, solver.problem());
  }
  if (!adjustment_internal::FillOutputs(output, &state, &result)) {
    return result;
  }
  summary.rms.push_back({"control_image", "px", after.control_images,
                         before.control_px, after.control_px});
  summary.rms.push_back({"control_database", "m", after.control_points,
                         before.control_m, after.control_m});
  if (!state.ties.empty()) {
    summary.rms.push_back(
        {"tie_image", "px", after.tie_images, before.tie_px, after.tie_px});
  }
  if (!state.motion.empty()) {
    const Eigen::Vector2d crab_after_deg = CrabRmsDeg(state);
    summary.rms.push_back({"vehicle_lateral_slip", "deg",
                           summary.num_vehicle_motion, crab_before_deg.x(),
                           crab_after_deg.x()});
    summary.rms.push_back({"vehicle_vertical_slip", "deg",
                           summary.num_vehicle_motion, crab_before_deg.y(),
                           crab_after_deg.y()});
    summary.vehicle_yaw_misalignment_deg = RadToDeg(state.vehicle[0]);
    summary.vehicle_axle_offset_m = state.vehicle[1];
    summary.vehicle_pitch_misalignment_deg = RadToDeg(state.vehicle[2]);
  }
  SummariseModel(state, &summary);
  summary.rms.push_back({"trajectory_correction_horizontal", "m",
                         input.trajectory->size(), 0.0,
                         summary.rms_correction_horizontal_m});
  summary.time_in_seconds = Seconds(start);
  summary.usable = true;
  summary.message = adjusted ? "adjusted" : "not adjusted: " + why_not;
  LOG(INFO) << "adjustment: " << summary.BriefReport();
  return result;
}

}  // namespace zebrageo
