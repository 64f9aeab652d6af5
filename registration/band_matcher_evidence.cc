// Step 2 of MatchBands (band_matcher_internal.h): what each view says
// about a correction (bands explained, bands in a gap of a crossing or
// beyond its band 1, database bands the view should show but does not,
// asked of the image probe where there is one), and that evidence summed
// over the views of the window, by crossing end.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "registration/band_matcher_internal.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

// Whether a band centred at `centre` lies one or two periods beyond the
// crossing's band 1 (held or implied by the numbering).
bool BeyondBandOne(const IndexedCrossing& crossing,
                   const Eigen::Vector2d& centre) {
  // Band numbers grow along across_axis; band 1 lies first_band - 1
  // periods before the first held band.
  const Eigen::Vector2d p = crossing.ToCrossing(centre);
  const Eigen::Vector2d first = crossing.ToCrossing(crossing.first_end_enu);
  const double s = crossing.spacing_m;
  const double y1 = first.y() - (crossing.first_band - 1) * s;
  const double along =
      p.x() - first.x() - std::tan(crossing.skew_rad) * (p.y() - first.y());
  return p.y() < y1 - 0.5 * s && p.y() > y1 - 2.5 * s &&
         std::abs(along) < 0.5 * crossing.band_length_m + 0.5;
}

// Files observed band `rec` (centred at `centre`), which no database band
// explains, as a band seen partly, a contradiction (in a gap of a
// crossing) or unexplained (and then whether beyond band 1).
void ClassifyUnexplained(const RoadmarkIndex& index,
                         const Eigen::Vector2d& centre, int rec, Eval* eval) {
  std::vector<int> near;
  index.BandsWithin(centre, 1.5, &near);
  std::set<int> crossings;
  for (int b : near) crossings.insert(index.bands()[b].crossing);
  bool contradiction = false;
  for (int c : crossings) {
    const IndexedCrossing& crossing = index.crossings()[c];
    const Eigen::Vector2d p = crossing.ToCrossing(centre);
    double nearest_across = std::numeric_limits<double>::infinity();
    double nearest_along = 0.0;
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (int b : crossing.bands) {
      const Eigen::Vector2d pb =
          crossing.ToCrossing(index.bands()[b].centre_enu);
      low = std::min(low, pb.y());
      high = std::max(high, pb.y());
      if (std::abs(p.y() - pb.y()) < std::abs(nearest_across)) {
        nearest_across = p.y() - pb.y();
        nearest_along = p.x() - pb.x();
      }
    }
    const double half_length = 0.5 * crossing.band_length_m;
    if (std::abs(nearest_across) < kPartialBandAcrossM &&
        std::abs(nearest_along) < half_length + 0.5) {
      eval->partial.push_back(rec);
      return;
    }
    const double half_width = 0.5 * crossing.band_width_m;
    if (p.y() > low - half_width && p.y() < high + half_width &&
        std::abs(nearest_along) < half_length) {
      // Inside the crossing, between bands: a gap of the database, unless
      // the database itself lacks a band number there.
      bool at_missing_number = false;
      const Eigen::Vector2d first = crossing.ToCrossing(crossing.first_end_enu);
      for (int n : crossing.missing_band_numbers) {
        const double y =
            first.y() + (n - crossing.first_band) * crossing.spacing_m;
        if (std::abs(p.y() - y) < 0.35 * crossing.spacing_m) {
          at_missing_number = true;
        }
      }
      if (!at_missing_number) contradiction = true;
    }
  }
  if (contradiction) {
    eval->contradictions.push_back(rec);
    return;
  }
  eval->unexplained.push_back(rec);
  for (int c : crossings) {
    if (BeyondBandOne(index.crossings()[c], centre)) {
      eval->beyond_first.push_back(rec);
      break;
    }
  }
}

