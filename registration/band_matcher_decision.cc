// Step 3 of MatchBands (band_matcher_internal.h): each observation decided
// alone. Its best hypothesis over the window must beat every distinct
// alternative (another band offset, another crossing) by min_margin (with
// require_both_ends, even without the evidence of its stronger crossing
// end), and every other band offset of its crossing by min_strong_margin of
// evidence that neither a database missing an end band nor an end band
// hidden in the images can fake.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "registration/band_matcher_internal.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

// Aggregated margin of `best` over `other` after discarding the evidence
// of the one crossing end that favours `best` most: a database fault at
// one end (a band missing on either side) must not decide the offset.
Margin MarginOver(const MatchState& state, int o, const Hypothesis& best,
                  const Hypothesis& other) {
  const MatchInput& input = state.input;
  // Both attributed with the best's placement, so that a band counts at the
  // same end under both hypotheses.
  std::map<int, Evidence> mine;
  std::map<int, Evidence> theirs;
  const double total =
      WindowEvidence(state, o, best.correction, best.correction, &mine) -
      WindowEvidence(state, o, other.correction, best.correction, &theirs);
  std::map<int, double> delta;
  double strong = 0.0;
  for (const auto& [unit, value] : mine) {
    delta[unit] += value.weak + value.strong;
    strong += value.strong;
  }
  for (const auto& [unit, value] : theirs) {
    delta[unit] -= value.weak + value.strong;
    strong -= value.strong;
  }
  double discount = 0.0;
  for (const auto& [unit, value] : delta) {
    if (unit >= 0) discount = std::max(discount, value);
  }
  VLOG(2) << "margin of observation " << o << " (exposure "
          << input.observations[o].exposure_id << "): " << total
          << ", both ends " << total - discount << ", strong " << strong
          << " against "
          << DescribeAlternative(state.index, state.obs[o], best, other);
  return {total, total - discount, strong};
}

// Why an observation without a hypothesis has none; false when it has.
bool ExplainNoCandidate(const MatchState& state, int o,
                        ObservationEvidence* ev) {
  const Obs& obs = state.obs[o];
  const std::vector<Hypothesis>& list = state.hypotheses[o];
  if (obs.usable == 0) {
    ev->decision = Decision::kNoCandidate;
    ev->reason = obs.bands.empty()
                     ? "no bands"
                     : "no observed band has a zebra band's shape (lane "
                       "marks or false detections?)";
    return true;
  }
  if (list.empty()) {
    ev->decision = Decision::kNoCandidate;
    const std::string what =
        obs.usable == 1 ? "a false detection or a crossing missing from the "
                          "database?"
                        : "crossing missing from the database?";
    ev->reason =
        state.candidate_bands[o] == 0
            ? "no database band within the " +
                  FormatFixed(Gate(state.options, obs), 1) +
                  " m drift gate: " + what
            : std::to_string(state.candidate_bands[o]) +
                  " database bands within the drift gate but none fits the "
                  "observed bands' shape: " +
                  what;
    return true;
  }
  return false;
}

// The hypothesis with the best aggregated score (ties: the best own score).
int BestHypothesis(const std::vector<Hypothesis>& list) {
  int best = 0;
  for (size_t k = 1; k < list.size(); ++k) {
    const Hypothesis& h = list[k];
    const Hypothesis& b = list[best];
    if (h.aggregated > b.aggregated + 1e-9 ||
        (std::abs(h.aggregated - b.aggregated) <= 1e-9 &&
         h.eval.score > b.eval.score)) {
      best = static_cast<int>(k);
    }
  }
  return best;
}

