#include "adjustment/control_selection.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "adjustment/line_discrepancies.h"
#include "survey/csv.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// Above this many crossings the leave-one-out test keeps the error model
// fitted on all of them (a refit per crossing would cost n^4).
constexpr int kMaxCrossingsForRefit = 40;

// -log of the upper tail probability of a chi-square of `dof` (1 to 3)
// degrees of freedom at `x`: crossings tested on different numbers of axes
// (a lone crossing against the road lines, on the axes they measure) are
// compared, and judged, at one significance.
double ChiSquareSurprise(double x, int dof) {
  x = std::max(x, 0.0);
  if (x > 600.0) {
    // Q(x; k) ~ (x/2)^(k/2-1) exp(-x/2) / Gamma(k/2) where exp underflows.
    const double half = 0.5 * dof;
    return 0.5 * x - (half - 1.0) * std::log(0.5 * x) + std::lgamma(half);
  }
  const double z = std::sqrt(0.5 * x);
  double tail = 0.0;
  if (dof == 1) {
    tail = std::erfc(z);
  } else if (dof == 2) {
    tail = std::exp(-0.5 * x);
  } else {
    tail = std::erfc(z) + std::sqrt(2.0 * x / kPi) * std::exp(-0.5 * x);
  }
  return -std::log(std::max(tail, 1e-300));
}

// The chi-square of `dof` degrees of freedom as surprising as `surprise`.
double ChiSquareAt(double surprise, int dof) {
  double low = 0.0;
  double high = 2000.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (low + high);
    (ChiSquareSurprise(mid, dof) < surprise ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

ProcessSamples AxisSamples(const std::vector<CrossingDiscrepancy>& crossings,
                           const std::vector<bool>& use, int axis) {
  ProcessSamples samples;
  for (size_t c = 0; c < crossings.size(); ++c) {
    if (!use[c]) continue;
    samples.Add(crossings[c].time_s, crossings[c].value_m[axis],
                crossings[c].variance_m2[axis]);
  }
  return samples;
}

bool Measures(const CrossingDiscrepancy& witness, int axis) {
  return witness.valid && witness.variance_m2[axis] < kUnmeasuredVarianceM2;
}

// The crossings in `use`, then the witnesses that measure `axis`.
ProcessSamples AxisSamples(const std::vector<CrossingDiscrepancy>& crossings,
                           const std::vector<bool>& use,
                           const std::vector<CrossingDiscrepancy>& witnesses,
                           int axis) {
  ProcessSamples samples = AxisSamples(crossings, use, axis);
  for (const CrossingDiscrepancy& w : witnesses) {
    if (Measures(w, axis)) {
      samples.Add(w.time_s, w.value_m[axis], w.variance_m2[axis]);
    }
  }
  return samples;
}

std::vector<GaussMarkovFit> FitAxesWith(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<bool>& use,
    const std::vector<CrossingDiscrepancy>& witnesses,
    const GaussMarkovFitOptions& fit_options) {
  std::vector<GaussMarkovFit> fits;
  for (int axis = 0; axis < 3; ++axis) {
    fits.push_back(FitGaussMarkov(AxisSamples(crossings, use, witnesses, axis),
                                  fit_options));
  }
  return fits;
}

// Whether the crossings in `others` and the witnesses measure `axis` both
// before and after `time_s`: then a change of the error on the way to it
// would show between them.
bool Bracketed(const std::vector<CrossingDiscrepancy>& crossings,
               const std::vector<bool>& others,
               const std::vector<CrossingDiscrepancy>& witnesses, int axis,
               double time_s) {
  const ProcessSamples samples =
      AxisSamples(crossings, others, witnesses, axis);
  bool before = false;
  bool after = false;
  for (double t : samples.time_s) {
    before = before || t < time_s;
    after = after || t > time_s;
  }
  return before && after;
}

// Chi-square of crossing `c`'s value, moved by `shift`, against what the
// other crossings in `use` and the witnesses predict with `fits`, over the
// axes something else measures (their number in `dof`: 3 unless `c` is
// alone with witnesses).
double LeaveOneOutChiSquare(const std::vector<CrossingDiscrepancy>& crossings,
                            const std::vector<bool>& use,
                            const std::vector<CrossingDiscrepancy>& witnesses,
                            int c, const std::vector<GaussMarkovFit>& fits,
                            const Eigen::Vector3d& shift, int* dof) {
  *dof = 0;
  std::vector<bool> with = use;
  with[c] = true;
  // Position of c among the samples of `with` (the witnesses come after).
  int position = 0;
  for (int k = 0; k < c; ++k) position += with[k] ? 1 : 0;
  double chi_square = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    ProcessSamples samples = AxisSamples(crossings, with, witnesses, axis);
    // Nothing else measures this axis (a lone crossing tested against the
    // road lines, which measure across the track only): no test on it.
    if (samples.size() < 2) continue;
    ++*dof;
    samples.value[position] += shift[axis];
    const ProcessPrediction p =
        PredictLeaveOneOut(samples, position, fits[axis]);
    chi_square += p.standardized * p.standardized;
    VLOG(3) << "  axis " << axis << ": " << samples.value[position]
            << " m, predicted " << p.mean << " m, sd " << std::sqrt(p.variance)
            << " m (sigma " << fits[axis].sigma << " m, tau "
            << fits[axis].tau_s << " s)";
  }
  return chi_square;
}

// The other control that votes in the crossings' tests: whole dashes
// (along-track), and the road lines per time bin, across the track only.
std::vector<CrossingDiscrepancy> Witnesses(const AdjustmentOptions& options,
                                           const State& state) {
  std::vector<CrossingDiscrepancy> witnesses = DashDiscrepancies(state);
  for (CrossingDiscrepancy d :
       LineDiscrepancies(state, options.road_lines.line_discrepancy_bin_s,
                         options.road_lines.line_discrepancy_min_points)) {
    d.variance_m2[2] = kUnmeasuredVarianceM2;
    if (d.variance_m2[1] < kUnmeasuredVarianceM2) witnesses.push_back(d);
  }
  return witnesses;
}

}  // namespace

