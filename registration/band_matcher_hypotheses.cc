// Step 1 of MatchBands (band_matcher_internal.h): the observations in the
// measured placement, and for each the hypotheses that one band paired
// with a database band of its shape seeds, refined on every band they
// explain.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "registration/band_matcher_internal.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace band_matcher_internal {
namespace {

// Least-squares 2D rigid transform b = R(angle) a + t (Umeyama without
// scale). Needs at least 2 distinct points.
struct Rigid2 {
  double angle = 0.0;
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
};
Rigid2 FitRigid2(const std::vector<Eigen::Vector2d>& a,
                 const std::vector<Eigen::Vector2d>& b) {
  Eigen::Vector2d ma = Eigen::Vector2d::Zero();
  Eigen::Vector2d mb = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= static_cast<double>(a.size());
  mb /= static_cast<double>(b.size());
  double sxx = 0.0;  // sum of dot products
  double sxy = 0.0;  // sum of cross products
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector2d da = a[i] - ma;
    const Eigen::Vector2d db = b[i] - mb;
    sxx += da.dot(db);
    sxy += da.x() * db.y() - da.y() * db.x();
  }
  Rigid2 fit;
  fit.angle = std::atan2(sxy, sxx);
  fit.t = mb - Rotation2(fit.angle) * ma;
  return fit;
}

std::vector<double> BorderMargins(const MatchInput& input) {
  // How close to the image border the reconstruction still delivers bands:
  // the observed corners projected into the cameras of their pair (body
  // frame, so no pose is needed).
  std::vector<double> margins;
  if (input.rig == nullptr) return margins;
  const Rig& rig = *input.rig;
  for (const CrossingObservation& obs : input.observations) {
    for (const ObservedBand& band : obs.bands) {
      if (band.pair < 0 ||
          band.pair >= static_cast<int>(rig.stereo_pairs.size())) {
        continue;
      }
      double closest = std::numeric_limits<double>::infinity();
      for (int cam : rig.stereo_pairs[band.pair]) {
        const Camera& camera = rig.cameras[cam].camera;
        const Eigen::Isometry3d T_cam_body =
            rig.cameras[cam].T_body_cam.inverse();
        for (const Eigen::Vector3d& p_body : band.p_body) {
          Eigen::Vector2d uv;
          if (!camera.Project(T_cam_body * p_body, &uv)) continue;
          closest = std::min({closest, uv.x() + 0.5, uv.y() + 0.5,
                              camera.width() - 0.5 - uv.x(),
                              camera.height() - 0.5 - uv.y()});
        }
      }
      if (std::isfinite(closest)) margins.push_back(closest);
    }
  }
  return margins;
}

// How far one database band's long axis may lie from its true direction:
// three standard deviations of the direction through the two end
// midpoints (each the mean of two corners of sd sigma_xy per axis), plus
// the reconstruction's own ~2 cm.
double BandAxisTolerance(const IndexedBand& db) {
  constexpr double kReconstructionSigmaM = 0.02;
  const double sigma = std::hypot(db.sigma_xy_m, kReconstructionSigmaM) /
                       std::max(db.length_m, 1.0);
  return 3.0 * sigma;
}

// The correction one band pair suggests, its rotation held within the
// heading gate: a rotation beyond it comes from the database band's
// corner errors, not from the trajectory, and the translation is then
// taken at the band's centre, where the rotation matters least.
PoseCorrection SeedCorrection(const ObsBand& band, const IndexedBand& db,
                              const Rigid2& fit, double max_angle,
                              const Eigen::Vector2d& vehicle) {
  PoseCorrection c{fit.angle, fit.t};
  if (std::abs(fit.angle) <= max_angle) return c;
  Eigen::Vector2d centre_q = Eigen::Vector2d::Zero();
  Eigen::Vector2d centre_db = Eigen::Vector2d::Zero();
  for (int k = 0; k < 4; ++k) {
    centre_q += 0.25 * band.q[k];
    centre_db += 0.25 * (db.corners_enu[k].head<2>() - vehicle);
  }
  c.heading_rad = std::clamp(fit.angle, -max_angle, max_angle);
  c.shift_enu_m = centre_db - Rotation2(c.heading_rad) * centre_q;
  return c;
}

