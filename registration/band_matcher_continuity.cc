// Step 4 of MatchBands (band_matcher_internal.h): continuity across
// crossings. The drift changes slowly, so crossings matched alone must
// imply consistent corrections: passes that disagree with their informative
// neighbours are refused, an observation ambiguous alone is resolved when
// the correction predicted from matched neighbours singles out one of its
// hypotheses, and a crossing whose correction departs from the one
// interpolated between agreeing neighbours is reported as shifted.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "registration/band_matcher_internal.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

std::vector<Pass> BuildPasses(const MatchState& state) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  std::map<int, std::vector<int>> by_crossing;
  for (int o : state.by_time) {
    if (state.accepted[o]) {
      by_crossing[state.hypotheses[o][state.chosen[o]].main_crossing].push_back(
          o);
    }
  }
  std::vector<Pass> passes;
  for (const auto& [crossing, list] : by_crossing) {
    for (int o : list) {
      const double t = input.observations[o].time_s;
      if (passes.empty() || passes.back().crossing != crossing ||
          t - passes.back().t1 > kPassGapFactor * options.window_s) {
        Pass pass;
        pass.crossing = crossing;
        pass.t0 = t;
        passes.push_back(pass);
      }
      passes.back().obs.push_back(o);
      passes.back().t1 = t;
    }
  }
  for (Pass& pass : passes) {
    std::vector<double> x;
    std::vector<double> y;
    for (int o : pass.obs) {
      x.push_back(
          state.hypotheses[o][state.chosen[o]].correction.shift_enu_m.x());
      y.push_back(
          state.hypotheses[o][state.chosen[o]].correction.shift_enu_m.y());
    }
    pass.shift = Eigen::Vector2d(Median(x), Median(y));
  }
  return passes;
}

double PassGap(const Pass& a, const Pass& b) {
  return std::max(0.0, std::max(a.t0, b.t0) - std::min(a.t1, b.t1));
}

// The nearest accepted observations before and after position k of
// by_time, within neighbour_window_s and in the same GNSS regime as it;
// -1 where there is none.
void NearestMatched(const MatchState& state, int k, int* before_out,
                    int* after_out) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  const int n = static_cast<int>(state.by_time.size());
  const int o = state.by_time[k];
  const double t = input.observations[o].time_s;
  // Nearest matched observation on each side.
  int before = -1;
  int after = -1;
  for (int m = k - 1; m >= 0; --m) {
    const int q = state.by_time[m];
    if (t - input.observations[q].time_s > options.neighbour_window_s) {
      break;
    }
    if (state.accepted[q]) {
      before = q;
      break;
    }
  }
  for (int m = k + 1; m < n; ++m) {
    const int q = state.by_time[m];
    if (input.observations[q].time_s - t > options.neighbour_window_s) {
      break;
    }
    if (state.accepted[q]) {
      after = q;
      break;
    }
  }
  // No propagation across a GNSS event: the claimed sd jumping up or
  // down means the error may jump too.
  auto same_regime = [&](int q) {
    if (q < 0) return false;
    const double a = std::max(input.observations[q].sd_horizontal_m, 1e-3);
    const double b = std::max(input.observations[o].sd_horizontal_m, 1e-3);
    return std::max(a, b) <= options.max_sd_ratio * std::min(a, b);
  };
  if (!same_regime(before)) before = -1;
  if (!same_regime(after)) after = -1;
  *before_out = before;
  *after_out = after;
}

// The correction of an observation predicted from matched neighbours, and
// the bound on its error.
struct Prediction {
  PoseCorrection correction;
  double gap_s = 0.0;  // to the match(es) it comes from
  double bound_m = 0.0;
  bool interpolated = false;
};