std::vector<CrossingDiscrepancy> CrossingDiscrepancies(
    const AdjustmentOptions& options, const State& state,
    const std::vector<Eigen::Vector3d>& period_enu) {
  const int n = static_cast<int>(period_enu.size());
  std::vector<std::vector<Eigen::Vector3d>> values(n);
  std::vector<Eigen::Vector3d> variance_sum(n, Eigen::Vector3d::Zero());
  std::vector<double> time_sum(n, 0.0);
  std::vector<Eigen::Matrix3d> R_track_enu(n, Eigen::Matrix3d::Identity());
  std::vector<int> observations(n, 0);
  for (const ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kRejected || p.observations.empty()) {
      continue;
    }
    Eigen::Vector3d X;
    Eigen::Matrix3d covariance;
    if (!StereoPosition(options, state, p.stereo, &X, &covariance)) continue;
    const int c = p.crossing;
    const Pose& ins = p.observations.front().ins_pose;
    R_track_enu[c] = state.correction.Frame(ins).transpose();
    values[c].push_back(R_track_enu[c] * (p.database_enu - X));
    VLOG(2) << "discrepancy " << p.crossing_id << " band " << p.band
            << " vertex " << p.db_vertex << ": " << values[c].back().transpose()
            << " from " << p.stereo.size() << " exposures";
    const Eigen::Matrix3d database =
        p.sigma_m.cwiseAbs2().asDiagonal().toDenseMatrix() + covariance;
    variance_sum[c] +=
        (R_track_enu[c] * database * R_track_enu[c].transpose()).diagonal();
    for (const StereoObservation& o : p.stereo) {
      time_sum[c] += o.time;
      ++observations[c];
    }
  }
  std::vector<CrossingDiscrepancy> out(n);
  const double offset2 = options.control.crossing_offset_sigma_m *
                         options.control.crossing_offset_sigma_m;
  for (int c = 0; c < n; ++c) {
    const int m = static_cast<int>(values[c].size());
    if (m == 0) continue;
    CrossingDiscrepancy& d = out[c];
    d.valid = true;
    d.vertices = m;
    d.time_s = time_sum[c] / observations[c];
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> v;
      for (const Eigen::Vector3d& x : values[c]) v.push_back(x[axis]);
      d.value_m[axis] = Median(v);
    }
    // The median of m values has pi/2 times the variance of their mean;
    // the crossing's offset is common to all of them.
    d.variance_m2 =
        Eigen::Vector3d::Constant(offset2) +
        (kPi / 2.0) * variance_sum[c] / (m * static_cast<double>(m));
    Eigen::Vector3d period = R_track_enu[c] * period_enu[c];
    period.z() = 0.0;
    d.period_m = period;
    // The jumps taken out of the trajectory before this time are part of
    // the correction (adjustment_state.h): the process is the rest.
    d.value_m -= state.PriorJumpAt(d.time_s);
  }
  return out;
}