// The corner order of database band `db` with the smallest rotation that
// fits `band`, rotations beyond band_max_angle excluded; *best_rms is its
// rms corner error (infinite when every order is excluded).
Rigid2 BestBandFit(const ObsBand& band, const IndexedBand& db,
                   const Eigen::Vector2d& vehicle, double band_max_angle,
                   double* best_rms) {
  Rigid2 best_fit;
  *best_rms = std::numeric_limits<double>::infinity();
  for (int perm = 0; perm < 8; ++perm) {
    std::vector<Eigen::Vector2d> a(4);
    std::vector<Eigen::Vector2d> b(4);
    for (int k = 0; k < 4; ++k) {
      a[k] = band.q[k];
      b[k] = db.corners_enu[PermutedCorner(perm, k)].head<2>() - vehicle;
    }
    const Rigid2 fit = FitRigid2(a, b);
    if (std::abs(fit.angle) > band_max_angle) continue;
    double sum = 0.0;
    for (int k = 0; k < 4; ++k) {
      sum += (Rotation2(fit.angle) * a[k] + fit.t - b[k]).squaredNorm();
    }
    const double rms = std::sqrt(sum / 4.0);
    if (rms < *best_rms) {
      *best_rms = rms;
      best_fit = fit;
    }
  }
  return best_fit;
}

// Adds `hypothesis` to `list`, or keeps the better of it and the one it
// duplicates.
void AddHypothesis(const Obs& obs, Hypothesis hypothesis,
                   std::vector<Hypothesis>* list) {
  const PoseCorrection& c = hypothesis.correction;
  bool merged = false;
  for (Hypothesis& h : *list) {
    if (CorrectionDistance(h.correction, c, obs.centroid_q) <
        kDuplicateHypothesisM) {
      if (hypothesis.eval.score > h.eval.score) h = hypothesis;
      merged = true;
      break;
    }
  }
  if (!merged) list->push_back(std::move(hypothesis));
}

// Whether correction `c` moves the observed crossing across the vehicle's
// track by no more than max_cross_track_m (always, when that is 0).
bool WithinCrossTrackGate(const MatchOptions& options, const Obs& obs,
                          const PoseCorrection& c) {
  if (options.max_cross_track_m <= 0.0) return true;
  // Body y (right): across the track, the sign does not matter.
  const Eigen::Vector2d across =
      (obs.source->pose.q_enu_body * Eigen::Vector3d::UnitY()).head<2>();
  if (across.norm() < 1e-6) return true;
  const Eigen::Vector2d moved = Rotation2(c.heading_rad) * obs.centroid_q +
                                c.shift_enu_m - obs.centroid_q;
  return std::abs(moved.dot(across.normalized())) <= options.max_cross_track_m;
}

}  // namespace

void PrepareObservations(MatchState* state) {
  const MatchInput& input = state->input;
  const MatchOptions& options = state->options;
  std::vector<double> ranges;
  state->obs.resize(input.observations.size());
  for (size_t o = 0; o < state->obs.size(); ++o) {
    const CrossingObservation& source = input.observations[o];
    Obs& obs = state->obs[o];
    obs.source = &source;
    obs.vehicle = source.pose.p_enu.head<2>();
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const ObservedBand& band : source.bands) {
      ObsBand b;
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d p = source.pose.q_enu_body * band.p_body[k];
        b.q[k] = p.head<2>();
      }
      b.shape = ShapeOfBand(b.q);
      b.range_m = b.shape.centre.norm();
      b.usable = b.shape.length_m >= options.min_band_length_m &&
                 b.shape.length_m <= options.max_band_length_m &&
                 b.shape.width_m >= options.min_band_width_m &&
                 b.shape.width_m <= options.max_band_width_m;
      if (b.usable) {
        ++obs.usable;
        sum += b.shape.centre;
        ranges.push_back(b.range_m);
      }
      obs.bands.push_back(b);
    }
    if (obs.usable > 0) obs.centroid_q = sum / obs.usable;
    for (const ObsBand& b : obs.bands) {
      if (!b.usable) continue;
      for (const Eigen::Vector2d& q : b.q) {
        obs.radius_m = std::max(obs.radius_m, (q - obs.centroid_q).norm());
      }
    }
  }
  double range = options.visibility_range_m;
  if (range <= 0.0) range = Percentile(ranges, 0.9);
  double margin = options.visibility_margin_px;
  if (margin <= 0.0) {
    margin = std::max(5.0, Percentile(BorderMargins(input), 0.01)) +
             options.visibility_safety_px;
  }
  state->visibility = Visibility(input.rig, margin, range);
  VLOG(1) << "visibility: range " << range << " m, margin " << margin << " px";
  state->by_time.resize(state->obs.size());
  for (size_t o = 0; o < state->obs.size(); ++o)
    state->by_time[o] = static_cast<int>(o);
  std::stable_sort(
      state->by_time.begin(), state->by_time.end(), [&](int a, int b) {
        return input.observations[a].time_s < input.observations[b].time_s;
      });
}

double Gate(const MatchOptions& options, const Obs& obs) {
  return std::max(options.max_drift_m,
                  options.sd_gate_factor * obs.source->sd_horizontal_m);
}

