// Step 5 of MatchBands (band_matcher_internal.h): each accepted
// observation's correction refined on its own bands into vertex matches
// (the bands whose corners lie on them across their axis, and the corners
// that also lie at their ends, to vertex_tolerance_m), and the result with
// a decision per observation (the database faults: band_matcher_faults.cc).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "registration/band_matcher_internal.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

// The matches of accepted observation `o` after refining its correction
// on its own bands: on the bands whose every corner fits across the band's
// axis to vertex_tolerance_m, with two corners or more that fit whole, the
// corners that fit whole.
std::vector<VertexMatch> RefinedMatches(const MatchState& state, int o,
                                        PoseCorrection* correction,
                                        std::vector<int>* bands,
                                        double* rms_m) {
  const MatchOptions& options = state.options;
  const RoadmarkIndex& index = state.index;
  const Obs& obs = state.obs[o];
  const Hypothesis& h = state.hypotheses[o][state.chosen[o]];
  // Refine on this observation's own bands, then keep the bands whose every
  // corner fits. One band alone (a second pass, min_hit_bands = 1) fixes
  // neither the heading nor its position along itself, where an end may
  // be cut short: refined on it, the cut is split between its ends and
  // both pass. It is checked against the trajectory as it stands, which
  // the second pass searches only where the adjustment holds it to
  // centimetres.
  const PoseCorrection c = h.eval.hits.size() == 1
                               ? PoseCorrection()
                               : Refine(state, obs, h.eval, h.correction);
  const Eval eval = Evaluate(state, obs, c);
  *correction = c;
  bands->clear();
  double sum = 0.0;
  int count = 0;
  std::vector<VertexMatch> out;
  for (const Hit& hit : eval.hits) {
    const IndexedBand& db = index.bands()[hit.db];
    if (db.implied) continue;  // no database coordinates to control with
    const ObsBand& band = obs.bands[hit.rec];
    // The band is the database's where every corner lies on it across its
    // axis; a corner is matched where it also lies at its end. An end
    // seen short (cut by the image, worn paint) or drawn long in the
    // database is left out alone, not the band with it.
    const Eigen::Vector2d across_axis(-db.axis_enu.y(), db.axis_enu.x());
    std::array<double, 4> error;
    std::array<bool, 4> corner_fits;
    bool across_fits = true;
    int corners = 0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d p = Apply(c, obs.vehicle, band.q[k]);
      const Eigen::Vector2d e =
          p - db.corners_enu[PermutedCorner(hit.perm, k)].head<2>();
      error[k] = e.norm();
      across_fits = across_fits &&
                    std::abs(e.dot(across_axis)) <= options.vertex_tolerance_m;
      corner_fits[k] = error[k] <= options.vertex_tolerance_m;
      corners += corner_fits[k] ? 1 : 0;
    }
    if (!across_fits || corners < 2) continue;
    bands->push_back(db.band);
    const ObservedBand& source = obs.source->bands[hit.rec];
    for (int k = 0; k < 4; ++k) {
      if (!corner_fits[k]) continue;
      VertexMatch match;
      match.exposure_id = obs.source->exposure_id;
      match.band_id = source.band_id;
      match.vertex = source.vertex[k];
      match.crossing_id = db.crossing_id;
      match.band = db.band;
      match.db_vertex = PermutedCorner(hit.perm, k);
      out.push_back(match);
      sum += error[k] * error[k];
      ++count;
    }
  }
  *rms_m = count > 0 ? std::sqrt(sum / count) : 0.0;
  return out;
}

}  // namespace

bool RefuseUnrefined(int o, MatchState* state) {
  const MatchOptions& options = state->options;
  PoseCorrection c;
  std::vector<int> bands;
  double rms = 0.0;
  RefinedMatches(*state, o, &c, &bands, &rms);
  if (static_cast<int>(bands.size()) >= options.min_hit_bands) return false;
  ObservationEvidence& ev = state->evidence[o];
  state->accepted[o] = false;
  ev.decision = Decision::kRefused;
  ev.reason = "after refinement only " + std::to_string(bands.size()) +
              " band(s) fit to vertex_tolerance_m = " +
              FormatFixed(options.vertex_tolerance_m, 2) +
              " m; was: " + ev.reason;
  return true;
}

void EmitMatches(int o, MatchState* state) {
  ObservationEvidence& ev = state->evidence[o];
  if (RefuseUnrefined(o, state)) return;
  const std::vector<VertexMatch> out = RefinedMatches(
      *state, o, &ev.correction, &ev.matched_bands, &ev.vertex_rms_m);
  ev.vertex_matches = static_cast<int>(out.size());
  state->matches.insert(state->matches.end(), out.begin(), out.end());
}

void Finish(MatchState* state, MatchResult* result) {
  const RoadmarkIndex& index = state->index;
  // Faults explain decisions: add them to the reasons of the observations
  // of the crossings concerned.
  std::map<std::string, std::vector<const DatabaseFault*>> by_crossing;
  for (const DatabaseFault& fault : state->faults) {
    if (!fault.crossing_id.empty()) {
      by_crossing[fault.crossing_id].push_back(&fault);
    }
  }
  MatchSummary& summary = result->summary;
  std::set<std::string> crossings;
  for (size_t o = 0; o < state->evidence.size(); ++o) {
    ObservationEvidence& ev = state->evidence[o];
    if (ev.decision != Decision::kMatched) {
      ev.crossing_id.clear();
    }
    const std::string& id =
        ev.decision == Decision::kMatched
            ? ev.crossing_id
            : (state->chosen[o] >= 0 &&
                       state->hypotheses[o][state->chosen[o]].main_crossing >= 0
                   ? index
                         .crossings()[state->hypotheses[o][state->chosen[o]]
                                          .main_crossing]
                         .crossing_id
                   : std::string());
    const auto faults = by_crossing.find(id);
    if (!id.empty() && faults != by_crossing.end()) {
      for (const DatabaseFault* fault : faults->second) {
        if (fault->kind == FaultKind::kCrossingShifted) continue;  // noted
        ev.reason += std::string("; database fault: ") +
                     FaultKindName(fault->kind) + " (band " +
                     std::to_string(fault->band) + ")";
      }
    }
    CrossingDecision decision;
    decision.exposure_id = ev.exposure_id;
    decision.group_id = ev.group_id;
    decision.decision = ev.decision;
    decision.crossing_id =
        ev.decision == Decision::kMatched ? ev.crossing_id : "";
    decision.reason = ev.reason;
    result->decisions.push_back(decision);
    ++summary.observations;
    switch (ev.decision) {
      case Decision::kMatched:
        ++summary.matched;
        crossings.insert(ev.crossing_id);
        if (ev.resolved_by_neighbours) ++summary.resolved_by_neighbours;
        break;
      case Decision::kRefused:
        ++summary.refused;
        if (state->inconsistent.count(static_cast<int>(o))) {
          ++summary.inconsistent;
        } else if (state->ambiguous[o]) {
          ++summary.ambiguous;
        }
        break;
      case Decision::kNoCandidate:
        ++summary.no_candidate;
        break;
    }
  }
  summary.vertex_matches = static_cast<int>(state->matches.size());
  summary.crossings_matched = static_cast<int>(crossings.size());
  summary.faults = static_cast<int>(state->faults.size());
  result->matches = std::move(state->matches);
  result->evidence = std::move(state->evidence);
  result->faults = std::move(state->faults);
  result->unrecognised = std::move(state->unrecognised);
  result->crossings_in_view = std::move(state->crossings_in_view);
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