std::vector<GaussMarkovFit> FitAxes(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<bool>& use, const GaussMarkovFitOptions& fit_options) {
  return FitAxesWith(crossings, use, {}, fit_options);
}

std::vector<GaussMarkovFit> FitAxes(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<bool>& use,
    const std::vector<CrossingDiscrepancy>& witnesses,
    const GaussMarkovFitOptions& fit_options) {
  return FitAxesWith(crossings, use, witnesses, fit_options);
}

std::vector<CrossingDiscrepancy> ControlWitnesses(
    const AdjustmentOptions& options, const State& state) {
  return Witnesses(options, state);
}

std::vector<CrossingVerdict> SelectConsistentCrossings(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<std::string>& names,
    const GaussMarkovFitOptions& fit_options, double chi_square_threshold,
    double two_crossings_sigma_m,
    const std::vector<CrossingDiscrepancy>& witnesses) {
  const int n = static_cast<int>(crossings.size());
  std::vector<CrossingVerdict> verdicts(n);
  std::vector<bool> active(n);
  for (int c = 0; c < n; ++c) active[c] = crossings[c].valid;
  // A lone crossing is judged by the road lines across the track only:
  // each of their time bins pools the points of lines checked against each
  // other (RejectInconsistentLines), where a whole dash is one mark matched
  // alone (geometry sweep seed 105: dashes 0.35 m from a right crossing
  // along the track, 3.8 sd, rejected it and H went 6.3 -> 101.3 cm). With
  // other crossings the dashes vote beside them.
  std::vector<CrossingDiscrepancy> across_track;
  for (const CrossingDiscrepancy& w : witnesses) {
    if (Measures(w, 1)) across_track.push_back(w);
  }
  while (std::count(active.begin(), active.end(), true) >=
         (across_track.empty() ? 2 : 1)) {
    const int count =
        static_cast<int>(std::count(active.begin(), active.end(), true));
    const std::vector<CrossingDiscrepancy>& voting =
        count > 1 ? witnesses : across_track;
    const std::vector<GaussMarkovFit> all =
        FitAxesWith(crossings, active, voting, fit_options);
    int worst = -1;
    double worst_chi = 0.0;
    int worst_dof = 3;
    double worst_surprise = 0.0;
    std::vector<GaussMarkovFit> worst_fits;
    for (int c = 0; c < n; ++c) {
      if (!active[c]) continue;
      // The model is refitted without the crossing tested, so that a
      // wrong crossing cannot widen it enough to pass.
      std::vector<bool> others = active;
      others[c] = false;
      std::vector<GaussMarkovFit> fits =
          count <= kMaxCrossingsForRefit
              ? FitAxesWith(crossings, others, voting, fit_options)
              : all;
      // Fitted on crossings all on one side of the one tested (the other
      // of two, or a cluster at the far end of the survey), the sigma says
      // nothing of how the error changes on the way to it: at least
      // two_crossings_sigma_m on a horizontal axis, unless other crossings
      // or witnesses (whole dashes, lines) measure it on both sides, so that a
      // change on the way would show between them.
      for (int axis : {0, 1}) {
        if (Bracketed(crossings, others, voting, axis, crossings[c].time_s)) {
          continue;
        }
        fits[axis].sigma = std::max(fits[axis].sigma, two_crossings_sigma_m);
      }
      int dof = 0;
      const double chi = LeaveOneOutChiSquare(
          crossings, others, voting, c, fits, Eigen::Vector3d::Zero(), &dof);
      VLOG(1) << "crossing " << names[c] << ": leave-one-out chi-square " << chi
              << " on " << dof << " axes (" << crossings[c].value_m.transpose()
              << " m)";
      if (dof == 0) continue;
      const double surprise = ChiSquareSurprise(chi, dof);
      if (surprise > worst_surprise) {
        worst_surprise = surprise;
        worst_chi = chi;
        worst_dof = dof;
        worst = c;
        worst_fits = fits;
      }
    }
    // The threshold is the 3-axis test's; on fewer axes, the chi-square of
    // the same significance.
    const double threshold_surprise =
        ChiSquareSurprise(chi_square_threshold, 3);
    if (worst < 0 || worst_surprise <= threshold_surprise) break;
    const double threshold = worst_dof == 3
                                 ? chi_square_threshold
                                 : ChiSquareAt(threshold_surprise, worst_dof);
    std::vector<bool> others = active;
    others[worst] = false;
    CrossingVerdict& verdict = verdicts[worst];
    verdict.consistent = false;
    verdict.chi_square = worst_chi;
    const Eigen::Vector3d& period = crossings[worst].period_m;
    if (period.norm() > 0.0) {
      for (double sign : {-1.0, 1.0}) {
        int dof = 0;
        const double shifted = LeaveOneOutChiSquare(
            crossings, others, voting, worst, worst_fits, sign * period, &dof);
        if (shifted <= threshold) verdict.one_period_off = true;
      }
    }
    const Eigen::Vector3d& d = crossings[worst].value_m;
    verdict.reason =
        "crossing " + names[worst] +
        " implies a trajectory correction (along-track " +
        FormatFixed(d.x(), 2) + " m, cross-track " + FormatFixed(d.y(), 2) +
        " m, up " + FormatFixed(d.z(), 2) + " m) that " +
        (count > 1 ? "the other crossings, " : "") +
        (voting.empty() ? std::string()
         : count > 1    ? "the road lines (across the track; whole "
                          "lane-line dashes along it), "
                        : "the road lines across the track, ") +
        "and the GNSS/INS error model do not explain (chi-square " +
        FormatFixed(worst_chi, 1) + " > " + FormatFixed(threshold, 1) +
        (worst_dof == 3   ? std::string()
         : worst_dof == 1 ? " on the one axis they measure"
                          : " on the two axes they measure") +
        ")";
    if (verdict.one_period_off) {
      verdict.reason += "; shifted by one band period (" +
                        FormatFixed(period.norm(), 2) +
                        " m) it would fit: matched one band off";
    } else {
      verdict.reason += ": repainted, or wrongly matched";
    }
    active[worst] = false;
  }
  return verdicts;
}

