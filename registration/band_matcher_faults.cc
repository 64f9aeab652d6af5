// Step 6 of MatchBands (band_matcher_internal.h): the database faults the
// decisions reveal. A fault that says the street lacks paint (a crossing
// gone from the street, a band missing from it) rests on positive image
// evidence only: bare road where the paint should be, in view and not
// occluded (paint_probe.h), in min_views_for_fault views and paint in
// none (issue 52). Without it the crossing or band is "not recognised"
// (MatchResult::unrecognised), listed apart from the faults.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "registration/band_matcher_internal.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

// "exposures 12, 13 and 14" (at most 6 named).
std::string ExposureList(const std::vector<int64_t>& exposures) {
  std::ostringstream out;
  out << (exposures.size() == 1 ? "exposure " : "exposures ");
  const size_t shown = std::min<size_t>(exposures.size(), 6);
  for (size_t i = 0; i < shown; ++i) {
    if (i > 0) out << (i + 1 == exposures.size() ? " and " : ", ");
    out << exposures[i];
  }
  if (shown < exposures.size())
    out << " and " << exposures.size() - shown << " more";
  return out.str();
}

// Per database band (or crossing): the views whose images show bare road
// at its place, paint there, or neither.
struct ImageVerdicts {
  std::vector<int64_t> bare, paint, unclear, occluded;
};

// A band's place: bare road in enough views, paint in none and nothing
// standing over it in any: the only evidence a band fault may rest on.
bool ShowsBareRoad(const ImageVerdicts& v, int min_views) {
  return static_cast<int>(v.bare.size()) >= min_views && v.paint.empty() &&
         v.occluded.empty();
}

