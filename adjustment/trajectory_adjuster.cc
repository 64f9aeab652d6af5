// The trajectory adjustment's steps, in order (trajectory_adjuster.h), each
// in its own file in the manner of COLMAP's bundle adjustment:
//   adjustment_observations.cc  control points from the matches, tie and
//                               line points
//   adjustment_setup.cc         the correction, the vehicle motion and the
//                               GNSS/INS error model
//   control_selection.cc        consistent crossings, check crossings
//   adjustment_problem.cc       the Ceres problem of one solve
//   blunder_loop.cc             the solves, the blunder loop, the check
//                               points held out, the variance components
//   covariance.cc               the posterior covariance
//   adjustment_outputs.cc       the results and the summary's figures
#include "adjustment/trajectory_adjuster.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_observations.h"
#include "adjustment/adjustment_outputs.h"
#include "adjustment/adjustment_setup.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/blunder_loop.h"
#include "adjustment/control_selection.h"
#include "adjustment/covariance.h"
#include "adjustment/input_guard.h"
#include "adjustment/outage_model.h"
#include "adjustment/trajectory_jumps.h"
#include "survey/csv.h"

namespace zebrageo {
namespace {

using adjustment_internal::AdjustmentSolver;
using adjustment_internal::Context;
using adjustment_internal::CrossingDiscrepancy;
using adjustment_internal::CrossingTable;
using adjustment_internal::OutputContext;
using adjustment_internal::State;

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// "" when the options (and the error model's fit options derived from
// them) are valid and every required input is set, else why not.
std::string CheckOptionsAndInput(const AdjustmentOptions& options,
                                 const AdjustmentInput& input) {
  const std::string error = options.Check();
  if (!error.empty()) return "invalid AdjustmentOptions: " + error;
  const std::string fit_error =
      adjustment_internal::PositionFitOptions(options).Check();
  if (!fit_error.empty()) {
    return "invalid AdjustmentOptions (position model): " + fit_error;
  }
  if (input.rig == nullptr || input.frame == nullptr ||
      input.trajectory == nullptr || input.exposures == nullptr ||
      input.roadmarks == nullptr || input.vertices == nullptr ||
      input.matches == nullptr) {
    return "AdjustmentInput: a required input is missing";
  }
  return "";
}

// The state before any selection: the exposures, the control points, the
// correction and its priors, the tie and line points. Returns the matched
// crossings.
CrossingTable BuildState(const Context& context, State* state) {
  for (const Exposure& e : context.input.exposures->exposures) {
    state->exposure_times.push_back(e.time);
  }
  std::vector<double>& times = state->exposure_times;
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  state->exposure_offsets.assign(times.size(), Eigen::Vector3d::Zero());
  CrossingTable crossings =
      adjustment_internal::AddControlPoints(context, state);
  adjustment_internal::InitialiseCorrection(context, state);
  for (double time : times) {
    Pose pose;
    state->exposure_frames.push_back(context.InsPoseAt(time, &pose)
                                         ? state->correction.Frame(pose)
                                         : Eigen::Matrix3d::Identity());
  }
  adjustment_internal::AddTieAndLinePoints(context, state);
  return crossings;
}

// Control selection: inconsistent crossings rejected, check crossings held
// out; then the error model the solves start from.
void SelectControl(const Context& context, const CrossingTable& crossings,
                   State* state) {
  const std::vector<CrossingDiscrepancy> discrepancies =
      adjustment_internal::CrossingDiscrepancies(context.options, *state,
                                                 crossings.period_enu);
  adjustment_internal::RejectInconsistentCrossings(context, crossings,
                                                   discrepancies, state);
  adjustment_internal::MarkCheckCrossings(context, crossings, state);
  state->model =
      adjustment_internal::InitialErrorModel(context, discrepancies, *state);
  state->along_track_held =
      adjustment_internal::AlongTrackHeld(context.options, *state);
}

}  // namespace

AdjustmentResult AdjustTrajectory(const AdjustmentOptions& options,
                                  const AdjustmentInput& input,
                                  const std::function<void(int, int)>& progress,
                                  const CancellationToken& cancel) {
  const auto start = std::chrono::steady_clock::now();
  AdjustmentResult result;
  AdjustmentSummary& summary = result.summary;
  summary.message = CheckOptionsAndInput(options, input);
  if (!summary.message.empty()) return result;
  summary.num_exposures = static_cast<int>(input.exposures->exposures.size());
  // The INS trajectory the correction applies to: without its jumps.
  Context context{
      options, input,
      RemoveJumps(*input.trajectory, options.trajectory_faults.jump_threshold_m,
                  options.trajectory_faults.jump_threshold_rad,
                  options.trajectory_faults.sideways_switches),
      &summary, cancel};
  summary.num_jumps = context.dejumped.num_jumps;
  for (const SidewaysSwitch& s : context.dejumped.switches) {
    const std::vector<TrajectorySample>& samples = input.trajectory->samples();
    context.Warn(
        "the GNSS/INS positions move " + FormatFixed(std::abs(s.size_m), 2) +
        " m " + (s.size_m > 0.0 ? "right" : "left") +
        " of the heading from time " + FormatFixed(samples[s.first].time, 2) +
        " to " + FormatFixed(samples[s.last].time, 2) +
        ": a switch of the GNSS error (multipath?), corrected as "
        "continuous INS motion");
  }
  if (summary.num_jumps > 0) {
    context.Warn(
        std::to_string(summary.num_jumps) +
        " jumps in the GNSS/INS trajectory (GNSS returning after an "
        "outage?): corrected as continuous INS motion" +
        (context.dejumped.num_closed_outages > 0
             ? "; " + std::to_string(context.dejumped.num_closed_outages) +
                   " close an outage (the stated sd grew into "
                   "them) and are spread back over it"
             : std::string()));
  }

  State state;
  const CrossingTable crossings = BuildState(context, &state);
  // What each jump means (an outage's drift, the GNSS's error, or both):
  // the reading that keeps the most control.
  for (const std::string& sentence :
       adjustment_internal::ChooseOutageModel(&context, crossings, &state)) {
    context.Warn(sentence);
  }
  SelectControl(context, crossings, &state);
  const adjustment_internal::StateRms before =
      adjustment_internal::MeasureState(*input.rig, state);
  const Eigen::Vector2d crab_before_deg =
      adjustment_internal::CrabRmsDeg(state);

  AdjustmentSolver solver(context, &state, progress);
  std::string why_not;
  const bool adjusted =
      adjustment_internal::RunAdjustments(context, &state, &solver, &why_not);
  if (!adjusted) {
    context.Warn(why_not +
                 ": the trajectory is not corrected, poses come from the "
                 "input trajectory");
    adjustment_internal::ResetState(&state);
  }
  adjustment_internal::EvaluateControlPoints(options, *input.rig, &state);
  const adjustment_internal::StateRms after =
      adjustment_internal::MeasureState(*input.rig, state);
  // Never worse than the input by the survey's own control: where the
  // adjusted trajectory fits the matched crossings worse, the input stays.
  GuardResult guard;
  if (adjusted) guard = adjustment_internal::GuardAdjustment(context, state);
  summary.guard_verdicts = guard.verdicts;
  summary.kept_input = guard.kept;

  OutputContext output;
  output.options = &options;
  output.input = &input;
  output.dejumped = &context.dejumped;
  output.adjusted = adjusted;
  output.warn = [&context](const std::string& w) { context.Warn(w); };
  output.guard = guard.Fired() ? &guard : nullptr;
  if (adjusted) {
    output.sample_covariance = adjustment_internal::SampleCovariance(
        context, &state, solver.problem());
  }
  if (!adjustment_internal::FillOutputs(output, &state, &result)) {
    return result;
  }
  adjustment_internal::SummariseFinalState(output, state, before, after,
                                           crab_before_deg, &summary);
  summary.corrected = adjusted && !guard.KeepsInputEverywhere();
  summary.line_control_only = adjusted && summary.num_control_crossings == 0 &&
                              summary.num_check_crossings == 0 &&
                              !state.lines.empty();
  if (summary.line_control_only) {
    context.Warn(
        state.along_track_held
            ? "no zebra crossing is control: road lines alone correct the "
              "trajectory across them and in height; the along-track "
              "position is the input's"
            : "no zebra crossing is control: road lines correct the "
              "trajectory across them and in height, the edges of crossings "
              "seen in part along the track");
  }
  summary.time_in_seconds = Seconds(start);
  summary.usable = true;
  summary.message = adjusted ? "adjusted" : "not adjusted: " + why_not;
  LOG(INFO) << "adjustment: " << summary.BriefReport();
  return result;
}

}  // namespace zebrageo