Prediction PredictCorrection(const MatchState& state, int o, int before,
                             int after) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  const double t = input.observations[o].time_s;
  // The prediction with the smallest error bound: extrapolated from the
  // nearest match on either side, or interpolated between both.
  PoseCorrection predicted;
  double gap = std::numeric_limits<double>::infinity();
  double bound = std::numeric_limits<double>::infinity();
  bool interpolated = false;
  // Distance travelled bounds a multipath switch (a metre within tens
  // of metres), time a smooth drift.
  auto metres_to = [&](int q) {
    return (state.obs[q].vehicle - state.obs[o].vehicle).norm();
  };
  for (int q : {before, after}) {
    if (q < 0) continue;
    const double dt = std::abs(t - input.observations[q].time_s);
    const double b = options.resolve_base_m +
                     std::max(options.drift_rate_m_per_s * dt,
                              options.max_drift_per_metre * metres_to(q));
    if (b < bound) {
      bound = b;
      gap = dt;
      predicted = state.hypotheses[q][state.chosen[q]].correction;
    }
  }
  if (before >= 0 && after >= 0) {
    const double tb = input.observations[before].time_s;
    const double ta = input.observations[after].time_s;
    const PoseCorrection& cb =
        state.hypotheses[before][state.chosen[before]].correction;
    const PoseCorrection& ca =
        state.hypotheses[after][state.chosen[after]].correction;
    // Neighbours further apart than the worst-case drift rate allows
    // (a jump) make the interpolation meaningless.
    const bool smooth = (cb.shift_enu_m - ca.shift_enu_m).norm() <=
                        options.neighbour_tolerance_m +
                            options.max_drift_rate_m_per_s * (ta - tb);
    const double u = ta > tb ? (t - tb) / (ta - tb) : 0.5;
    // Smooth drift bends little between two matches; a switch may lie
    // anywhere between them, so the nearer match's distance counts too,
    // with the part of their difference the interpolation puts on it.
    const double switch_bound =
        options.max_drift_per_metre *
            std::min(metres_to(before), metres_to(after)) +
        (cb.shift_enu_m - ca.shift_enu_m).norm() * std::min(u, 1.0 - u);
    const double b = options.resolve_base_m +
                     std::max(0.5 * options.max_drift_acceleration_m_per_s2 *
                                  (t - tb) * (ta - t),
                              switch_bound);
    if (smooth && b < bound) {
      predicted.heading_rad = (1.0 - u) * cb.heading_rad + u * ca.heading_rad;
      predicted.shift_enu_m = (1.0 - u) * cb.shift_enu_m + u * ca.shift_enu_m;
      bound = b;
      gap = std::min(t - tb, ta - t);
      interpolated = true;
    }
  }
  return {predicted, gap, bound, interpolated};
}

// The usable hypothesis of `o` nearest the prediction within its bound
// (its distance in *distance), or -1.
int PickNearPrediction(const MatchState& state, int o,
                       const Prediction& prediction, double* distance) {
  const MatchOptions& options = state.options;
  const PoseCorrection& predicted = prediction.correction;
  const double bound = prediction.bound_m;
  const std::vector<Hypothesis>& list = state.hypotheses[o];
  double top = -std::numeric_limits<double>::infinity();
  for (const Hypothesis& h : list) top = std::max(top, h.aggregated);
  int pick = -1;
  double pick_distance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < list.size(); ++i) {
    const double d = CorrectionDistance(list[i].correction, predicted,
                                        state.obs[o].centroid_q);
    const bool usable =
        static_cast<int>(list[i].eval.hits.size()) >= options.min_hit_bands &&
        list[i].eval.contradictions.empty() &&
        list[i].aggregated >= top - options.min_margin;
    if (usable && d <= bound && d < pick_distance) {
      pick = static_cast<int>(i);
      pick_distance = d;
    }
  }
  *distance = pick_distance;
  return pick;
}

// Whether every distinct hypothesis of `o` (duplicates of the pick aside)
// lies clearly outside the prediction's bound.
bool UniqueNearPrediction(const MatchState& state, int o, int pick,
                          const Prediction& prediction) {
  const MatchOptions& options = state.options;
  const std::vector<Hypothesis>& list = state.hypotheses[o];
  const PoseCorrection& predicted = prediction.correction;
  const double bound = prediction.bound_m;
  bool unique = true;
  for (size_t i = 0; i < list.size(); ++i) {
    if (static_cast<int>(i) == pick) continue;
    const double between = CorrectionDistance(
        list[i].correction, list[pick].correction, state.obs[o].centroid_q);
    if (between < 2.0 * options.same_correction_tolerance_m) continue;
    const double d = CorrectionDistance(list[i].correction, predicted,
                                        state.obs[o].centroid_q);
    if (d < bound + options.same_correction_tolerance_m) unique = false;
  }
  return unique;
}

void AcceptResolved(int o, int pick, const Prediction& prediction,
                    double pick_distance, const std::string& how,
                    MatchState* state) {
  const RoadmarkIndex& index = state->index;
  const std::vector<Hypothesis>& list = state->hypotheses[o];
  const bool interpolated = prediction.interpolated;
  const double gap = prediction.gap_s;
  const double bound = prediction.bound_m;
  const Hypothesis& h = list[pick];
  state->chosen[o] = pick;
  state->accepted[o] = true;
  ObservationEvidence& ev = state->evidence[o];
  const std::string was = ev.reason;
  ev.decision = Decision::kMatched;
  ev.resolved_by_neighbours = true;
  ev.hits = static_cast<int>(h.eval.hits.size());
  ev.missing = static_cast<int>(h.eval.missing.size());
  ev.contradictions = 0;
  ev.unexplained = static_cast<int>(h.eval.unexplained.size());
  ev.own_score = h.eval.score;
  ev.aggregated_score = h.aggregated;
  ev.correction = h.correction;
  ev.crossing_id = h.main_crossing >= 0
                       ? index.crossings()[h.main_crossing].crossing_id
                       : "";
  ev.reason = "resolved by trajectory continuity: the correction " +
              std::string(interpolated ? "interpolated" : "extrapolated") +
              " from matched exposures (" + FormatFixed(gap, 1) +
              " s away; error bound " + FormatFixed(bound, 2) + " m) " + how +
              " at " + FormatFixed(pick_distance, 2) + " m; alone it was " +
              was;
}