// The mark for a band or crossing the images did not show gone.
UnrecognisedMark Unrecognised(const std::string& crossing_id, int band,
                              const Eigen::Vector2d& location,
                              const ImageVerdicts& verdicts, bool probed,
                              const std::string& what) {
  UnrecognisedMark mark;
  mark.crossing_id = crossing_id;
  mark.band = band;
  mark.location_enu = location;
  std::vector<int64_t> all = verdicts.bare;
  all.insert(all.end(), verdicts.paint.begin(), verdicts.paint.end());
  all.insert(all.end(), verdicts.unclear.begin(), verdicts.unclear.end());
  all.insert(all.end(), verdicts.occluded.begin(), verdicts.occluded.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  mark.exposure_ids = all;
  mark.views = static_cast<int>(all.size());
  if (!probed) {
    mark.why = "no images";
    mark.description = what + " was not recognised in " +
                       std::to_string(mark.views) +
                       " views that should have shown it; without the "
                       "images nothing tells whether it is gone: not a "
                       "database fault";
  } else if (!verdicts.occluded.empty() && verdicts.paint.empty()) {
    mark.why = "occluded";
    mark.description =
        what +
        " was not recognised: the stereo pair shows something "
        "standing above the road at its place (" +
        ExposureList(verdicts.occluded) +
        ": its image points match in front of the road surface, not on "
        "it): occluded, not a database fault";
  } else if (!verdicts.paint.empty()) {
    mark.why = "paint seen";
    mark.description = what +
                       " was not recognised, but the images show "
                       "paint at its place (" +
                       ExposureList(verdicts.paint) +
                       "): painted, not a database fault";
  } else {
    mark.why = "occluded or not told";
    mark.description =
        what + " was not recognised in " + std::to_string(mark.views) +
        " views, and the images show neither paint nor bare road at its "
        "place in enough of them (a vehicle, a shadow, out of view): "
        "occluded or not recognised, not a database fault";
  }
  return mark;
}

// The accepted observations' corrections by time.
std::vector<std::pair<double, PoseCorrection>> KnownCorrections(
    const MatchState& state) {
  std::vector<std::pair<double, PoseCorrection>> known;
  for (int o : state.by_time) {
    if (state.accepted[o]) {
      known.emplace_back(state.input.observations[o].time_s,
                         state.hypotheses[o][state.chosen[o]].correction);
    }
  }
  return known;
}

// The correction of the accepted observation nearest in time to `t` (none
// without any).
PoseCorrection NearestCorrection(
    const std::vector<std::pair<double, PoseCorrection>>& known, double t) {
  if (known.empty()) return PoseCorrection();
  const auto it =
      std::lower_bound(known.begin(), known.end(), t,
                       [](const std::pair<double, PoseCorrection>& k,
                          double time) { return k.first < time; });
  if (it == known.end()) return known.back().second;
  if (it == known.begin() || it->first - t < t - std::prev(it)->first) {
    return it->second;
  }
  return std::prev(it)->second;
}

// Bands missing on either side (from the street, from the database), from
// matched observations. Missing from the street only where the images show
// bare road at the band's place against the paint of the bands matched
// beside it (AddMissingBands), in min_views_for_fault views and paint in
// none; bands never reconstructed otherwise are not recognised.
void DetectBandFaults(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const auto& crossings = index.crossings();
  const bool probed = static_cast<bool>(input.paint_probe);
  std::map<int, int> band_seen;           // database band -> views
  std::map<int, ImageVerdicts> verdicts;  // database band -> views
  std::map<std::pair<int, int>, std::vector<int64_t>>
      extra;  // (crossing, side)
  for (size_t o = 0; o < state->obs.size(); ++o) {
    if (!state->accepted[o]) continue;
    const Hypothesis& h = state->hypotheses[o][state->chosen[o]];
    const int64_t exposure = input.observations[o].exposure_id;
    for (const Hit& hit : h.eval.hits) ++band_seen[hit.db];
    // Without a probe every predicted band in view is "missing": no
    // image says whether it is bare road.
    for (int b : h.eval.missing) {
      if (index.bands()[b].implied) continue;
      (probed ? verdicts[b].bare : verdicts[b].unclear).push_back(exposure);
    }
    for (int b : h.eval.painted) {
      if (!index.bands()[b].implied) verdicts[b].paint.push_back(exposure);
    }
    for (int b : h.eval.unclear) {
      if (!index.bands()[b].implied) verdicts[b].unclear.push_back(exposure);
    }
    for (int b : h.eval.occluded) {
      if (!index.bands()[b].implied) verdicts[b].occluded.push_back(exposure);
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
  for (const auto& [b, v] : verdicts) {
    if (band_seen.count(b)) continue;
    const IndexedBand& band = index.bands()[b];
    const std::string what = "database band " + std::to_string(band.band) +
                             " of crossing " + band.crossing_id;
    const int bare = static_cast<int>(v.bare.size());
    if (probed && ShowsBareRoad(v, options.min_views_for_fault)) {
      DatabaseFault fault;
      fault.kind = FaultKind::kBandMissingFromStreet;
      fault.crossing_id = band.crossing_id;
      fault.band = band.band;
      fault.location_enu = band.centre_enu;
      fault.views = bare;
      fault.exposure_ids = v.bare;
      fault.evidence = "bare road at the band's place in " +
                       std::to_string(bare) + " images (" +
                       ExposureList(v.bare) +
                       "): the paint of the bands matched beside it, no "
                       "paint contrast where it should be, paint in none";
      fault.description = what + " was not seen in " +
                          std::to_string(fault.views) +
                          " matched views whose images show bare road at "
                          "its place: missing from the street";
      state->faults.push_back(fault);
      continue;
    }
    const int views = static_cast<int>(v.bare.size() + v.paint.size() +
                                       v.unclear.size() + v.occluded.size());
    if (views < options.min_views_for_fault) continue;
    state->unrecognised.push_back(Unrecognised(
        band.crossing_id, band.band, band.centre_enu, v, probed, what));
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
    fault.evidence =
        "a band reconstructed one period beyond the database's "
        "last in " +
        ExposureList(exposures);
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
// the correction of the nearest match), never fitted by anything seen, and
// bare road at the places of its bands in the images (the probe without
// seen bands: the paint contrast assumed, the surface the road's ahead) in
// min_views_for_fault views, paint in none. Otherwise not recognised.
void DetectCrossingsGoneFromStreet(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const Visibility& visibility = state->visibility;
  const auto& crossings = index.crossings();
  if (!visibility.enabled()) return;
  const bool probed = static_cast<bool>(input.paint_probe);
  std::set<int> touched;  // crossings some hypothesis explains bands of
  for (const std::vector<Hypothesis>& list : state->hypotheses) {
    for (const Hypothesis& h : list) {
      for (const Hit& hit : h.eval.hits) {
        touched.insert(index.bands()[hit.db].crossing);
      }
    }
  }
  const std::vector<std::pair<double, PoseCorrection>> known =
      KnownCorrections(*state);
  std::map<int, std::vector<int64_t>> should_have_seen;
  std::map<int, ImageVerdicts> verdicts;
  std::vector<int> near;
  for (const ExposurePose& exposure : input.exposures) {
    const PoseCorrection c = NearestCorrection(known, exposure.time_s);
    const Pose pose = CorrectedPose(exposure.pose, c);
    index.CrossingsWithin(pose.p_enu.head<2>(), visibility.range_m(), &near);
    for (int crossing : near) {
      if (touched.count(crossing)) continue;
      const IndexedCrossing& x = crossings[crossing];
      std::vector<int> visible;
      for (int b : x.bands) {
        if (visibility.BandVisible(pose, index.bands()[b]))
          visible.push_back(b);
      }
      if (static_cast<int>(visible.size()) <
          std::min<int>(3, static_cast<int>(x.bands.size()))) {
        continue;
      }
      should_have_seen[crossing].push_back(exposure.exposure_id);
      if (!probed) continue;
      // This view's verdict: paint on any band, bare road on at least
      // three (or all; a band under something standing over it is never
      // bare road), something standing over any, or neither.
      int bare = 0, paint = 0, occluded = 0;
      for (int b : visible) {
        const PaintEvidence e = input.paint_probe(
            exposure.exposure_id, pose, index.bands()[b].corners_enu, {});
        bare += e == PaintEvidence::kBareRoad;
        paint += e == PaintEvidence::kPaint;
        occluded += e == PaintEvidence::kOccluded;
      }
      ImageVerdicts& v = verdicts[crossing];
      if (paint > 0) {
        v.paint.push_back(exposure.exposure_id);
      } else if (bare >= std::min<int>(3, static_cast<int>(x.bands.size()))) {
        v.bare.push_back(exposure.exposure_id);
      } else if (occluded > 0) {
        v.occluded.push_back(exposure.exposure_id);
      } else {
        v.unclear.push_back(exposure.exposure_id);
      }
    }
  }
  for (const auto& [crossing, exposures] : should_have_seen) {
    if (static_cast<int>(exposures.size()) < options.min_views_for_fault) {
      continue;
    }
    const IndexedCrossing& x = crossings[crossing];
    ImageVerdicts v = verdicts[crossing];
    const int bare = static_cast<int>(v.bare.size());
    if (probed && bare >= options.min_views_for_fault && v.paint.empty()) {
      DatabaseFault fault;
      fault.kind = FaultKind::kCrossingGoneFromStreet;
      fault.crossing_id = x.crossing_id;
      fault.location_enu = x.centre_enu;
      fault.views = bare;
      fault.exposure_ids = v.bare;
      fault.evidence =
          "bare road at the places of its bands in " + std::to_string(bare) +
          " images (" + ExposureList(v.bare) +
          "): no paint contrast against the gaps beside them, the surface "
          "the road's ahead of the vehicle, paint in none of " +
          std::to_string(exposures.size()) + " views";
      fault.description = "database crossing " + x.crossing_id +
                          " was in full view of " +
                          std::to_string(exposures.size()) +
                          " exposures, nothing seen fits it and the images "
                          "show bare road where it should be: gone from the "
                          "street";
      state->faults.push_back(fault);
      continue;
    }
    if (!probed) v.unclear = exposures;
    state->unrecognised.push_back(
        Unrecognised(x.crossing_id, 0, x.centre_enu, v, probed,
                     "database crossing " + x.crossing_id));
  }
}

// What became of every database crossing in view (issue 51): matched,
// refused, gone, not recognised, or not reconstructed and why (edge-on,
// beyond range, partly in view). After the faults.
void ListCrossingsInView(MatchState* state) {
  const MatchInput& input = state->input;
  const RoadmarkIndex& index = state->index;
  const Visibility& visibility = state->visibility;
  const auto& crossings = index.crossings();
  if (!visibility.enabled()) return;
  std::map<int, std::pair<std::string, std::string>> fate;  // status, why
  for (size_t o = 0; o < state->obs.size(); ++o) {
    if (!state->accepted[o]) continue;
    for (const Hit& hit : state->hypotheses[o][state->chosen[o]].eval.hits) {
      fate[index.bands()[hit.db].crossing] = {"matched", ""};
    }
  }
  for (size_t o = 0; o < state->obs.size(); ++o) {
    const int chosen = state->chosen[o];
    if (state->accepted[o] || chosen < 0) continue;
    const int c = state->hypotheses[o][chosen].main_crossing;
    if (c < 0 || fate.count(c)) continue;
    const ObservationEvidence& ev = state->evidence[o];
    fate[c] = {ev.decision == Decision::kRefused ? "refused" : "not matched",
               ev.reason};
  }
  std::map<std::string, int> by_id;
  for (size_t c = 0; c < crossings.size(); ++c) {
    by_id[crossings[c].crossing_id] = static_cast<int>(c);
  }
  for (const DatabaseFault& f : state->faults) {
    if (f.kind != FaultKind::kCrossingGoneFromStreet) continue;
    fate[by_id[f.crossing_id]] = {"gone from the street", f.evidence};
  }
  for (const UnrecognisedMark& m : state->unrecognised) {
    if (m.band != 0 || fate.count(by_id[m.crossing_id])) continue;
    // Occluded: the stereo pair shows something standing over it (issue
    // 51 point 4, issue 52), listed as such rather than "not recognised".
    fate[by_id[m.crossing_id]] = {
        m.why == "occluded" ? "occluded" : "not recognised",
        m.why == "occluded" ? m.description : m.why};
  }
  // Views with a band in full view, the nearest distance, and whether its
  // bands lay across the track there (long sides along the baseline).
  struct Seen {
    int views = 0;
    double nearest_m = 1e30;
    bool edge_on = false;
  };
  std::map<int, Seen> seen;
  const std::vector<std::pair<double, PoseCorrection>> known =
      KnownCorrections(*state);
  std::vector<int> near;
  for (const ExposurePose& exposure : input.exposures) {
    const Pose pose =
        CorrectedPose(exposure.pose, NearestCorrection(known, exposure.time_s));
    const Eigen::Vector2d p = pose.p_enu.head<2>();
    index.CrossingsWithin(p, 1.5 * visibility.range_m(), &near);
    Eigen::Vector2d ahead =
        (pose.q_enu_body * Eigen::Vector3d::UnitX()).head<2>();
    if (ahead.norm() > 0.0) ahead.normalize();
    for (int c : near) {
      Seen& s = seen[c];
      const double d = (crossings[c].centre_enu - p).norm();
      bool any = false;
      for (int b : crossings[c].bands) {
        any = any || visibility.BandVisible(pose, index.bands()[b]);
      }
      s.views += any ? 1 : 0;
      if (d < s.nearest_m) {
        s.nearest_m = d;
        s.edge_on = std::abs(crossings[c].band_axis.dot(ahead)) < 0.7;
      }
    }
  }
  for (const auto& [c, s] : seen) {
    CrossingInView entry;
    entry.crossing_id = crossings[c].crossing_id;
    entry.views = s.views;
    const auto f = fate.find(c);
    if (f != fate.end()) {
      entry.status = f->second.first;
      entry.reason = f->second.second;
    } else if (s.views == 0 && s.nearest_m > visibility.range_m()) {
      entry.status = "not reconstructed";
      entry.reason = "beyond range: " + FormatFixed(s.nearest_m, 1) +
                     " m away at the nearest, the bands are used within " +
                     FormatFixed(visibility.range_m(), 1) + " m";
    } else if (s.edge_on) {
      entry.status = "not reconstructed";
      entry.reason =
          "seen edge-on: its bands lie across the track, their long sides "
          "along the stereo baseline where disparity measures nothing";
    } else if (s.views == 0) {
      entry.status = "not reconstructed";
      entry.reason = "never wholly inside the images";
    } else {
      entry.status = "not reconstructed";
      entry.reason =
          "too few bands or views in full view (at the edge of "
          "the images or partly hidden)";
    }
    state->crossings_in_view.push_back(entry);
  }
}

}  // namespace

void DetectFaults(MatchState* state) {
  DetectBandFaults(state);
  DetectCrossingsMissingFromDatabase(state);
  DetectCrossingsGoneFromStreet(state);
  ListCrossingsInView(state);
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
