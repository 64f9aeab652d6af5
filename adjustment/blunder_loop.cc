// The solves of the trajectory adjustment and its blunder loop
// (blunder_loop.h).
#include "adjustment/blunder_loop.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "adjustment/adjustment_setup.h"
#include "adjustment/attitude_significance.h"
#include "adjustment/variance_components.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {

bool AdjustmentSolver::Adjust() {
  const AdjustmentOptions& options = context_.options;
  // Least squares first (the drift makes every observation look like an
  // outlier at the start), then robustly.
  if (!SolveTwice()) return false;
  for (int iteration = 0; iteration < options.blunders.max_blunder_iterations;
       ++iteration) {
    if (!RejectBlunders()) break;
    if (!HasControl()) {
      if (!RoadLinesOnly(options, *state_)) return true;
      // The last crossing rejected: the road lines alone hold the
      // trajectory now, solved as when none had been matched (SelectControl):
      // along the track nothing measures it (a height misfit on a grade
      // would move it by metres) unless crossing edges do, and the position
      // process is the lines'.
      state_->along_track_held = AlongTrackHeld(options, *state_);
      FitPositionModel(context_, {}, *state_, &state_->model);
      adjustment_internal::ResetState(state_);
      if (!SolveTwice()) return false;
      break;
    }
    adjustment_internal::ResetState(state_);
    if (!SolveTwice()) return false;
  }
  context_.summary->sigma0 = problem_->Sigma0();
  return true;
}

bool AdjustmentSolver::HasControl() const {
  return std::any_of(state_->points.begin(), state_->points.end(),
                     [](const ControlPoint& p) {
                       return p.status == ControlStatus::kControl;
                     });
}

bool AdjustmentSolver::Solve(bool robust) {
  AdjustmentSummary& summary = *context_.summary;
  context_.cancel.ThrowIfCancelled();
  problem_ = std::make_unique<AdjustmentProblem>(
      context_.options, *context_.input.rig, robust, state_);
  const ceres::Solver::Summary s = problem_->Solve(context_.cancel);
  // A solve the cancellation stopped is no result.
  context_.cancel.ThrowIfCancelled();
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

bool AdjustmentSolver::RejectBlunders() {
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
  if (options.control.crossing_offset_sigma_m > 0.0) {
    for (int c = 0; c < num_crossings; ++c) {
      crossing_w[c] = state.crossing_offsets[c].norm() /
                      options.control.crossing_offset_sigma_m;
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
  if (worst <= options.blunders.blunder_threshold) return false;
  for (ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kControl &&
        crossing_w[p.crossing] > options.blunders.blunder_threshold &&
        crossing_w[p.crossing] >= 0.5 * worst) {
      p.status = ControlStatus::kRejected;
      p.normalized_residual =
          std::max(p.normalized_residual, crossing_w[p.crossing]);
    }
  }
  // Reject the worst vertices (those within half of the worst), then
  // whole crossings that lost too many.
  std::vector<int> rejected_in(num_crossings, 0), control_in(num_crossings, 0);
  for (ControlPoint& p : state.points) {
    if (p.status != ControlStatus::kControl) continue;
    ++control_in[p.crossing];
    if (p.normalized_residual > options.blunders.blunder_threshold &&
        p.normalized_residual >= 0.5 * worst) {
      p.status = ControlStatus::kRejected;
      ++rejected_in[p.crossing];
    }
  }
  for (ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kControl &&
        rejected_in[p.crossing] >
            options.blunders.reject_crossing_share * control_in[p.crossing]) {
      p.status = ControlStatus::kRejected;
    }
  }
  return true;
}

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

bool RunAdjustments(const Context& context, State* state,
                    AdjustmentSolver* solver, std::string* why_not) {
  const AdjustmentOptions& options = context.options;
  AdjustmentSummary& summary = *context.summary;
  const bool any_check = std::any_of(
      state->points.begin(), state->points.end(),
      [](const ControlPoint& p) { return p.status == ControlStatus::kCheck; });
  // Without zebra control only road lines hold the trajectory, across them
  // and in height (the error model is then fitted on them,
  // line_discrepancies.h); ties and the vehicle's motion are relative.
  // Without either the input trajectory is kept.
  const bool line_control = options.road_lines.line_control_without_crossings &&
                            !state->lines.empty();
  if (!solver->HasControl() && !any_check && !line_control) {
    *why_not = "no control point (no matched band vertex)";
    return false;
  }
  bool adjusted = solver->Adjust();
  // The attitude axes the control does not determine held at the input's
  // before anything is measured: the check points' held-out residuals
  // come from the adjustment the user gets.
  if (adjusted &&
      HoldInsignificantAttitude(context, state, solver->problem())) {
    ResetState(state);
    adjusted = solver->Adjust();
  }
  if (adjusted && any_check && options.control.check_points_in_final) {
    HoldOutCheckPoints(context, state);
    ResetState(state);
    adjusted = solver->Adjust();
  }
  if (adjusted && options.model.estimate_variance_components) {
    for (int i = 0; i < options.model.max_variance_iterations; ++i) {
      if (!UpdateVarianceComponents(options, solver->problem(), state,
                                    &summary.warnings)) {
        break;
      }
      ResetState(state);
      if (!(adjusted = solver->Adjust())) break;
    }
  }
  if (!adjusted) {
    *why_not = summary.message;
    return false;
  }
  if (!solver->HasControl() && !line_control) {
    *why_not =
        "every control point was rejected as a blunder: the control "
        "disagrees with the trajectory and with itself";
    return false;
  }
  return true;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