GaussMarkovFitOptions PositionFitOptions(const AdjustmentOptions& options) {
  GaussMarkovFitOptions fit;
  fit.min_sigma = options.model.min_position_sigma_m;
  fit.max_sigma = options.model.max_position_sigma_m;
  fit.default_tau_s = options.model.position_tau_s;
  fit.min_samples_for_tau = options.model.min_crossings_for_tau;
  return fit;
}

void RejectInconsistentCrossings(const Context& context,
                                 const CrossingTable& crossings,
                                 const std::vector<CrossingDiscrepancy>& d,
                                 State* state) {
  const std::vector<CrossingVerdict> verdicts =
      adjustment_internal::SelectConsistentCrossings(
          d, crossings.names, PositionFitOptions(context.options),
          context.options.selection.crossing_consistency_chi_square,
          context.options.selection.two_crossings_position_sigma_m,
          Witnesses(context.options, *state));
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
  if (options.control.check_crossing_share <= 0.0 || order.empty()) return;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return crossings.first_time[a] < crossings.first_time[b];
  });
  const int k = std::max(2, static_cast<int>(std::lround(
                                1.0 / options.control.check_crossing_share)));
  std::vector<int> checks;
  for (size_t i = k / 2; i < order.size(); i += k) checks.push_back(order[i]);
  if (static_cast<int>(order.size() - checks.size()) <
      options.control.min_control_crossings) {
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

}  // namespace adjustment_internal
}  // namespace zebrageo