// The distinct alternatives of hypothesis `best` of observation `o`, by
// their closest calls.
struct Alternatives {
  int runner = -1;  // the runner-up reported
  double margin = std::numeric_limits<double>::infinity();
  double both_ends = std::numeric_limits<double>::infinity();
  // The band offset of the same crossing beaten by the least strong
  // evidence (bare road where it puts paint, a band where it has a gap or
  // nothing before band 1), and which it is.
  double one_end_strong = std::numeric_limits<double>::infinity();
  int one_end_runner = -1;
  // Every band offset of the same crossing beaten by less strong evidence
  // than min_strong_margin.
  std::vector<int> unbeaten;
};
Alternatives CompareAlternatives(const MatchState& state, int o, int best) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  const Obs& obs = state.obs[o];
  const std::vector<Hypothesis>& list = state.hypotheses[o];
  const Hypothesis& h = list[best];
  // Every distinct alternative (another band offset, another crossing)
  // must lose by min_margin; with require_both_ends, even without the
  // evidence of the crossing end that favours the best most. The runner-up
  // reported is the closest call.
  const double distinct = 2.0 * options.same_correction_tolerance_m;
  int runner = -1;
  double margin = std::numeric_limits<double>::infinity();
  double both_ends = std::numeric_limits<double>::infinity();
  double one_end_strong = std::numeric_limits<double>::infinity();
  int one_end_runner = -1;
  std::vector<int> unbeaten;
  for (size_t k = 0; k < list.size(); ++k) {
    VLOG(3) << "hypothesis " << k << " of exposure "
            << input.observations[o].exposure_id << ": own "
            << list[k].eval.score << ", aggregated " << list[k].aggregated
            << ", shift " << list[k].correction.shift_enu_m.transpose();
    if (static_cast<int>(k) == best) continue;
    if (CorrectionDistance(list[k].correction, h.correction, obs.centroid_q) <
        distinct) {
      continue;
    }
    const Margin m = MarginOver(state, o, h, list[k]);
    const double deciding = options.require_both_ends ? m.both_ends : m.raw;
    if (deciding < (options.require_both_ends ? both_ends : margin)) {
      runner = static_cast<int>(k);
    }
    margin = std::min(margin, m.raw);
    both_ends = std::min(both_ends, m.both_ends);
    // Between band offsets of one crossing, band counts decide nothing:
    // at either end a database missing its end band (not implied by the
    // numbering when it is the last), or an end band hidden in the images
    // (a parked vehicle, the image border, range), gives the same counts.
    if (list[k].main_crossing == h.main_crossing && m.strong < one_end_strong) {
      one_end_strong = m.strong;
      one_end_runner = static_cast<int>(k);
    }
    if (list[k].main_crossing == h.main_crossing &&
        m.strong < options.min_strong_margin) {
      unbeaten.push_back(static_cast<int>(k));
    }
  }
  return {runner,         margin,         both_ends,
          one_end_strong, one_end_runner, std::move(unbeaten)};
}

// The reason of an accepted observation.
std::string MatchedReason(const MatchOptions& options,
                          const ObservationEvidence& ev, int runner,
                          double both_ends) {
  std::ostringstream reason;
  reason << ev.hits << " bands fit crossing " << ev.crossing_id << "; score "
         << FormatFixed(ev.aggregated_score, 1) << " over +-"
         << FormatFixed(options.window_s, 0) << " s";
  if (runner >= 0) {
    reason << "; next " << ev.runner_up << " "
           << FormatFixed(ev.runner_up_score, 1);
    if (both_ends < options.min_margin) {
      // Said plainly: decided at one end, by what a database fault there
      // cannot fake (bare road where the alternative puts paint, a band
      // beyond band 1).
      reason << "; decided at one end of the crossing, by what the images "
                "show there";
    }
  } else {
    reason << "; no alternative";
  }
  return reason.str();
}

}  // namespace

