#include "adjustment/outage_model.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "adjustment/adjustment_setup.h"
#include "adjustment/control_selection.h"
#include "adjustment/line_discrepancies.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

std::string Fixed(double value, int decimals) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

// How much control a reading keeps, and how likely the kept control is
// under it.
struct Score {
  int vertices = 0;
  int crossings = 0;
  double log_likelihood = 0.0;
};

// The witnesses (whole dashes, road lines) pooled per `bin_s` seconds: on
// each axis they measure, the median of their values with their median
// variance (not shrunk: neighbouring ones share their errors). A reading
// is judged by the shape of the error they show over seconds, and the
// Gauss-Markov fits cost the cube of their number.
std::vector<CrossingDiscrepancy> PooledWitnesses(
    const std::vector<CrossingDiscrepancy>& witnesses, double bin_s) {
  std::map<long, std::vector<const CrossingDiscrepancy*>> bins;
  for (const CrossingDiscrepancy& w : witnesses) {
    if (w.valid) bins[std::lround(std::floor(w.time_s / bin_s))].push_back(&w);
  }
  std::vector<CrossingDiscrepancy> pooled;
  for (const auto& [bin, members] : bins) {
    CrossingDiscrepancy p;
    p.valid = true;
    p.variance_m2 = Eigen::Vector3d::Constant(kUnmeasuredVarianceM2);
    std::vector<double> times;
    bool any = false;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> values, variances;
      for (const CrossingDiscrepancy* w : members) {
        if (w->variance_m2[axis] >= kUnmeasuredVarianceM2) continue;
        values.push_back(w->value_m[axis]);
        variances.push_back(w->variance_m2[axis]);
        times.push_back(w->time_s);
      }
      if (values.empty()) continue;
      p.value_m[axis] = Median(values);
      p.variance_m2[axis] = Median(variances);
      any = true;
    }
    if (!any) continue;
    p.time_s = Median(times);
    pooled.push_back(p);
  }
  return pooled;
}

Score ScoreOf(const Context& context, const CrossingTable& crossings,
              const State& state) {
  const AdjustmentOptions& options = context.options;
  const std::vector<CrossingDiscrepancy> d =
      CrossingDiscrepancies(options, state, crossings.period_enu);
  constexpr double kWitnessBinS = 6.0;
  const std::vector<CrossingDiscrepancy> witnesses =
      PooledWitnesses(ControlWitnesses(options, state), kWitnessBinS);
  const std::vector<CrossingVerdict> verdicts = SelectConsistentCrossings(
      d, crossings.names, PositionFitOptions(options),
      options.selection.crossing_consistency_chi_square,
      options.selection.two_crossings_position_sigma_m, witnesses);
  Score score;
  std::vector<bool> kept(d.size(), false);
  for (size_t c = 0; c < d.size(); ++c) {
    kept[c] = d[c].valid && verdicts[c].consistent;
    if (!kept[c]) continue;
    score.vertices += d[c].vertices;
    ++score.crossings;
  }
  for (const GaussMarkovFit& fit :
       FitAxes(d, kept, witnesses, PositionFitOptions(options))) {
    score.log_likelihood += fit.log_likelihood;
  }
  return score;
}

// Time of sample i.
double TimeOf(const Trajectory& trajectory, int i) {
  return trajectory.samples()[i].time;
}