PoseCorrection Refine(const MatchState& state, const Obs& obs, const Eval& eval,
                      const PoseCorrection& start) {
  const RoadmarkIndex& index = state.index;
  if (eval.hits.empty()) return start;
  std::vector<Eigen::Vector2d> a;
  std::vector<Eigen::Vector2d> b;
  // Implied bands' corners are extrapolated: fitted on only when fewer
  // than two held bands are hit.
  int held = 0;
  for (const Hit& h : eval.hits) held += index.bands()[h.db].implied ? 0 : 1;
  for (const Hit& h : eval.hits) {
    const IndexedBand& db = index.bands()[h.db];
    if (db.implied && held >= 2) continue;
    for (int k = 0; k < 4; ++k) {
      a.push_back(obs.bands[h.rec].q[k]);
      b.push_back(db.corners_enu[PermutedCorner(h.perm, k)].head<2>() -
                  obs.vehicle);
    }
  }
  const Rigid2 fit = FitRigid2(a, b);
  PoseCorrection c;
  c.heading_rad = fit.angle;
  c.shift_enu_m = fit.t;  // q_true = R q + t, so the shift is t itself
  return c;
}

void GenerateHypotheses(int o, MatchState* state) {
  const MatchOptions& options = state->options;
  const RoadmarkIndex& index = state->index;
  const Obs& obs = state->obs[o];
  std::vector<Hypothesis>& list = state->hypotheses[o];
  if (obs.usable == 0) return;
  const double gate = Gate(options, obs);
  const double lever = obs.centroid_q.norm() + obs.radius_m;
  const double radius =
      gate + obs.radius_m + options.max_heading_error_rad * lever;
  std::vector<int> candidates;
  index.BandsWithin(obs.vehicle + obs.centroid_q, radius, &candidates);
  state->candidate_bands[o] = static_cast<int>(candidates.size());
  const double max_angle = options.max_heading_error_rad + 0.02;
  for (size_t i = 0; i < obs.bands.size(); ++i) {
    const ObsBand& band = obs.bands[i];
    if (!band.usable) continue;
    for (int j : candidates) {
      const IndexedBand& db = index.bands()[j];
      if (std::abs(band.shape.length_m - db.length_m) >
              options.max_length_difference_m ||
          std::abs(band.shape.width_m - db.width_m) >
              options.max_width_difference_m) {
        continue;
      }
      // One band's direction is only as good as its corners: a database
      // band's long axis is off by about sigma_xy / length (5 cm on 3 m is
      // 1 degree), which the heading gate must not turn into a rejection
      // of the true correspondence.
      const double band_max_angle = max_angle + BandAxisTolerance(db);
      // Axes are directions up to sign: |sin| of the angle between them.
      const double sin_angle = std::abs(band.shape.axis.x() * db.axis_enu.y() -
                                        band.shape.axis.y() * db.axis_enu.x());
      if (sin_angle > std::sin(band_max_angle)) continue;
      double best_rms = 0.0;
      const Rigid2 best_fit =
          BestBandFit(band, db, obs.vehicle, band_max_angle, &best_rms);
      VLOG(4) << "exposure " << obs.source->exposure_id << " band " << i
              << " on database band " << db.band << ": rms " << best_rms
              << " shift " << best_fit.t.transpose() << " angle "
              << best_fit.angle;
      if (best_rms > options.hit_tolerance_m) continue;
      PoseCorrection c =
          SeedCorrection(band, db, best_fit, max_angle, obs.vehicle);
      if (c.shift_enu_m.norm() > gate) continue;
      bool explored = false;
      for (const Hypothesis& h : list) {
        if (CorrectionDistance(h.correction, c, band.shape.centre) <
            0.5 * options.hit_tolerance_m) {
          explored = true;
          break;
        }
      }
      if (explored) continue;
      Eval eval = Evaluate(*state, obs, c);
      for (int iteration = 0; iteration < 2 && !eval.hits.empty();
           ++iteration) {
        const PoseCorrection refined = Refine(*state, obs, eval, c);
        if (std::abs(refined.heading_rad) > max_angle ||
            refined.shift_enu_m.norm() > gate + options.hit_tolerance_m) {
          break;
        }
        c = refined;
        eval = Evaluate(*state, obs, c);
      }
      VLOG(4) << "  -> " << c.shift_enu_m.transpose() << " " << c.heading_rad
              << ": " << eval.hits.size() << " hits, own " << eval.score;
      if (eval.hits.empty() || !WithinCrossTrackGate(options, obs, c)) {
        continue;
      }
      Hypothesis hypothesis;
      hypothesis.correction = c;
      hypothesis.main_crossing = eval.MainCrossing(index);
      hypothesis.eval = std::move(eval);
      AddHypothesis(obs, std::move(hypothesis), &list);
    }
  }
}

}  // namespace band_matcher_internal
}  // namespace zebrageo
