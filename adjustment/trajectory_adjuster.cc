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
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <set>
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

// Per sample and axis (along, cross, up): whether a control holds it within
// `radius_m` of trajectory. A zebra control vertex holds every axis of the
// samples within radius_m of it; a road-line point the axis its residual
// measures (across_enu: cross-track for a lane line, along-track for a line
// across the track or a dash's ends) and the height, at the samples within
// radius_m along the trajectory of where it was seen.
std::vector<std::array<bool, 3>> HeldAxes(const Context& context,
                                          const AdjustmentResult& result,
                                          const std::vector<double>& times,
                                          const std::vector<Eigen::Vector3d>& p,
                                          double radius_m) {
  const int n = static_cast<int>(times.size());
  std::vector<std::array<bool, 3>> held(n, {false, false, false});
  std::vector<Eigen::Vector2d> crossings;  // one control vertex each
  std::set<std::string> seen;
  for (const ControlPointResult& c : result.control_points) {
    if (c.status == ControlStatus::kControl &&
        seen.insert(c.crossing_id).second) {
      crossings.push_back(c.database_enu.head<2>());
    }
  }
  for (int i = 0; i < n; ++i) {
    for (const Eigen::Vector2d& c : crossings) {
      if ((p[i].head<2>() - c).norm() <= radius_m) {
        held[i] = {true, true, true};
        break;
      }
    }
  }
  if (context.input.line_points == nullptr || n == 0) return held;
  std::vector<double> distance(n, 0.0);
  for (int i = 1; i < n; ++i) {
    distance[i] = distance[i - 1] + (p[i] - p[i - 1]).norm();
  }
  // Per axis, the intervals of trajectory distance a line point holds.
  std::array<std::vector<std::pair<double, double>>, 3> spans;
  for (const LineControlPoint& point : *context.input.line_points) {
    const int i = static_cast<int>(
        std::lower_bound(times.begin(), times.end(), point.time) -
        times.begin());
    if (i <= 0 || i >= n) continue;
    Eigen::Vector3d ahead = p[i] - p[i - 1];
    ahead.z() = 0.0;
    if (ahead.norm() < 1e-6) continue;
    const bool along = std::abs(point.across_enu.dot(ahead.normalized())) > 0.7;
    const std::pair<double, double> span = {distance[i] - radius_m,
                                            distance[i] + radius_m};
    spans[along ? 0 : 1].push_back(span);
    spans[2].push_back(span);
  }
  for (int axis = 0; axis < 3; ++axis) {
    std::sort(spans[axis].begin(), spans[axis].end());
    size_t k = 0;
    double reach = -1e300;
    for (int i = 0; i < n; ++i) {
      while (k < spans[axis].size() && spans[axis][k].first <= distance[i]) {
        reach = std::max(reach, spans[axis][k].second);
        ++k;
      }
      if (distance[i] <= reach) held[i][axis] = true;
    }
  }
  return held;
}

// The stretches where an axis is weakly held (CovarianceOptions::weak_*),
// each also a warning: thresholds from the database's stated accuracy,
// positions of the corrected trajectory.
std::vector<WeakStretch> WeakStretchesOf(
    const Context& context, const AdjustmentResult& result,
    const std::vector<Eigen::Vector3d>& sd_track_m) {
  const CovarianceOptions& options = context.options.covariance;
  std::vector<double> sigma_xy, sigma_z;
  if (context.input.roadmarks != nullptr) {
    for (const RoadmarkBand& band : context.input.roadmarks->bands) {
      sigma_xy.push_back(band.sigma_xy_m);
      if (band.height_known) sigma_z.push_back(band.sigma_z_m);
    }
  }
  const double xy = options.weak_sd_database_factor * Median(sigma_xy);
  const double z = options.weak_sd_database_factor * Median(sigma_z);
  const Eigen::Vector3d threshold(std::max(options.weak_sd_floor_m, xy),
                                  std::max(options.weak_sd_floor_m, xy),
                                  std::max(options.weak_sd_floor_m, z));
  std::vector<double> times;
  std::vector<Eigen::Vector3d> positions;
  for (size_t i = 0; i < result.corrected_samples.size(); ++i) {
    times.push_back(result.corrected_samples[i].time);
    positions.push_back(result.corrected_poses[i].p_enu);
  }
  const std::vector<WeakStretch> stretches = adjustment_internal::WeakStretches(
      times, positions, sd_track_m,
      HeldAxes(context, result, times, positions,
               options.weak_control_radius_m),
      threshold, options.weak_min_length_m);
  for (const WeakStretch& s : stretches) {
    const char* axis = s.axis == TrackAxis::kAlongTrack   ? "along-track"
                       : s.axis == TrackAxis::kCrossTrack ? "cross-track"
                                                          : "height";
    std::ostringstream text;
    text << std::fixed << std::setprecision(0) << "the " << axis
         << " position is held by no control over " << s.length_m
         << " m of trajectory (t = " << s.begin_time_s << " to " << s.end_time_s
         << " s)";
    if (!s.held_by_no_control) {
      text << std::setprecision(2) << ": posterior sd above " << s.threshold_m
           << " m";
    } else if (s.axis == TrackAxis::kAlongTrack) {
      text << ": no zebra crossing within " << options.weak_control_radius_m
           << " m and no road line across the track";
    } else {
      text << ": no zebra crossing or road line within "
           << options.weak_control_radius_m << " m";
    }
    if (std::isfinite(s.max_sd_m)) {
      text << std::setprecision(2) << "; its posterior sd there up to "
           << s.max_sd_m << " m (median " << s.median_sd_m << " m)";
    }
    context.Warn(text.str());
  }
  return stretches;
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
  std::vector<Eigen::Vector3d> sd_track;
  if (adjusted) {
    output.sample_covariance = adjustment_internal::SampleCovariance(
        context, &state, solver.problem(), &sd_track);
  }
  if (!adjustment_internal::FillOutputs(output, &state, &result)) {
    return result;
  }
  if (adjusted) {
    summary.weak_stretches = WeakStretchesOf(context, result, sd_track);
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