// The database bands of the crossings `eval` hits that the view should
// show under correction `c` but that it did not reconstruct. With an image
// probe, only those the images show as bare road.
void AddMissingBands(const MatchState& state, const Obs& obs,
                     const PoseCorrection& c, const std::set<int>& used_db,
                     Eval* eval) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  const RoadmarkIndex& index = state.index;
  const Visibility& visibility = state.visibility;
  std::set<int> crossings;
  for (const Hit& h : eval->hits) {
    crossings.insert(index.bands()[h.db].crossing);
  }
  const Pose pose = CorrectedPose(obs.source->pose, c);
  std::vector<BandCornersEnu> seen;
  if (input.paint_probe) {
    for (const Hit& h : eval->hits)
      seen.push_back(index.bands()[h.db].corners_enu);
  }
  for (int crossing : crossings) {
    std::vector<int> predicted = index.crossings()[crossing].bands;
    const std::vector<int>& implied = index.crossings()[crossing].implied_bands;
    predicted.insert(predicted.end(), implied.begin(), implied.end());
    for (int b : predicted) {
      if (used_db.count(b)) continue;
      const bool may_look =
          input.paint_probe ? visibility.ProbeMayLook(pose, index.bands()[b],
                                                      options.probe_range_m)
                            : visibility.BandVisible(pose, index.bands()[b]);
      if (!may_look) continue;
      // A band the reconstruction missed (hidden, worn, lost at range) is
      // no evidence; bare road where the hypothesis puts paint is.
      if (input.paint_probe) {
        const PaintEvidence evidence = input.paint_probe(
            obs.source->exposure_id, pose, index.bands()[b].corners_enu, seen);
        if (evidence == PaintEvidence::kPaint) eval->painted.push_back(b);
        if (evidence == PaintEvidence::kUnknown) eval->unclear.push_back(b);
        if (evidence == PaintEvidence::kOccluded) eval->occluded.push_back(b);
        if (evidence != PaintEvidence::kBareRoad) continue;
      }
      eval->missing.push_back(b);
    }
  }
}

// Two hypotheses of views `dt` apart are the same correction within this.
double Tolerance(const MatchOptions& options, double dt) {
  return options.same_correction_tolerance_m +
         options.drift_rate_m_per_s * std::abs(dt);
}

// The crossing end `p_enu` lies at (crossing * 2 + end, end 0 for the half
// of the crossing holding its first band, 1 for the other), or -1 away
// from every crossing.
int EndUnit(const RoadmarkIndex& index, const Eigen::Vector2d& p_enu) {
  const int nearest = index.NearestBand(p_enu);
  if (nearest < 0) return -1;
  const IndexedBand& band = index.bands()[nearest];
  const IndexedCrossing& crossing = index.crossings()[band.crossing];
  if ((p_enu - crossing.centre_enu).norm() > crossing.radius_m + 2.0) {
    return -1;
  }
  const double y = crossing.ToCrossing(p_enu).y();
  const double mid = 0.5 * (crossing.ToCrossing(crossing.first_end_enu).y() +
                            crossing.ToCrossing(crossing.last_end_enu).y());
  return 2 * band.crossing + (y <= mid ? 0 : 1);
}

// The best-scoring hypothesis of observation `other` within the window
// tolerance of `c`, or null.
const Hypothesis* Supporting(const MatchState& state, int other,
                             const PoseCorrection& c, double dt) {
  const double tolerance = Tolerance(state.options, dt);
  const Hypothesis* best = nullptr;
  for (const Hypothesis& g : state.hypotheses[other]) {
    if (CorrectionDistance(g.correction, c, state.obs[other].centroid_q) >
        tolerance) {
      continue;
    }
    if (best == nullptr || g.eval.score > best->eval.score) best = &g;
  }
  return best;
}

}  // namespace

Visibility::Visibility(const Rig* rig, double margin_px, double range_m)
    : rig_(rig), margin_px_(margin_px), range_m_(range_m) {
  if (rig_ == nullptr) return;
  for (const RigCamera& camera : rig_->cameras) {
    T_cam_body_.push_back(camera.T_body_cam.inverse());
  }
}

bool Visibility::ProbeMayLook(const Pose& pose, const IndexedBand& band,
                              double probe_range_m) const {
  if (rig_ == nullptr || rig_->stereo_pairs.empty()) return false;
  if ((band.centre_enu - pose.p_enu.head<2>()).norm() > probe_range_m) {
    return false;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : band.corners_enu) centre += 0.25 * c;
  const int cam = rig_->stereo_pairs.front()[0];
  const Eigen::Vector3d p_cam =
      T_cam_body_[cam] * (pose.q_enu_body.conjugate() * (centre - pose.p_enu));
  Eigen::Vector2d uv;
  const Camera& camera = rig_->cameras[cam].camera;
  return p_cam.z() > 1.0 && camera.Project(p_cam, &uv) && camera.IsInImage(uv);
}