// True when the prediction, too loose to single out one hypothesis, still
// rules out every band offset that the images' strong evidence left
// standing against observation o's own best (which it must hold within
// its bound): the images excluded the near offsets, continuity the far
// ones. *distance: the own best's from the prediction.
bool ExcludesUnbeatenOffsets(const MatchState& state, int o,
                             const Prediction& prediction, double* distance) {
  const MatchOptions& options = state.options;
  const std::vector<int>& unbeaten = state.unbeaten_offsets[o];
  const std::vector<Hypothesis>& list = state.hypotheses[o];
  const Eigen::Vector2d& q = state.obs[o].centroid_q;
  if (unbeaten.empty() || state.chosen[o] < 0 ||
      prediction.bound_m > options.max_exclusion_bound_m) {
    return false;
  }
  *distance = CorrectionDistance(list[state.chosen[o]].correction,
                                 prediction.correction, q);
  if (*distance > prediction.bound_m) return false;
  for (int k : unbeaten) {
    if (CorrectionDistance(list[k].correction, prediction.correction, q) <=
        prediction.bound_m + options.same_correction_tolerance_m) {
      return false;
    }
  }
  return true;
}

// Resolves the observation at position k of by_time from its matched
// neighbours, if they single out one of its hypotheses.
void ResolveObservation(int k, MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const int o = state->by_time[k];
  int before = -1;
  int after = -1;
  NearestMatched(*state, k, &before, &after);
  if (before < 0 && after < 0) {
    VLOG(1) << "resolve " << input.observations[o].exposure_id
            << ": no matched neighbour in the same GNSS regime";
    return;
  }
  const Prediction prediction = PredictCorrection(*state, o, before, after);
  const double bound = prediction.bound_m;
  if (bound > options.max_resolve_bound_m) {
    double own_distance = 0.0;
    if (ExcludesUnbeatenOffsets(*state, o, prediction, &own_distance)) {
      AcceptResolved(o, state->chosen[o], prediction, own_distance,
                     "rules out the band offsets the images left standing",
                     state);
      return;
    }
    VLOG(1) << "resolve " << input.observations[o].exposure_id
            << ": prediction bound " << bound << " m too loose";
    return;
  }
  double pick_distance = 0.0;
  const int pick = PickNearPrediction(*state, o, prediction, &pick_distance);
  if (pick < 0) {
    VLOG(1) << "resolve " << input.observations[o].exposure_id
            << ": no hypothesis within " << bound << " m of the "
            << "prediction";
    return;
  }
  if (!UniqueNearPrediction(*state, o, pick, prediction)) {
    VLOG(1) << "resolve " << input.observations[o].exposure_id
            << ": several hypotheses near the prediction";
    return;
  }
  AcceptResolved(o, pick, prediction, pick_distance, "selects it", state);
}

}  // namespace

void CheckContinuity(MatchState* state) {
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  std::vector<Pass> passes = BuildPasses(*state);
  auto gap = [](const Pass& a, const Pass& b) { return PassGap(a, b); };
  auto consistent = [&](const Pass& a, const Pass& b) {
    return (a.shift - b.shift).norm() <=
           options.neighbour_tolerance_m +
               options.max_drift_rate_m_per_s * gap(a, b);
  };
  // Only neighbours close enough in time to tell a one-band error (1 m)
  // from drift vote.
  auto informative = [&](const Pass& a, const Pass& b) {
    return gap(a, b) <= options.neighbour_window_s &&
           options.neighbour_tolerance_m +
                   options.max_drift_rate_m_per_s * gap(a, b) <=
               options.max_informative_tolerance_m;
  };
  // Reject, worst first, passes that disagree with more neighbours than
  // agree; two passes that only disagree with each other both go.
  while (true) {
    int worst = 0;
    std::vector<int> worst_passes;
    for (size_t p = 0; p < passes.size(); ++p) {
      if (passes[p].rejected) continue;
      int agree = 0;
      int disagree = 0;
      for (size_t q = 0; q < passes.size(); ++q) {
        if (q == p || passes[q].rejected) continue;
        if (passes[q].crossing == passes[p].crossing) continue;
        if (!informative(passes[p], passes[q])) continue;
        if (consistent(passes[p], passes[q])) {
          ++agree;
        } else {
          ++disagree;
        }
      }
      const int balance = disagree - agree;
      if (balance > worst) {
        worst = balance;
        worst_passes.assign(1, static_cast<int>(p));
      } else if (balance == worst && balance > 0) {
        worst_passes.push_back(static_cast<int>(p));
      }
    }
    if (worst <= 0) break;
    for (int p : worst_passes) {
      Pass& pass = passes[p];
      pass.rejected = true;
      // Name the neighbours it disagrees with.
      std::ostringstream why;
      why << "inconsistent with neighbouring crossings:";
      int named = 0;
      for (size_t q = 0; q < passes.size(); ++q) {
        if (static_cast<int>(q) == p || passes[q].crossing == pass.crossing ||
            !informative(pass, passes[q]) || consistent(pass, passes[q]) ||
            named >= 3) {
          continue;
        }
        ++named;
        why << " " << index.crossings()[passes[q].crossing].crossing_id << " ("
            << FormatFixed(passes[q].t0 - pass.t0, 1) << " s) implies a "
            << "correction "
            << FormatFixed((passes[q].shift - pass.shift).norm(), 2)
            << " m away";
      }
      for (int o : pass.obs) {
        state->accepted[o] = false;
        state->evidence[o].decision = Decision::kRefused;
        state->evidence[o].reason = why.str();
        state->inconsistent.insert(o);
      }
    }
  }
}