void DecideAlone(int o, MatchState* state) {
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const Obs& obs = state->obs[o];
  ObservationEvidence& ev = state->evidence[o];
  const std::vector<Hypothesis>& list = state->hypotheses[o];
  ev.hypotheses = static_cast<int>(list.size());
  ev.candidate_db_bands = state->candidate_bands[o];
  if (ExplainNoCandidate(*state, o, &ev)) return;
  const int best = BestHypothesis(list);
  const Hypothesis& h = list[best];
  state->chosen[o] = best;
  ev.hits = static_cast<int>(h.eval.hits.size());
  ev.missing = static_cast<int>(h.eval.missing.size());
  ev.contradictions = static_cast<int>(h.eval.contradictions.size());
  ev.unexplained = static_cast<int>(h.eval.unexplained.size());
  ev.own_score = h.eval.score;
  ev.aggregated_score = h.aggregated;
  ev.correction = h.correction;
  if (h.main_crossing >= 0) {
    ev.crossing_id = index.crossings()[h.main_crossing].crossing_id;
  }
  const auto [runner, margin, both_ends, one_end_strong, one_end_runner,
              unbeaten] = CompareAlternatives(*state, o, best);
  if (runner >= 0) {
    const Hypothesis& r = list[runner];
    ev.has_runner_up = true;
    ev.runner_up_score = r.aggregated;
    ev.runner_up = DescribeAlternative(index, obs, h, r);
  }
  const double robust_margin = options.require_both_ends ? both_ends : margin;
  ev.robust_margin = std::isfinite(robust_margin) ? robust_margin : 0.0;
  ev.both_ends_margin = std::isfinite(both_ends) ? both_ends : 0.0;
  ev.decision = Decision::kRefused;
  if (ev.hits < options.min_hit_bands) {
    ev.reason = "only " + std::to_string(ev.hits) +
                " band(s) explained (min_hit_bands = " +
                std::to_string(options.min_hit_bands) + ")";
    state->ambiguous[o] = false;
    return;
  }
  if (ev.contradictions > 0) {
    ev.reason = "the best fit leaves " + std::to_string(ev.contradictions) +
                " observed band(s) in gaps of crossing " + ev.crossing_id;
    return;
  }
  if (ev.unexplained > options.max_unexplained_per_hit * ev.hits) {
    ev.reason = "the best fit leaves " + std::to_string(ev.unexplained) +
                " observed band(s) outside every crossing against " +
                std::to_string(ev.hits) + " it explains on crossing " +
                ev.crossing_id;
    return;
  }
  if (robust_margin < options.min_margin) {
    state->ambiguous[o] = true;
    ev.reason = "ambiguous: " + ev.runner_up + " scores " +
                FormatFixed(ev.runner_up_score, 2) + " against " +
                FormatFixed(ev.aggregated_score, 2) + " (margin " +
                FormatFixed(robust_margin, 2) + " < " +
                FormatFixed(options.min_margin, 1) + ")";
    if (h.main_crossing >= 0) {
      const IndexedCrossing& crossing = index.crossings()[h.main_crossing];
      bool end_seen = false;
      for (const Hit& hit : h.eval.hits) {
        const int band = index.bands()[hit.db].band;
        end_seen = end_seen || band == crossing.first_band ||
                   band == crossing.last_band;
      }
      if (!end_seen) ev.reason += "; only interior bands seen";
    }
    return;
  }
  if (one_end_runner >= 0 && one_end_strong < options.min_strong_margin) {
    state->ambiguous[o] = true;
    state->unbeaten_offsets[o] = unbeaten;
    ev.reason = "ambiguous: decided against " +
                DescribeAlternative(index, obs, h, list[one_end_runner]) +
                " by band counts alone (evidence a database missing an "
                "end band, or an end band hidden in the images, cannot "
                "fake: " +
                FormatFixed(std::max(0.0, one_end_strong), 2) + " < " +
                FormatFixed(options.min_strong_margin, 1) + ")";
    return;
  }
  state->accepted[o] = true;
  ev.decision = Decision::kMatched;
  ev.reason = MatchedReason(options, ev, runner, both_ends);
}

std::string DescribeAlternative(const RoadmarkIndex& index, const Obs& obs,
                                const Hypothesis& best,
                                const Hypothesis& other) {
  if (other.main_crossing != best.main_crossing || best.main_crossing < 0) {
    const std::string id =
        other.main_crossing >= 0
            ? index.crossings()[other.main_crossing].crossing_id
            : std::string("?");
    return "crossing " + id + " also fits";
  }
  const IndexedCrossing& crossing = index.crossings()[best.main_crossing];
  const Eigen::Vector2d delta =
      Apply(other.correction, obs.vehicle, obs.centroid_q) -
      Apply(best.correction, obs.vehicle, obs.centroid_q);
  const double across = delta.dot(crossing.across_axis);
  const double bands =
      crossing.spacing_m > 0.0 ? across / crossing.spacing_m : 0.0;
  std::ostringstream out;
  out << "band offset " << (bands >= 0 ? "+" : "") << FormatFixed(bands, 1)
      << " (" << FormatFixed(delta.norm(), 2) << " m)";
  return out.str();
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
