// Step 5 of MatchBands (band_matcher_internal.h): each accepted
// observation's correction refined on its own bands into vertex matches
// (the bands whose corners lie on them across their axis, and the corners
// that also lie at their ends, to vertex_tolerance_m), the database
// faults the decisions reveal, and the result with a decision per
// observation.
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

// Bands missing on either side (from the street, from the database), from
// matched observations.
void DetectBandFaults(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const auto& crossings = index.crossings();
  std::map<int, int> band_seen;                      // database band -> views
  std::map<int, std::vector<int64_t>> band_missing;  // -> exposures
  std::map<std::pair<int, int>, std::vector<int64_t>>
      extra;  // (crossing, side)
  std::set<int> matched_crossings;
  for (size_t o = 0; o < state->obs.size(); ++o) {
    if (!state->accepted[o]) continue;
    const Hypothesis& h = state->hypotheses[o][state->chosen[o]];
    const int64_t exposure = input.observations[o].exposure_id;
    for (const Hit& hit : h.eval.hits) {
      ++band_seen[hit.db];
      matched_crossings.insert(index.bands()[hit.db].crossing);
    }
    for (int b : h.eval.missing) {
      if (!index.bands()[b].implied) band_missing[b].push_back(exposure);
    }
    if (h.main_crossing < 0) continue;
    const IndexedCrossing& crossing = crossings[h.main_crossing];
    const Eigen::Vector2d first = crossing.ToCrossing(crossing.first_end_enu);
    const Eigen::Vector2d last = crossing.ToCrossing(crossing.last_end_enu);
    for (int rec : h.eval.unexplained) {
      const Eigen::Vector2d p =
          crossing.ToCrossing(Apply(h.correction, state->obs[o].vehicle,
                                    state->obs[o].bands[rec].shape.centre));
      const double s = crossing.spacing_m;
      if (std::abs(p.y() - (last.y() + s)) < 0.3 * s &&
          std::abs(p.x() - last.x()) < crossing.band_length_m) {
        extra[{h.main_crossing, +1}].push_back(exposure);
      } else if (std::abs(p.y() - (first.y() - s)) < 0.3 * s &&
                 std::abs(p.x() - first.x()) < crossing.band_length_m) {
        extra[{h.main_crossing, -1}].push_back(exposure);
      }
    }
  }
  for (const auto& [b, exposures] : band_missing) {
    if (static_cast<int>(exposures.size()) < options.min_views_for_fault ||
        band_seen.count(b)) {
      continue;
    }
    const IndexedBand& band = index.bands()[b];
    DatabaseFault fault;
    fault.kind = FaultKind::kBandMissingFromStreet;
    fault.crossing_id = band.crossing_id;
    fault.band = band.band;
    fault.location_enu = band.centre_enu;
    fault.views = static_cast<int>(exposures.size());
    fault.exposure_ids = exposures;
    fault.description = "database band " + std::to_string(band.band) +
                        " of crossing " + band.crossing_id +
                        " was not seen in " + std::to_string(fault.views) +
                        " matched views that should have shown it: missing "
                        "from the street (or occluded)";
    state->faults.push_back(fault);
  }
  for (const auto& [key, exposures] : extra) {
    if (static_cast<int>(exposures.size()) < options.min_views_for_fault) {
      continue;
    }
    const IndexedCrossing& crossing = crossings[key.first];
    DatabaseFault fault;
    fault.kind = FaultKind::kBandMissingFromDatabase;
    fault.crossing_id = crossing.crossing_id;
    fault.band =
        key.second > 0 ? crossing.last_band + 1 : crossing.first_band - 1;
    fault.location_enu =
        key.second > 0
            ? Eigen::Vector2d(crossing.last_end_enu +
                              crossing.spacing_m * crossing.across_axis)
            : Eigen::Vector2d(crossing.first_end_enu -
                              crossing.spacing_m * crossing.across_axis);
    fault.views = static_cast<int>(exposures.size());
    fault.exposure_ids = exposures;
    fault.description = "a band was seen in " + std::to_string(fault.views) +
                        " views beyond band " +
                        std::to_string(key.second > 0 ? crossing.last_band
                                                      : crossing.first_band) +
                        " of crossing " + crossing.crossing_id +
                        ": missing from the database";
    state->faults.push_back(fault);
  }
}