void DetectShiftedCrossings(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  std::vector<Pass> passes = BuildPasses(*state);
  // Shifted (repainted) crossings: neighbours on both sides agree with each
  // other and predict a correction this crossing departs from.
  for (Pass& pass : passes) {
    if (pass.rejected) continue;
    const Pass* before = nullptr;
    const Pass* after = nullptr;
    for (const Pass& q : passes) {
      if (q.rejected || q.crossing == pass.crossing) continue;
      if (q.t1 < pass.t0 && pass.t0 - q.t1 <= options.neighbour_window_s &&
          (before == nullptr || q.t1 > before->t1)) {
        before = &q;
      }
      if (q.t0 > pass.t1 && q.t0 - pass.t1 <= options.neighbour_window_s &&
          (after == nullptr || q.t0 < after->t0)) {
        after = &q;
      }
    }
    if (before == nullptr || after == nullptr) continue;
    const double tb = 0.5 * (before->t0 + before->t1);
    const double ta = 0.5 * (after->t0 + after->t1);
    const double tp = 0.5 * (pass.t0 + pass.t1);
    const double u = ta > tb ? (tp - tb) / (ta - tb) : 0.5;
    const Eigen::Vector2d predicted =
        (1.0 - u) * before->shift + u * after->shift;
    const double span = ta - tb;
    const double neighbours_disagree = (after->shift - before->shift).norm();
    const double deviation = (pass.shift - predicted).norm();
    const double allowed = options.shifted_crossing_threshold_m + 0.01 * span +
                           neighbours_disagree;
    if (deviation <= allowed) continue;
    const IndexedCrossing& crossing = index.crossings()[pass.crossing];
    DatabaseFault fault;
    fault.kind = FaultKind::kCrossingShifted;
    fault.crossing_id = crossing.crossing_id;
    fault.location_enu = crossing.centre_enu;
    fault.shift_m = deviation;
    fault.views = static_cast<int>(pass.obs.size());
    for (int o : pass.obs) {
      fault.exposure_ids.push_back(input.observations[o].exposure_id);
    }
    fault.description = "crossing " + crossing.crossing_id +
                        " implies a correction " + FormatFixed(deviation, 2) +
                        " m away from the one interpolated between " +
                        index.crossings()[before->crossing].crossing_id +
                        " and " +
                        index.crossings()[after->crossing].crossing_id +
                        ": database crossing shifted (repainted?)";
    state->faults.push_back(fault);
    for (int o : pass.obs) {
      if (options.refuse_shifted_crossings) {
        state->accepted[o] = false;
        state->evidence[o].decision = Decision::kRefused;
        state->evidence[o].reason = fault.description;
        state->inconsistent.insert(o);
      } else {
        state->evidence[o].reason += "; warning: " + fault.description;
      }
    }
  }
}

void ResolveFromNeighbours(MatchState* state) {
  // Sweep forward then backward so that a resolved observation can serve
  // its neighbours (the drift barely changes between exposures).
  for (int sweep = 0; sweep < 2; ++sweep) {
    const int n = static_cast<int>(state->by_time.size());
    for (int s = 0; s < n; ++s) {
      const int k = sweep == 0 ? s : n - 1 - s;
      const int o = state->by_time[k];
      if (state->accepted[o] || !state->ambiguous[o] ||
          state->inconsistent.count(o))
        continue;
      ResolveObservation(k, state);
    }
  }
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