// The prior's centre at `time` (ENU), linear between samples.
Eigen::Vector3d PriorOffsetAt(const Trajectory& trajectory,
                              const DejumpedTrajectory& dejumped, double time) {
  const int i = trajectory.FindSegment(time);
  if (i < 0) return Eigen::Vector3d::Zero();
  const double t0 = TimeOf(trajectory, i);
  const double t1 = TimeOf(trajectory, i + 1);
  const double u =
      t1 > t0 ? std::clamp((time - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
  return (1.0 - u) * dejumped.prior_position_offset[i] +
         u * dejumped.prior_position_offset[i + 1];
}

// The vehicle's motion as a witness of a reading (vehicle_motion.h): the
// INS drifting through an outage from a velocity error moves across its
// own heading, by the error's rate over the speed; the prior's centre of
// the right reading takes that motion out, and leaves the crab of the
// trajectory moved to it as steady as the vehicle's yaw misalignment and
// the GNSS's slow drift make it. The Gaussian log-likelihood (each
// constraint's lateral sigma) of those crab angles about their median, over
// the constraints within [begin_s, end_s] whose chord does not span the
// jump.
double CrabLogLikelihood(const Trajectory& trajectory,
                         const DejumpedTrajectory& dejumped, const State& state,
                         double begin_s, double end_s, double jump_begin_s,
                         double jump_end_s) {
  std::vector<double> crab, sigma;
  for (const VehicleMotionSample& m : state.motion) {
    if (m.times[1] < begin_s || m.times[1] > end_s) continue;
    if (m.times[0] <= jump_end_s && m.times[2] >= jump_begin_s) continue;
    const double length = (m.ins[2].p_enu - m.ins[0].p_enu).head<2>().norm();
    if (!(length > 0.0) || !(m.sigma_lateral_rad > 0.0)) continue;
    const Eigen::Vector3d p0 =
        m.ins[0].p_enu + PriorOffsetAt(trajectory, dejumped, m.times[0]);
    const Eigen::Vector3d p2 =
        m.ins[2].p_enu + PriorOffsetAt(trajectory, dejumped, m.times[2]);
    crab.push_back((m.ins[1].q_enu_body.inverse() * (p2 - p0)).y() / length);
    sigma.push_back(m.sigma_lateral_rad);
  }
  if (crab.empty()) return 0.0;
  const double centre = Median(crab);
  double log_likelihood = 0.0;
  for (size_t k = 0; k < crab.size(); ++k) {
    const double z = (crab[k] - centre) / sigma[k];
    log_likelihood -= 0.5 * z * z;
  }
  // The sigmas count the body's sway as independent over a second; the
  // GNSS's drift and a jittery solution's wander stay correlated over
  // several: the constraints within kCrabCorrelationS count as one.
  constexpr double kCrabCorrelationS = 5.0;
  return log_likelihood / kCrabCorrelationS;
}

}  // namespace

namespace {

OutageHypothesis OutageReading(double length, double power, double share,
                               double decay_s) {
  OutageHypothesis h;
  h.ins_share = share;
  h.outage_length_s = length;
  h.growth_power = power;
  h.gnss_decay_s = share < 1.0 ? decay_s : 0.0;
  h.name = std::string(share < 1.0 ? "half of it " : "") +
           "the INS's drift through an outage of the " + Fixed(length, 0) +
           " s before it, growing " + (power > 1.0 ? "as t^2" : "with t") +
           (share < 1.0 ? ", half the GNSS's error when it returned, "
                          "decaying over " +
                              Fixed(h.gnss_decay_s, 0) + " s"
                        : " (the GNSS after it right)");
  return h;
}

}  // namespace

std::vector<OutageHypothesis> OutageHypotheses(const NeverWorseOptions& options,
                                               double jump_time_s,
                                               double floor_time_s) {
  std::vector<OutageHypothesis> out;
  OutageHypothesis found;
  found.name = "as found";
  found.as_found = true;
  out.push_back(found);
  const double longest = jump_time_s - floor_time_s;
  // Outage lengths from the shortest up, as long as the trajectory before
  // the jump allows (the last one clipped to it).
  for (double length : {10.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 180.0}) {
    if (length < options.outage_min_length_s ||
        length > options.outage_max_length_s) {
      continue;
    }
    if (length >= longest) {
      if (longest >= options.outage_min_length_s) {
        out.push_back(OutageReading(longest, 2.0, 1.0, 0.0));
      }
      break;
    }
    out.push_back(OutageReading(length, 2.0, 1.0, 0.0));
  }
  for (double decay : {0.3, 1.0, 3.0}) {
    OutageHypothesis h;
    h.gnss_decay_s = decay * options.gnss_return_decay_s;
    h.name = "the GNSS's error when it returned, decaying over " +
             Fixed(h.gnss_decay_s, 0) + " s (the INS before it right)";
    out.push_back(h);
  }
  return out;
}

std::vector<OutageHypothesis> RefinedOutageHypotheses(
    const NeverWorseOptions& options, const OutageHypothesis& outage) {
  const double length = outage.outage_length_s;
  const double decay = options.gnss_return_decay_s;
  return {OutageReading(length, 1.0, 1.0, 0.0),
          OutageReading(length, 2.0, 0.5, decay),
          OutageReading(length, 1.0, 0.5, decay)};
}

void ApplyOutageHypothesis(const Trajectory& trajectory, const JumpEvent& jump,
                           int floor, const OutageHypothesis& h,
                           DejumpedTrajectory* dejumped) {
  if (h.as_found) return;
  DejumpedTrajectory& d = *dejumped;
  const int n = static_cast<int>(d.position_offset.size());
  const Eigen::Vector3d J =
      d.position_offset[jump.last] - d.position_offset[jump.first - 1];
  // The next jump's closure begins after this one's last sample: this
  // reading changes nothing from there on (`ceiling`).
  int ceiling = n;
  for (int i = jump.last + 1; i < n; ++i) {
    if (d.position_offset[i] != d.position_offset[i - 1] &&
        (d.switch_step.empty() || !d.switch_step[i])) {
      ceiling = i;
      break;
    }
  }
  // Back to the step, this jump's closure undone.
  for (int i = floor; i < ceiling; ++i) {
    d.prior_position_offset[i] = d.position_offset[i];
    if (i > floor) d.innovation_variance_m2[i] = 0.0;
  }
  const double t_jump = TimeOf(trajectory, jump.first);
  const double J2 = J.squaredNorm();
  if (h.ins_share > 0.0 && h.outage_length_s > 0.0) {
    const double t_begin =
        std::max(t_jump - h.outage_length_s, TimeOf(trajectory, floor));
    const double length = t_jump - t_begin;
    double previous = 0.0;
    for (int i = floor; i < jump.first; ++i) {
      const double t = TimeOf(trajectory, i);
      if (t < t_begin || !(length > 0.0)) continue;
      const double share = std::pow((t - t_begin) / length, h.growth_power);
      d.prior_position_offset[i] += h.ins_share * share * J;
      // The drift's exact shape is not known: a quarter of its square
      // spread as it grows (as SpreadOutageClosures does).
      d.innovation_variance_m2[i] =
          0.25 * h.ins_share * h.ins_share * (share - previous) * J2;
      previous = share;
    }
  }
  const double gnss_share = 1.0 - h.ins_share;
  if (gnss_share > 0.0 && h.gnss_decay_s > 0.0) {
    double previous = 1.0;
    for (int i = jump.first; i < ceiling; ++i) {
      const double decay =
          std::exp(-(TimeOf(trajectory, i) - t_jump) / h.gnss_decay_s);
      d.prior_position_offset[i] -= gnss_share * decay * J;
      d.innovation_variance_m2[i] +=
          0.25 * gnss_share * gnss_share * (previous - decay) * J2;
      previous = decay;
    }
  }
  if (h.ins_share >= 1.0 || gnss_share >= 1.0) return;
  // Shared between the two, the jump itself may still be a step of either.
  d.innovation_variance_m2[jump.first] += 0.25 * J2;
}

std::vector<std::string> ChooseOutageModel(Context* context,
                                           const CrossingTable& crossings,
                                           State* state) {
  std::vector<std::string> sentences;
  const NeverWorseOptions& options = context->options.never_worse;
  if (!(options.outage_min_jump_m > 0.0) || crossings.names.empty()) {
    return sentences;
  }
  const Trajectory& trajectory = *context->input.trajectory;
  const std::vector<JumpEvent> jumps = JumpEvents(context->dejumped);
  // A likelihood ratio of e^3 (about 20) between readings that keep as
  // much control is needed to leave the one found.
  constexpr double kLeaveFoundLogLikelihood = 3.0;
  int floor = 0;
  bool changed_any = false;
  for (const JumpEvent& jump : jumps) {
    const DejumpedTrajectory& d = context->dejumped;
    const Eigen::Vector3d J =
        d.position_offset[jump.last] - d.position_offset[jump.first - 1];
    if (J.norm() < options.outage_min_jump_m) {
      floor = jump.last;
      continue;
    }
    const double t_jump = TimeOf(trajectory, jump.first);
    // Where the readings' outage parts differ: from the previous jump on.
    const double window_begin = TimeOf(trajectory, floor);
    const double jump_begin = TimeOf(trajectory, jump.first - 1);
    const double jump_end = TimeOf(trajectory, jump.last);
    // The readings, coarse first (the outage's length, the GNSS part's
    // decay), then the outage's growth and a half share at the best
    // length.
    std::vector<OutageHypothesis> hypotheses =
        OutageHypotheses(options, t_jump, TimeOf(trajectory, floor));
    const size_t coarse = hypotheses.size();
    Score found;
    Score best;
    int best_index = 0;
    int best_outage = -1;
    Score best_outage_score;
    DejumpedTrajectory best_dejumped = d;
    for (size_t k = 0; k < hypotheses.size(); ++k) {
      DejumpedTrajectory trial = d;
      ApplyOutageHypothesis(trajectory, jump, floor, hypotheses[k], &trial);
      SetKnotPriors(*context, trial, state);
      Score score = ScoreOf(*context, crossings, *state);
      // The crab before the jump only: after it a reading's GNSS part
      // decays over tens of seconds, as the GNSS's own slow drift does,
      // which the crab cannot tell apart; an outage's drift is fast.
      score.log_likelihood +=
          CrabLogLikelihood(trajectory, trial, *state, window_begin, jump_begin,
                            jump_begin, jump_end);
      VLOG(1) << "outage model, jump of " << J.norm() << " m at "
              << t_jump - trajectory.start_time()
              << " s: " << hypotheses[k].name << ": keeps " << score.crossings
              << " crossings (" << score.vertices << " vertices), log L "
              << score.log_likelihood;
      if (k == 0) {
        found = best = score;
      } else {
        const double margin = best_index == 0 ? kLeaveFoundLogLikelihood : 0.0;
        if (score.vertices > best.vertices ||
            (score.vertices == best.vertices &&
             score.log_likelihood > best.log_likelihood + margin)) {
          best = score;
          best_index = static_cast<int>(k);
          best_dejumped = std::move(trial);
        }
      }
      if (k < coarse && hypotheses[k].outage_length_s > 0.0 &&
          (best_outage < 0 || score.vertices > best_outage_score.vertices ||
           (score.vertices == best_outage_score.vertices &&
            score.log_likelihood > best_outage_score.log_likelihood))) {
        best_outage = static_cast<int>(k);
        best_outage_score = score;
      }
      if (k + 1 == coarse && best_outage >= 0) {
        for (const OutageHypothesis& h :
             RefinedOutageHypotheses(options, hypotheses[best_outage])) {
          hypotheses.push_back(h);
        }
      }
    }
    if (best_index > 0) {
      context->dejumped = std::move(best_dejumped);
      changed_any = true;
      sentences.push_back(
          "the jump of " + Fixed(J.norm(), 2) +
          " m in the GNSS/INS positions at " +
          Fixed(t_jump - trajectory.start_time(), 1) +
          " s (GNSS returning after an outage?) is read as " +
          hypotheses[best_index].name + ": so read, " +
          std::to_string(best.crossings) + " matched crossings agree (" +
          std::to_string(found.crossings) + " as a plain jump)");
    }
    floor = jump.last;
  }
  // The state's priors: those of the readings chosen.
  SetKnotPriors(*context, context->dejumped, state);
  if (changed_any) {
    VLOG(1) << "outage model: " << sentences.size() << " jumps read anew";
  }
  return sentences;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