bool Visibility::BandVisible(const Pose& pose, const IndexedBand& band) const {
  if (!enabled()) return false;
  if ((band.centre_enu - pose.p_enu.head<2>()).norm() > range_m_) {
    return false;
  }
  const Eigen::Matrix3d R_body_enu =
      pose.q_enu_body.toRotationMatrix().transpose();
  std::array<Eigen::Vector3d, 4> p_body;
  for (int k = 0; k < 4; ++k) {
    p_body[k] = R_body_enu * (band.corners_enu[k] - pose.p_enu);
  }
  for (const std::array<int, 2>& pair : rig_->stereo_pairs) {
    bool seen = true;
    for (int side = 0; side < 2 && seen; ++side) {
      const int cam = pair[side];
      const Camera& camera = rig_->cameras[cam].camera;
      for (int k = 0; k < 4 && seen; ++k) {
        const Eigen::Vector3d p_cam = T_cam_body_[cam] * p_body[k];
        Eigen::Vector2d uv;
        seen = p_cam.z() > 0.5 && camera.Project(p_cam, &uv) &&
               camera.IsInImage(uv, margin_px_);
      }
    }
    if (seen) return true;
  }
  return false;
}

Eval Evaluate(const MatchState& state, const Obs& obs,
              const PoseCorrection& c) {
  const MatchOptions& options = state.options;
  const RoadmarkIndex& index = state.index;
  Eval eval;
  const Eigen::Matrix2d R = Rotation2(c.heading_rad);
  const double tolerance = options.hit_tolerance_m;
  std::vector<Hit> candidates;
  std::vector<int> near;
  std::vector<Eigen::Vector2d> centres(obs.bands.size());
  for (size_t i = 0; i < obs.bands.size(); ++i) {
    const ObsBand& band = obs.bands[i];
    if (!band.usable) continue;
    std::array<Eigen::Vector2d, 4> w;
    for (int k = 0; k < 4; ++k)
      w[k] = R * band.q[k] + obs.vehicle + c.shift_enu_m;
    centres[i] = 0.25 * (w[0] + w[1] + w[2] + w[3]);
    index.BandsWithin(centres[i], tolerance, &near);
    for (int j : near) {
      const IndexedBand& db = index.bands()[j];
      double best = std::numeric_limits<double>::infinity();
      int best_perm = 0;
      for (int perm = 0; perm < 8; ++perm) {
        double worst = 0.0;
        for (int k = 0; k < 4 && worst < best; ++k) {
          worst = std::max(
              worst, (w[k] - db.corners_enu[PermutedCorner(perm, k)].head<2>())
                         .norm());
        }
        if (worst < best) {
          best = worst;
          best_perm = perm;
        }
      }
      if (best <= tolerance) {
        candidates.push_back({static_cast<int>(i), j, best_perm, best});
      }
    }
  }
  // One database band explains at most one observed band and vice versa.
  std::sort(
      candidates.begin(), candidates.end(),
      [](const Hit& a, const Hit& b) { return a.max_error_m < b.max_error_m; });
  std::set<int> used_rec;
  std::set<int> used_db;
  for (const Hit& h : candidates) {
    if (used_rec.count(h.rec) || used_db.count(h.db)) continue;
    used_rec.insert(h.rec);
    used_db.insert(h.db);
    eval.hits.push_back(h);
  }
  std::sort(eval.hits.begin(), eval.hits.end(),
            [](const Hit& a, const Hit& b) { return a.rec < b.rec; });
  for (size_t i = 0; i < obs.bands.size(); ++i) {
    if (!obs.bands[i].usable || used_rec.count(static_cast<int>(i))) continue;
    ClassifyUnexplained(index, centres[i], static_cast<int>(i), &eval);
  }
  if (state.visibility.enabled() && !eval.hits.empty()) {
    AddMissingBands(state, obs, c, used_db, &eval);
  }
  eval.score = static_cast<double>(eval.hits.size()) -
               options.missing_band_weight * eval.missing.size() -
               options.contradiction_weight * eval.contradictions.size() -
               options.unexplained_band_weight * eval.unexplained.size();
  return eval;
}

void Aggregate(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  const int n = static_cast<int>(state->obs.size());
  // Observations sorted by time, and a sliding window over them.
  std::vector<double> times(n);
  for (int k = 0; k < n; ++k) {
    times[k] = input.observations[state->by_time[k]].time_s;
  }
  for (int k = 0; k < n; ++k) {
    const int o = state->by_time[k];
    const double t = times[k];
    const auto low =
        std::lower_bound(times.begin(), times.end(), t - options.window_s) -
        times.begin();
    const auto high =
        std::upper_bound(times.begin(), times.end(), t + options.window_s) -
        times.begin();
    state->window[o] = {static_cast<int>(low), static_cast<int>(high)};
    for (Hypothesis& h : state->hypotheses[o]) {
      h.aggregated =
          WindowEvidence(*state, o, h.correction, h.correction, nullptr);
    }
  }
}