// Crossings missing from the database: groups of usable bands nothing
// fits, clustered by place.
void DetectCrossingsMissingFromDatabase(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  struct Cluster {
    Eigen::Vector2d centre;
    std::vector<int64_t> exposures;
  };
  std::vector<Cluster> clusters;
  for (size_t o = 0; o < state->obs.size(); ++o) {
    if (state->evidence[o].decision != Decision::kNoCandidate ||
        state->obs[o].usable < 2) {
      continue;
    }
    const Eigen::Vector2d p = state->obs[o].vehicle + state->obs[o].centroid_q;
    Cluster* home = nullptr;
    for (Cluster& cluster : clusters) {
      if ((cluster.centre - p).norm() < 10.0) home = &cluster;
    }
    if (home == nullptr) {
      clusters.push_back({p, {}});
      home = &clusters.back();
    }
    home->exposures.push_back(input.observations[o].exposure_id);
  }
  for (const Cluster& cluster : clusters) {
    if (static_cast<int>(cluster.exposures.size()) <
        options.min_views_for_fault) {
      continue;
    }
    DatabaseFault fault;
    fault.kind = FaultKind::kCrossingMissingFromDatabase;
    fault.location_enu = cluster.centre;
    fault.views = static_cast<int>(cluster.exposures.size());
    fault.exposure_ids = cluster.exposures;
    fault.description =
        "a crossing seen in " + std::to_string(fault.views) + " views near E " +
        FormatFixed(cluster.centre.x(), 1) + " N " +
        FormatFixed(cluster.centre.y(), 1) +
        " (measured trajectory) has no database crossing within the drift "
        "gate: missing from the database";
    state->faults.push_back(fault);
  }
}

// Crossings gone from the street: fully in view of several exposures (with
// the correction of the nearest match) and never fitted by anything seen.
void DetectCrossingsGoneFromStreet(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const Visibility& visibility = state->visibility;
  const auto& crossings = index.crossings();
  if (!visibility.enabled()) return;
  std::set<int> touched;  // crossings some hypothesis explains bands of
  for (const std::vector<Hypothesis>& list : state->hypotheses) {
    for (const Hypothesis& h : list) {
      for (const Hit& hit : h.eval.hits) {
        touched.insert(index.bands()[hit.db].crossing);
      }
    }
  }
  std::vector<std::pair<double, PoseCorrection>> known;
  for (int o : state->by_time) {
    if (state->accepted[o]) {
      known.emplace_back(input.observations[o].time_s,
                         state->hypotheses[o][state->chosen[o]].correction);
    }
  }
  std::map<int, std::vector<int64_t>> should_have_seen;
  std::vector<int> near;
  for (const ExposurePose& exposure : input.exposures) {
    PoseCorrection c;
    if (!known.empty()) {
      const auto it =
          std::lower_bound(known.begin(), known.end(), exposure.time_s,
                           [](const std::pair<double, PoseCorrection>& k,
                              double t) { return k.first < t; });
      const auto& nearest =
          it == known.end()
              ? known.back()
              : (it == known.begin() ||
                         it->first - exposure.time_s <
                             exposure.time_s - std::prev(it)->first
                     ? *it
                     : *std::prev(it));
      c = nearest.second;
    }
    const Pose pose = CorrectedPose(exposure.pose, c);
    index.CrossingsWithin(pose.p_enu.head<2>(), visibility.range_m(), &near);
    for (int crossing : near) {
      if (touched.count(crossing)) continue;
      const IndexedCrossing& x = crossings[crossing];
      int visible = 0;
      for (int b : x.bands) {
        visible += visibility.BandVisible(pose, index.bands()[b]) ? 1 : 0;
      }
      if (visible >= std::min<int>(3, static_cast<int>(x.bands.size()))) {
        should_have_seen[crossing].push_back(exposure.exposure_id);
      }
    }
  }
  for (const auto& [crossing, exposures] : should_have_seen) {
    if (static_cast<int>(exposures.size()) < options.min_views_for_fault) {
      continue;
    }
    const IndexedCrossing& x = crossings[crossing];
    DatabaseFault fault;
    fault.kind = FaultKind::kCrossingGoneFromStreet;
    fault.crossing_id = x.crossing_id;
    fault.location_enu = x.centre_enu;
    fault.views = static_cast<int>(exposures.size());
    fault.exposure_ids = exposures;
    fault.description = "database crossing " + x.crossing_id +
                        " was in full "
                        "view of " +
                        std::to_string(fault.views) +
                        " exposures and nothing seen fits it: gone from the "
                        "street";
    state->faults.push_back(fault);
  }
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

void DetectFaults(MatchState* state) {
  DetectBandFaults(state);
  DetectCrossingsMissingFromDatabase(state);
  DetectCrossingsGoneFromStreet(state);
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
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