double WindowEvidence(const MatchState& state, int o, const PoseCorrection& c,
                      const PoseCorrection& placement,
                      std::map<int, Evidence>* units) {
  const MatchInput& input = state.input;
  const MatchOptions& options = state.options;
  const RoadmarkIndex& index = state.index;
  const double t = input.observations[o].time_s;
  std::map<int, Evidence> local;
  std::map<int, Evidence>& by_unit = units != nullptr ? *units : local;
  std::set<int> seen;                // database bands hit in the window
  std::map<int, int> missing_views;  // database band -> views missing it
  // Contradictions are strong only when two views show them: one view's
  // odd band (a reflection, a band of another crossing) must not decide.
  std::map<int, std::set<int>> contradicting_views;
  std::map<int, double> contradiction_strong;
  for (int m = state.window[o].first; m < state.window[o].second; ++m) {
    const int q = state.by_time[m];
    const Hypothesis* g =
        Supporting(state, q, c, input.observations[q].time_s - t);
    if (g == nullptr) continue;  // no band of q fits c: no information
    const Obs& obs = state.obs[q];
    // Evidence is strong only from a view whose own fit is this
    // correction: a view's best hypothesis merely within the window's
    // tolerance places its bands up to decimetres off, between the
    // database's bands, where they would read as contradictions.
    const bool agrees = CorrectionDistance(g->correction, c, obs.centroid_q) <=
                        kStrongAgreementM;
    auto unit_of = [&](int rec) {
      return units == nullptr
                 ? -1
                 : EndUnit(index, Apply(placement, obs.vehicle,
                                        obs.bands[rec].shape.centre));
    };
    for (const Hit& hit : g->eval.hits) {
      by_unit[unit_of(hit.rec)].weak += 1.0;
      seen.insert(hit.db);
    }
    // A band cut short (an occluder, the image border) is not a band of
    // its own where it lies: strong evidence takes whole bands only.
    auto whole = [&](int rec) {
      return g->main_crossing >= 0 &&
             std::abs(obs.bands[rec].shape.length_m -
                      index.crossings()[g->main_crossing].band_length_m) <=
                 options.max_length_difference_m;
    };
    const std::set<int> beyond_first(g->eval.beyond_first.begin(),
                                     g->eval.beyond_first.end());
    for (int rec : g->eval.unexplained) {
      Evidence& e = by_unit[unit_of(rec)];
      (agrees && whole(rec) && beyond_first.count(rec) ? e.strong : e.weak) -=
          options.unexplained_band_weight;
    }
    for (int rec : g->eval.contradictions) {
      const int unit = unit_of(rec);
      if (agrees && whole(rec)) {
        contradicting_views[unit].insert(q);
        contradiction_strong[unit] += options.contradiction_weight;
      } else {
        by_unit[unit].weak -= options.contradiction_weight;
      }
    }
    if (agrees) {
      for (int b : g->eval.missing) ++missing_views[b];
    }
    if (VLOG_IS_ON(3) && units != nullptr) {
      std::ostringstream line;
      line << "  view " << input.observations[q].exposure_id
           << (agrees ? " agrees" : " near") << ": hits";
      for (const Hit& hit : g->eval.hits) {
        line << " " << hit.rec << "->" << index.bands()[hit.db].band << "@"
             << unit_of(hit.rec);
      }
      line << "; unexplained";
      for (int rec : g->eval.unexplained) {
        line << " " << rec << "@" << unit_of(rec) << (whole(rec) ? "" : "(cut)")
             << (beyond_first.count(rec) ? "(beyond 1)" : "");
      }
      line << "; contradictions";
      for (int rec : g->eval.contradictions) line << " " << rec;
      line << "; missing";
      for (int b : g->eval.missing) line << " " << index.bands()[b].band;
      VLOG(3) << line.str();
    }
  }
  // A database band missed in some views but seen in another was hidden
  // (a parked vehicle) or missed by the detector: no evidence. One never
  // seen counts for at most max_missing_views views: views of one place are
  // not independent (an occluder hides it from every one of them).
  for (const auto& [unit, amount] : contradiction_strong) {
    Evidence& e = by_unit[unit];
    (contradicting_views[unit].size() >= 2 ? e.strong : e.weak) -= amount;
  }
  for (const auto& [b, views] : missing_views) {
    if (seen.count(b)) continue;
    by_unit[units == nullptr ? -1 : EndUnit(index, index.bands()[b].centre_enu)]
        .strong -= options.missing_band_weight *
                   std::min(views, options.max_missing_views);
  }
  double total = 0.0;
  for (const auto& [unit, value] : by_unit) total += value.weak + value.strong;
  return total;
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
