#include "registration/band_matcher.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Two hypotheses of one observation closer than this are one hypothesis.
constexpr double kDuplicateHypothesisM = 0.1;
// Observations of one crossing further apart in time start a new pass.
constexpr double kPassGapFactor = 2.0;
// Evidence counts as strong only from a view whose own best hypothesis lies
// within this of the correction scored (see WindowEvidence).
constexpr double kStrongAgreementM = 0.1;
// A non-explained band this close (across) to a database band's centre
// line is that band seen partly (truncated, occluded): no evidence either way.
constexpr double kPartialBandAcrossM = 0.25;

Eigen::Matrix2d Rotation2(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(values.size() - 1,
                            static_cast<size_t>(p * (values.size() - 1) + 0.5));
  return values[i];
}

std::string Fixed(double value, int decimals) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(decimals);
  out << value;
  return out.str();
}

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

// Corner k of an observed band goes to database corner Corner(perm, k):
// 4 starting corners x 2 senses (the ring orders of the two may differ).
int PermutedCorner(int perm, int k) {
  const int start = perm % 4;
  return perm < 4 ? (start + k) % 4 : (start - k + 4) % 4;
}

// ---------------------------------------------------------------------------
// Observations, precomputed in the measured placement.

struct ObsBand {
  bool usable = false;
  std::array<Eigen::Vector2d, 4> q;  // measured ENU minus vehicle position
  BandShape shape;                   // of q (centre relative to the vehicle)
  double range_m = 0.0;
};

struct Obs {
  const CrossingObservation* source = nullptr;
  Eigen::Vector2d vehicle = Eigen::Vector2d::Zero();
  std::vector<ObsBand> bands;
  Eigen::Vector2d centroid_q = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  int usable = 0;
};

// Where a correction moves a point q (relative to the vehicle).
Eigen::Vector2d Apply(const PoseCorrection& c, const Eigen::Vector2d& vehicle,
                      const Eigen::Vector2d& q) {
  return Rotation2(c.heading_rad) * q + vehicle + c.shift_enu_m;
}

// How far apart two corrections place an observation's bands.
double CorrectionDistance(const PoseCorrection& a, const PoseCorrection& b,
                          const Eigen::Vector2d& centroid_q) {
  return ((Rotation2(a.heading_rad) - Rotation2(b.heading_rad)) * centroid_q +
          a.shift_enu_m - b.shift_enu_m)
      .norm();
}

// ---------------------------------------------------------------------------
// Evaluation of one correction for one observation.

struct Hit {
  int rec = 0;
  int db = 0;
  int perm = 0;
  double max_error_m = 0.0;
};

struct Eval {
  std::vector<Hit> hits;
  std::vector<int> missing;         // database bands
  std::vector<int> contradictions;  // observed bands
  std::vector<int> unexplained;     // observed bands
  // The unexplained bands lying beyond the crossing's band 1 (held or
  // implied): the database's numbering says the crossing ends there, so a
  // hypothesis that leaves a band there is contradicted, not merely short
  // of a band the database may have lost at its far end.
  std::vector<int> beyond_first;
  std::vector<int> partial;  // observed bands
  double score = 0.0;

  // The crossing most hits fall on, or -1.
  int MainCrossing(const RoadmarkIndex& index) const {
    std::map<int, int> count;
    for (const Hit& h : hits) ++count[index.bands()[h.db].crossing];
    int best = -1;
    int best_count = 0;
    for (const auto& [crossing, n] : count) {
      if (n > best_count) {
        best = crossing;
        best_count = n;
      }
    }
    return best;
  }
};

struct Hypothesis {
  PoseCorrection correction;
  Eval eval;
  int main_crossing = -1;
  // Over the window:
  double aggregated = 0.0;
};

// Visibility of a database band from a corrected pose, through the rig.
class Visibility {
 public:
  Visibility(const Rig* rig, double margin_px, double range_m)
      : rig_(rig), margin_px_(margin_px), range_m_(range_m) {
    if (rig_ == nullptr) return;
    for (const RigCamera& camera : rig_->cameras) {
      T_cam_body_.push_back(camera.T_body_cam.inverse());
    }
  }
  bool enabled() const { return rig_ != nullptr && range_m_ > 0.0; }
  double range_m() const { return range_m_; }

  // Whether the image probe may look for `band` from `pose`: its centre
  // in front of the left camera of the first stereo pair (the probe's),
  // inside that image, within probe_range_m. The probe itself then says
  // whether enough of the band is in the image to tell paint from asphalt
  // (PaintProbeOptions::min_inside_share): bare road seen where a band is
  // predicted is evidence whether or not the reconstruction could have
  // delivered that band whole.
  bool ProbeMayLook(const Pose& pose, const IndexedBand& band,
                    double probe_range_m) const {
    if (rig_ == nullptr || rig_->stereo_pairs.empty()) return false;
    if ((band.centre_enu - pose.p_enu.head<2>()).norm() > probe_range_m) {
      return false;
    }
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& c : band.corners_enu) centre += 0.25 * c;
    const int cam = rig_->stereo_pairs.front()[0];
    const Eigen::Vector3d p_cam =
        T_cam_body_[cam] *
        (pose.q_enu_body.conjugate() * (centre - pose.p_enu));
    Eigen::Vector2d uv;
    const Camera& camera = rig_->cameras[cam].camera;
    return p_cam.z() > 1.0 && camera.Project(p_cam, &uv) &&
           camera.IsInImage(uv);
  }

  bool BandVisible(const Pose& pose, const IndexedBand& band) const {
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

 private:
  const Rig* rig_;
  double margin_px_;
  double range_m_;
  std::vector<Eigen::Isometry3d> T_cam_body_;
};

Pose CorrectedPose(const Pose& measured, const PoseCorrection& c) {
  Pose pose;
  pose.q_enu_body = Eigen::Quaterniond(Eigen::AngleAxisd(
                        c.heading_rad, Eigen::Vector3d::UnitZ())) *
                    measured.q_enu_body;
  pose.p_enu = measured.p_enu;
  pose.p_enu.head<2>() += c.shift_enu_m;
  return pose;
}

// Passes: runs of matched observations of one crossing.
struct Pass {
  int crossing = -1;
  std::vector<int> obs;
  double t0 = 0.0;
  double t1 = 0.0;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();  // median
  bool rejected = false;
};

class Matcher {
 public:
  Matcher(const MatchInput& input, const MatchOptions& options)
      : input_(input),
        options_(options),
        index_(*input.index),
        visibility_(nullptr, 0.0, 0.0) {}

  MatchResult Run(const std::function<void(int, int)>& progress);

 private:
  // Stage 0.
  void PrepareObservations();
  // Stage 1.
  Eval Evaluate(const Obs& obs, const PoseCorrection& c) const;
  // Whether a band centred at `centre` lies one or two periods beyond the
  // crossing's band 1 (held or implied by the numbering).
  bool BeyondBandOne(const IndexedCrossing& crossing,
                     const Eigen::Vector2d& centre) const;
  void ClassifyUnexplained(const Eigen::Vector2d& centre, int rec,
                           Eval* eval) const;
  PoseCorrection Refine(const Obs& obs, const Eval& eval,
                        const PoseCorrection& start) const;
  void GenerateHypotheses(int o);
  double Gate(const Obs& obs) const;
  std::vector<double> BorderMargins() const;
  // Stage 2, 3.
  void Aggregate();
  void DecideAlone(int o);
  // Stage 4.
  std::vector<Pass> BuildPasses() const;
  static double PassGap(const Pass& a, const Pass& b);
  // The matches of accepted observation `o` after refining its correction
  // on its own bands: the bands whose every corner fits to
  // vertex_tolerance_m.
  std::vector<VertexMatch> RefinedMatches(int o, PoseCorrection* correction,
                                          std::vector<int>* bands,
                                          double* rms_m) const;
  // Refuses `o` when fewer than min_hit_bands bands fit after refinement
  // (a hypothesis that fits only loosely); true when refused.
  bool RefuseUnrefined(int o);
  void CheckContinuity();
  void ResolveFromNeighbours();
  void DetectShiftedCrossings();
  // Stage 5.
  void EmitMatches(int o);
  void DetectFaults();
  void Finish(MatchResult* result);

  double Tolerance(double dt) const {
    return options_.same_correction_tolerance_m +
           options_.drift_rate_m_per_s * std::abs(dt);
  }
  std::string DescribeAlternative(const Obs& obs, const Hypothesis& best,
                                  const Hypothesis& other) const;

  const MatchInput& input_;
  const MatchOptions& options_;
  const RoadmarkIndex& index_;
  Visibility visibility_;

  std::vector<Obs> obs_;
  std::vector<std::vector<Hypothesis>> hypotheses_;
  std::vector<int> candidate_bands_;  // per observation
  std::vector<int> chosen_;           // hypothesis index or -1
  std::vector<bool> accepted_;
  std::vector<bool> ambiguous_;
  std::set<int> inconsistent_;  // refused by the continuity check
  std::vector<ObservationEvidence> evidence_;
  std::vector<VertexMatch> matches_;
  std::vector<DatabaseFault> faults_;
  std::vector<int> by_time_;  // observation indices sorted by time
  // Per observation: [first, last) positions in by_time_ of its window.
  std::vector<std::pair<int, int>> window_;

  // Where each piece of evidence of `eval` lies: (crossing * 2 + end) with
  // end 0 for the half of the crossing holding its first band, 1 for the
  // other; -1 away from every crossing. Observed bands are placed with
  // `placement` so that two hypotheses attribute them alike.
  // Score of correction `c` over the window of observation `o`: per view
  // the hits and unexplained bands of the view's own hypothesis at `c`,
  // plus the missing database bands counted per band (see the .cc). With
  // `units`, the evidence by crossing end (bands placed with `placement`).
  // Evidence of one crossing end (or of nothing, unit -1): `strong` is
  // what neither a database missing an end band nor an end band hidden in
  // the images can fake (bare road where paint is predicted, a band in a
  // gap of the crossing or beyond its band 1); `weak` is the rest (bands
  // explained, bands beyond the crossing's last band).
  struct Evidence {
    double weak = 0.0;
    double strong = 0.0;
  };
  double WindowEvidence(int o, const PoseCorrection& c,
                        const PoseCorrection& placement,
                        std::map<int, Evidence>* units) const;
  int EndUnit(const Eigen::Vector2d& p_enu) const;
  // The best-scoring hypothesis of observation `other` within the window
  // tolerance of `c`, or null.
  const Hypothesis* Supporting(int other, const PoseCorrection& c,
                               double dt) const;
  // Aggregated margin of `best` over `other` after discarding the evidence
  // of the one crossing end that favours `best` most: a database fault at
  // one end (a band missing on either side) must not decide the offset.
  struct Margin {
    double raw = 0.0;        // aggregated score difference
    double both_ends = 0.0;  // without the evidence of the stronger end
    double strong = 0.0;     // of the strong evidence alone
  };
  Margin MarginOver(int o, const Hypothesis& best,
                    const Hypothesis& other) const;
};

void Matcher::PrepareObservations() {
  std::vector<double> ranges;
  obs_.resize(input_.observations.size());
  for (size_t o = 0; o < obs_.size(); ++o) {
    const CrossingObservation& source = input_.observations[o];
    Obs& obs = obs_[o];
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
      b.usable = b.shape.length_m >= options_.min_band_length_m &&
                 b.shape.length_m <= options_.max_band_length_m &&
                 b.shape.width_m >= options_.min_band_width_m &&
                 b.shape.width_m <= options_.max_band_width_m;
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
  double range = options_.visibility_range_m;
  if (range <= 0.0) range = Percentile(ranges, 0.9);
  double margin = options_.visibility_margin_px;
  if (margin <= 0.0) {
    margin = std::max(5.0, Percentile(BorderMargins(), 0.01)) +
             options_.visibility_safety_px;
  }
  visibility_ = Visibility(input_.rig, margin, range);
  VLOG(1) << "visibility: range " << range << " m, margin " << margin << " px";
  by_time_.resize(obs_.size());
  for (size_t o = 0; o < obs_.size(); ++o) by_time_[o] = static_cast<int>(o);
  std::stable_sort(by_time_.begin(), by_time_.end(), [&](int a, int b) {
    return input_.observations[a].time_s < input_.observations[b].time_s;
  });
}

std::vector<double> Matcher::BorderMargins() const {
  // How close to the image border the reconstruction still delivers bands:
  // the observed corners projected into the cameras of their pair (body
  // frame, so no pose is needed).
  std::vector<double> margins;
  if (input_.rig == nullptr) return margins;
  const Rig& rig = *input_.rig;
  for (const CrossingObservation& obs : input_.observations) {
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

double Matcher::Gate(const Obs& obs) const {
  return std::max(options_.max_drift_m,
                  options_.sd_gate_factor * obs.source->sd_horizontal_m);
}

void Matcher::ClassifyUnexplained(const Eigen::Vector2d& centre, int rec,
                                  Eval* eval) const {
  std::vector<int> near;
  index_.BandsWithin(centre, 1.5, &near);
  std::set<int> crossings;
  for (int b : near) crossings.insert(index_.bands()[b].crossing);
  bool contradiction = false;
  for (int c : crossings) {
    const IndexedCrossing& crossing = index_.crossings()[c];
    const Eigen::Vector2d p = crossing.ToCrossing(centre);
    double nearest_across = std::numeric_limits<double>::infinity();
    double nearest_along = 0.0;
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    for (int b : crossing.bands) {
      const Eigen::Vector2d pb =
          crossing.ToCrossing(index_.bands()[b].centre_enu);
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
    if (BeyondBandOne(index_.crossings()[c], centre)) {
      eval->beyond_first.push_back(rec);
      break;
    }
  }
}

bool Matcher::BeyondBandOne(const IndexedCrossing& crossing,
                            const Eigen::Vector2d& centre) const {
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

Eval Matcher::Evaluate(const Obs& obs, const PoseCorrection& c) const {
  Eval eval;
  const Eigen::Matrix2d R = Rotation2(c.heading_rad);
  const double tolerance = options_.hit_tolerance_m;
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
    index_.BandsWithin(centres[i], tolerance, &near);
    for (int j : near) {
      const IndexedBand& db = index_.bands()[j];
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
    ClassifyUnexplained(centres[i], static_cast<int>(i), &eval);
  }
  if (visibility_.enabled() && !eval.hits.empty()) {
    std::set<int> crossings;
    for (const Hit& h : eval.hits) {
      crossings.insert(index_.bands()[h.db].crossing);
    }
    const Pose pose = CorrectedPose(obs.source->pose, c);
    std::vector<BandCornersEnu> seen;
    if (input_.paint_probe) {
      for (const Hit& h : eval.hits)
        seen.push_back(index_.bands()[h.db].corners_enu);
    }
    for (int crossing : crossings) {
      std::vector<int> predicted = index_.crossings()[crossing].bands;
      const std::vector<int>& implied =
          index_.crossings()[crossing].implied_bands;
      predicted.insert(predicted.end(), implied.begin(), implied.end());
      for (int b : predicted) {
        if (used_db.count(b)) continue;
        const bool may_look =
            input_.paint_probe
                ? visibility_.ProbeMayLook(pose, index_.bands()[b],
                                           options_.probe_range_m)
                : visibility_.BandVisible(pose, index_.bands()[b]);
        if (!may_look) continue;
        // A band the reconstruction missed (hidden, worn, lost at range) is
        // no evidence; bare road where the hypothesis puts paint is.
        if (input_.paint_probe &&
            input_.paint_probe(obs.source->exposure_id, pose,
                               index_.bands()[b].corners_enu,
                               seen) != PaintEvidence::kBareRoad) {
          continue;
        }
        eval.missing.push_back(b);
      }
    }
  }
  eval.score = static_cast<double>(eval.hits.size()) -
               options_.missing_band_weight * eval.missing.size() -
               options_.contradiction_weight * eval.contradictions.size() -
               options_.unexplained_band_weight * eval.unexplained.size();
  return eval;
}

PoseCorrection Matcher::Refine(const Obs& obs, const Eval& eval,
                               const PoseCorrection& start) const {
  if (eval.hits.empty()) return start;
  std::vector<Eigen::Vector2d> a;
  std::vector<Eigen::Vector2d> b;
  // Implied bands' corners are extrapolated: fitted on only when fewer
  // than two held bands are hit.
  int held = 0;
  for (const Hit& h : eval.hits) held += index_.bands()[h.db].implied ? 0 : 1;
  for (const Hit& h : eval.hits) {
    const IndexedBand& db = index_.bands()[h.db];
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

namespace {

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

}  // namespace

void Matcher::GenerateHypotheses(int o) {
  const Obs& obs = obs_[o];
  std::vector<Hypothesis>& list = hypotheses_[o];
  if (obs.usable == 0) return;
  const double gate = Gate(obs);
  const double lever = obs.centroid_q.norm() + obs.radius_m;
  const double radius =
      gate + obs.radius_m + options_.max_heading_error_rad * lever;
  std::vector<int> candidates;
  index_.BandsWithin(obs.vehicle + obs.centroid_q, radius, &candidates);
  candidate_bands_[o] = static_cast<int>(candidates.size());
  const double max_angle = options_.max_heading_error_rad + 0.02;
  for (size_t i = 0; i < obs.bands.size(); ++i) {
    const ObsBand& band = obs.bands[i];
    if (!band.usable) continue;
    for (int j : candidates) {
      const IndexedBand& db = index_.bands()[j];
      if (std::abs(band.shape.length_m - db.length_m) >
              options_.max_length_difference_m ||
          std::abs(band.shape.width_m - db.width_m) >
              options_.max_width_difference_m) {
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
      // The corner order with the smallest rotation that fits.
      Rigid2 best_fit;
      double best_rms = std::numeric_limits<double>::infinity();
      for (int perm = 0; perm < 8; ++perm) {
        std::vector<Eigen::Vector2d> a(4);
        std::vector<Eigen::Vector2d> b(4);
        for (int k = 0; k < 4; ++k) {
          a[k] = band.q[k];
          b[k] =
              db.corners_enu[PermutedCorner(perm, k)].head<2>() - obs.vehicle;
        }
        const Rigid2 fit = FitRigid2(a, b);
        if (std::abs(fit.angle) > band_max_angle) continue;
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) {
          sum += (Rotation2(fit.angle) * a[k] + fit.t - b[k]).squaredNorm();
        }
        const double rms = std::sqrt(sum / 4.0);
        if (rms < best_rms) {
          best_rms = rms;
          best_fit = fit;
        }
      }
      VLOG(4) << "exposure " << obs.source->exposure_id << " band " << i
              << " on database band " << db.band << ": rms " << best_rms
              << " shift " << best_fit.t.transpose() << " angle "
              << best_fit.angle;
      if (best_rms > options_.hit_tolerance_m) continue;
      PoseCorrection c =
          SeedCorrection(band, db, best_fit, max_angle, obs.vehicle);
      if (c.shift_enu_m.norm() > gate) continue;
      bool explored = false;
      for (const Hypothesis& h : list) {
        if (CorrectionDistance(h.correction, c, band.shape.centre) <
            0.5 * options_.hit_tolerance_m) {
          explored = true;
          break;
        }
      }
      if (explored) continue;
      Eval eval = Evaluate(obs, c);
      for (int iteration = 0; iteration < 2 && !eval.hits.empty();
           ++iteration) {
        const PoseCorrection refined = Refine(obs, eval, c);
        if (std::abs(refined.heading_rad) > max_angle ||
            refined.shift_enu_m.norm() > gate + options_.hit_tolerance_m) {
          break;
        }
        c = refined;
        eval = Evaluate(obs, c);
      }
      VLOG(4) << "  -> " << c.shift_enu_m.transpose() << " " << c.heading_rad
              << ": " << eval.hits.size() << " hits, own " << eval.score;
      if (eval.hits.empty()) continue;
      Hypothesis hypothesis;
      hypothesis.correction = c;
      hypothesis.main_crossing = eval.MainCrossing(index_);
      hypothesis.eval = std::move(eval);
      bool merged = false;
      for (Hypothesis& h : list) {
        if (CorrectionDistance(h.correction, c, obs.centroid_q) <
            kDuplicateHypothesisM) {
          if (hypothesis.eval.score > h.eval.score) h = hypothesis;
          merged = true;
          break;
        }
      }
      if (!merged) list.push_back(std::move(hypothesis));
    }
  }
}

void Matcher::Aggregate() {
  const int n = static_cast<int>(obs_.size());
  // Observations sorted by time, and a sliding window over them.
  std::vector<double> times(n);
  for (int k = 0; k < n; ++k) {
    times[k] = input_.observations[by_time_[k]].time_s;
  }
  for (int k = 0; k < n; ++k) {
    const int o = by_time_[k];
    const double t = times[k];
    const auto low =
        std::lower_bound(times.begin(), times.end(), t - options_.window_s) -
        times.begin();
    const auto high =
        std::upper_bound(times.begin(), times.end(), t + options_.window_s) -
        times.begin();
    window_[o] = {static_cast<int>(low), static_cast<int>(high)};
    for (Hypothesis& h : hypotheses_[o]) {
      h.aggregated = WindowEvidence(o, h.correction, h.correction, nullptr);
    }
  }
}

double Matcher::WindowEvidence(int o, const PoseCorrection& c,
                               const PoseCorrection& placement,
                               std::map<int, Evidence>* units) const {
  const double t = input_.observations[o].time_s;
  std::map<int, Evidence> local;
  std::map<int, Evidence>& by_unit = units != nullptr ? *units : local;
  std::set<int> seen;                // database bands hit in the window
  std::map<int, int> missing_views;  // database band -> views missing it
  // Contradictions are strong only when two views show them: one view's
  // odd band (a reflection, a band of another crossing) must not decide.
  std::map<int, std::set<int>> contradicting_views;
  std::map<int, double> contradiction_strong;
  for (int m = window_[o].first; m < window_[o].second; ++m) {
    const int q = by_time_[m];
    const Hypothesis* g = Supporting(q, c, input_.observations[q].time_s - t);
    if (g == nullptr) continue;  // no band of q fits c: no information
    const Obs& obs = obs_[q];
    // Evidence is strong only from a view whose own fit is this
    // correction: a view's best hypothesis merely within the window's
    // tolerance places its bands up to decimetres off, between the
    // database's bands, where they would read as contradictions.
    const bool agrees = CorrectionDistance(g->correction, c, obs.centroid_q) <=
                        kStrongAgreementM;
    auto unit_of = [&](int rec) {
      return units == nullptr ? -1
                              : EndUnit(Apply(placement, obs.vehicle,
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
                      index_.crossings()[g->main_crossing].band_length_m) <=
                 options_.max_length_difference_m;
    };
    const std::set<int> beyond_first(g->eval.beyond_first.begin(),
                                     g->eval.beyond_first.end());
    for (int rec : g->eval.unexplained) {
      Evidence& e = by_unit[unit_of(rec)];
      (agrees && whole(rec) && beyond_first.count(rec) ? e.strong : e.weak) -=
          options_.unexplained_band_weight;
    }
    for (int rec : g->eval.contradictions) {
      const int unit = unit_of(rec);
      if (agrees && whole(rec)) {
        contradicting_views[unit].insert(q);
        contradiction_strong[unit] += options_.contradiction_weight;
      } else {
        by_unit[unit].weak -= options_.contradiction_weight;
      }
    }
    if (agrees) {
      for (int b : g->eval.missing) ++missing_views[b];
    }
    if (VLOG_IS_ON(3) && units != nullptr) {
      std::ostringstream line;
      line << "  view " << input_.observations[q].exposure_id
           << (agrees ? " agrees" : " near") << ": hits";
      for (const Hit& hit : g->eval.hits) {
        line << " " << hit.rec << "->" << index_.bands()[hit.db].band << "@"
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
      for (int b : g->eval.missing) line << " " << index_.bands()[b].band;
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
    by_unit[units == nullptr ? -1 : EndUnit(index_.bands()[b].centre_enu)]
        .strong -= options_.missing_band_weight *
                   std::min(views, options_.max_missing_views);
  }
  double total = 0.0;
  for (const auto& [unit, value] : by_unit) total += value.weak + value.strong;
  return total;
}

int Matcher::EndUnit(const Eigen::Vector2d& p_enu) const {
  const int nearest = index_.NearestBand(p_enu);
  if (nearest < 0) return -1;
  const IndexedBand& band = index_.bands()[nearest];
  const IndexedCrossing& crossing = index_.crossings()[band.crossing];
  if ((p_enu - crossing.centre_enu).norm() > crossing.radius_m + 2.0) {
    return -1;
  }
  const double y = crossing.ToCrossing(p_enu).y();
  const double mid = 0.5 * (crossing.ToCrossing(crossing.first_end_enu).y() +
                            crossing.ToCrossing(crossing.last_end_enu).y());
  return 2 * band.crossing + (y <= mid ? 0 : 1);
}

const Hypothesis* Matcher::Supporting(int other, const PoseCorrection& c,
                                      double dt) const {
  const double tolerance = Tolerance(dt);
  const Hypothesis* best = nullptr;
  for (const Hypothesis& g : hypotheses_[other]) {
    if (CorrectionDistance(g.correction, c, obs_[other].centroid_q) >
        tolerance) {
      continue;
    }
    if (best == nullptr || g.eval.score > best->eval.score) best = &g;
  }
  return best;
}

Matcher::Margin Matcher::MarginOver(int o, const Hypothesis& best,
                                    const Hypothesis& other) const {
  // Both attributed with the best's placement, so that a band counts at the
  // same end under both hypotheses.
  std::map<int, Evidence> mine;
  std::map<int, Evidence> theirs;
  const double total =
      WindowEvidence(o, best.correction, best.correction, &mine) -
      WindowEvidence(o, other.correction, best.correction, &theirs);
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
          << input_.observations[o].exposure_id << "): " << total
          << ", both ends " << total - discount << ", strong " << strong
          << " against " << DescribeAlternative(obs_[o], best, other);
  return {total, total - discount, strong};
}

std::string Matcher::DescribeAlternative(const Obs& obs, const Hypothesis& best,
                                         const Hypothesis& other) const {
  if (other.main_crossing != best.main_crossing || best.main_crossing < 0) {
    const std::string id =
        other.main_crossing >= 0
            ? index_.crossings()[other.main_crossing].crossing_id
            : std::string("?");
    return "crossing " + id + " also fits";
  }
  const IndexedCrossing& crossing = index_.crossings()[best.main_crossing];
  const Eigen::Vector2d delta =
      Apply(other.correction, obs.vehicle, obs.centroid_q) -
      Apply(best.correction, obs.vehicle, obs.centroid_q);
  const double across = delta.dot(crossing.across_axis);
  const double bands =
      crossing.spacing_m > 0.0 ? across / crossing.spacing_m : 0.0;
  std::ostringstream out;
  out << "band offset " << (bands >= 0 ? "+" : "") << Fixed(bands, 1) << " ("
      << Fixed(delta.norm(), 2) << " m)";
  return out.str();
}

void Matcher::DecideAlone(int o) {
  const Obs& obs = obs_[o];
  ObservationEvidence& ev = evidence_[o];
  const std::vector<Hypothesis>& list = hypotheses_[o];
  ev.hypotheses = static_cast<int>(list.size());
  ev.candidate_db_bands = candidate_bands_[o];
  if (obs.usable == 0) {
    ev.decision = Decision::kNoCandidate;
    ev.reason = obs.bands.empty()
                    ? "no bands"
                    : "no observed band has a zebra band's shape (lane "
                      "marks or false detections?)";
    return;
  }
  if (list.empty()) {
    ev.decision = Decision::kNoCandidate;
    const std::string what =
        obs.usable == 1 ? "a false detection or a crossing missing from the "
                          "database?"
                        : "crossing missing from the database?";
    ev.reason =
        candidate_bands_[o] == 0
            ? "no database band within the " + Fixed(Gate(obs), 1) +
                  " m drift gate: " + what
            : std::to_string(candidate_bands_[o]) +
                  " database bands within the drift gate but none fits the "
                  "observed bands' shape: " +
                  what;
    return;
  }
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
  const Hypothesis& h = list[best];
  chosen_[o] = best;
  ev.hits = static_cast<int>(h.eval.hits.size());
  ev.missing = static_cast<int>(h.eval.missing.size());
  ev.contradictions = static_cast<int>(h.eval.contradictions.size());
  ev.unexplained = static_cast<int>(h.eval.unexplained.size());
  ev.own_score = h.eval.score;
  ev.aggregated_score = h.aggregated;
  ev.correction = h.correction;
  if (h.main_crossing >= 0) {
    ev.crossing_id = index_.crossings()[h.main_crossing].crossing_id;
  }
  // Every distinct alternative (another band offset, another crossing)
  // must lose by min_margin; with require_both_ends, even without the
  // evidence of the crossing end that favours the best most. The runner-up
  // reported is the closest call.
  const double distinct = 2.0 * options_.same_correction_tolerance_m;
  int runner = -1;
  double margin = std::numeric_limits<double>::infinity();
  double both_ends = std::numeric_limits<double>::infinity();
  // The band offset of the same crossing beaten by the least strong
  // evidence (bare road where it puts paint, a band where it has a gap or
  // nothing before band 1), and which it is.
  double one_end_strong = std::numeric_limits<double>::infinity();
  int one_end_runner = -1;
  for (size_t k = 0; k < list.size(); ++k) {
    VLOG(3) << "hypothesis " << k << " of exposure "
            << input_.observations[o].exposure_id << ": own "
            << list[k].eval.score << ", aggregated " << list[k].aggregated
            << ", shift " << list[k].correction.shift_enu_m.transpose();
    if (static_cast<int>(k) == best) continue;
    if (CorrectionDistance(list[k].correction, h.correction, obs.centroid_q) <
        distinct) {
      continue;
    }
    const Margin m = MarginOver(o, h, list[k]);
    const double deciding = options_.require_both_ends ? m.both_ends : m.raw;
    if (deciding < (options_.require_both_ends ? both_ends : margin)) {
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
  }
  if (runner >= 0) {
    const Hypothesis& r = list[runner];
    ev.has_runner_up = true;
    ev.runner_up_score = r.aggregated;
    ev.runner_up = DescribeAlternative(obs, h, r);
  }
  const double robust_margin = options_.require_both_ends ? both_ends : margin;
  ev.robust_margin = std::isfinite(robust_margin) ? robust_margin : 0.0;
  ev.both_ends_margin = std::isfinite(both_ends) ? both_ends : 0.0;
  ev.decision = Decision::kRefused;
  if (ev.hits < options_.min_hit_bands) {
    ev.reason = "only " + std::to_string(ev.hits) +
                " band(s) explained (min_hit_bands = " +
                std::to_string(options_.min_hit_bands) + ")";
    ambiguous_[o] = false;
    return;
  }
  if (ev.contradictions > 0) {
    ev.reason = "the best fit leaves " + std::to_string(ev.contradictions) +
                " observed band(s) in gaps of crossing " + ev.crossing_id;
    return;
  }
  if (robust_margin < options_.min_margin) {
    ambiguous_[o] = true;
    ev.reason = "ambiguous: " + ev.runner_up + " scores " +
                Fixed(ev.runner_up_score, 2) + " against " +
                Fixed(ev.aggregated_score, 2) + " (margin " +
                Fixed(robust_margin, 2) + " < " +
                Fixed(options_.min_margin, 1) + ")";
    if (h.main_crossing >= 0) {
      const IndexedCrossing& crossing = index_.crossings()[h.main_crossing];
      bool end_seen = false;
      for (const Hit& hit : h.eval.hits) {
        const int band = index_.bands()[hit.db].band;
        end_seen = end_seen || band == crossing.first_band ||
                   band == crossing.last_band;
      }
      if (!end_seen) ev.reason += "; only interior bands seen";
    }
    return;
  }
  if (one_end_runner >= 0 && one_end_strong < options_.min_strong_margin) {
    ambiguous_[o] = true;
    ev.reason = "ambiguous: decided against " +
                DescribeAlternative(obs, h, list[one_end_runner]) +
                " by band counts alone (evidence a database missing an "
                "end band, or an end band hidden in the images, cannot "
                "fake: " +
                Fixed(std::max(0.0, one_end_strong), 2) + " < " +
                Fixed(options_.min_strong_margin, 1) + ")";
    return;
  }
  accepted_[o] = true;
  ev.decision = Decision::kMatched;
  std::ostringstream reason;
  reason << ev.hits << " bands fit crossing " << ev.crossing_id << "; score "
         << Fixed(ev.aggregated_score, 1) << " over +-"
         << Fixed(options_.window_s, 0) << " s";
  if (runner >= 0) {
    reason << "; next " << ev.runner_up << " " << Fixed(ev.runner_up_score, 1);
    if (both_ends < options_.min_margin) {
      // Said plainly: decided at one end, by what a database fault there
      // cannot fake (bare road where the alternative puts paint, a band
      // beyond band 1).
      reason << "; decided at one end of the crossing, by what the images "
                "show there";
    }
  } else {
    reason << "; no alternative";
  }
  ev.reason = reason.str();
}

double MedianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

std::vector<Pass> Matcher::BuildPasses() const {
  std::map<int, std::vector<int>> by_crossing;
  for (int o : by_time_) {
    if (accepted_[o]) {
      by_crossing[hypotheses_[o][chosen_[o]].main_crossing].push_back(o);
    }
  }
  std::vector<Pass> passes;
  for (const auto& [crossing, list] : by_crossing) {
    for (int o : list) {
      const double t = input_.observations[o].time_s;
      if (passes.empty() || passes.back().crossing != crossing ||
          t - passes.back().t1 > kPassGapFactor * options_.window_s) {
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
      x.push_back(hypotheses_[o][chosen_[o]].correction.shift_enu_m.x());
      y.push_back(hypotheses_[o][chosen_[o]].correction.shift_enu_m.y());
    }
    pass.shift = Eigen::Vector2d(MedianOf(x), MedianOf(y));
  }
  return passes;
}

double Matcher::PassGap(const Pass& a, const Pass& b) {
  return std::max(0.0, std::max(a.t0, b.t0) - std::min(a.t1, b.t1));
}

void Matcher::CheckContinuity() {
  std::vector<Pass> passes = BuildPasses();
  auto gap = [](const Pass& a, const Pass& b) { return PassGap(a, b); };
  auto consistent = [&](const Pass& a, const Pass& b) {
    return (a.shift - b.shift).norm() <=
           options_.neighbour_tolerance_m +
               options_.max_drift_rate_m_per_s * gap(a, b);
  };
  // Only neighbours close enough in time to tell a one-band error (1 m)
  // from drift vote.
  auto informative = [&](const Pass& a, const Pass& b) {
    return gap(a, b) <= options_.neighbour_window_s &&
           options_.neighbour_tolerance_m +
                   options_.max_drift_rate_m_per_s * gap(a, b) <=
               options_.max_informative_tolerance_m;
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
        why << " " << index_.crossings()[passes[q].crossing].crossing_id << " ("
            << Fixed(passes[q].t0 - pass.t0, 1) << " s) implies a "
            << "correction " << Fixed((passes[q].shift - pass.shift).norm(), 2)
            << " m away";
      }
      for (int o : pass.obs) {
        accepted_[o] = false;
        evidence_[o].decision = Decision::kRefused;
        evidence_[o].reason = why.str();
        inconsistent_.insert(o);
      }
    }
  }
}

void Matcher::DetectShiftedCrossings() {
  std::vector<Pass> passes = BuildPasses();
  // Shifted (repainted) crossings: neighbours on both sides agree with each
  // other and predict a correction this crossing departs from.
  for (Pass& pass : passes) {
    if (pass.rejected) continue;
    const Pass* before = nullptr;
    const Pass* after = nullptr;
    for (const Pass& q : passes) {
      if (q.rejected || q.crossing == pass.crossing) continue;
      if (q.t1 < pass.t0 && pass.t0 - q.t1 <= options_.neighbour_window_s &&
          (before == nullptr || q.t1 > before->t1)) {
        before = &q;
      }
      if (q.t0 > pass.t1 && q.t0 - pass.t1 <= options_.neighbour_window_s &&
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
    const double allowed = options_.shifted_crossing_threshold_m + 0.01 * span +
                           neighbours_disagree;
    if (deviation <= allowed) continue;
    const IndexedCrossing& crossing = index_.crossings()[pass.crossing];
    DatabaseFault fault;
    fault.kind = FaultKind::kCrossingShifted;
    fault.crossing_id = crossing.crossing_id;
    fault.location_enu = crossing.centre_enu;
    fault.shift_m = deviation;
    fault.views = static_cast<int>(pass.obs.size());
    for (int o : pass.obs) {
      fault.exposure_ids.push_back(input_.observations[o].exposure_id);
    }
    fault.description =
        "crossing " + crossing.crossing_id + " implies a correction " +
        Fixed(deviation, 2) + " m away from the one interpolated between " +
        index_.crossings()[before->crossing].crossing_id + " and " +
        index_.crossings()[after->crossing].crossing_id +
        ": database crossing shifted (repainted?)";
    faults_.push_back(fault);
    for (int o : pass.obs) {
      if (options_.refuse_shifted_crossings) {
        accepted_[o] = false;
        evidence_[o].decision = Decision::kRefused;
        evidence_[o].reason = fault.description;
        inconsistent_.insert(o);
      } else {
        evidence_[o].reason += "; warning: " + fault.description;
      }
    }
  }
}

void Matcher::ResolveFromNeighbours() {
  // Sweep forward then backward so that a resolved observation can serve
  // its neighbours (the drift barely changes between exposures).
  for (int sweep = 0; sweep < 2; ++sweep) {
    const int n = static_cast<int>(by_time_.size());
    for (int s = 0; s < n; ++s) {
      const int k = sweep == 0 ? s : n - 1 - s;
      const int o = by_time_[k];
      if (accepted_[o] || !ambiguous_[o] || inconsistent_.count(o)) continue;
      const double t = input_.observations[o].time_s;
      // Nearest matched observation on each side.
      int before = -1;
      int after = -1;
      for (int m = k - 1; m >= 0; --m) {
        const int q = by_time_[m];
        if (t - input_.observations[q].time_s > options_.neighbour_window_s) {
          break;
        }
        if (accepted_[q]) {
          before = q;
          break;
        }
      }
      for (int m = k + 1; m < n; ++m) {
        const int q = by_time_[m];
        if (input_.observations[q].time_s - t > options_.neighbour_window_s) {
          break;
        }
        if (accepted_[q]) {
          after = q;
          break;
        }
      }
      // No propagation across a GNSS event: the claimed sd jumping up or
      // down means the error may jump too.
      auto same_regime = [&](int q) {
        if (q < 0) return false;
        const double a = std::max(input_.observations[q].sd_horizontal_m, 1e-3);
        const double b = std::max(input_.observations[o].sd_horizontal_m, 1e-3);
        return std::max(a, b) <= options_.max_sd_ratio * std::min(a, b);
      };
      if (!same_regime(before)) before = -1;
      if (!same_regime(after)) after = -1;
      if (before < 0 && after < 0) {
        VLOG(1) << "resolve " << input_.observations[o].exposure_id
                << ": no matched neighbour in the same GNSS regime";
        continue;
      }
      // The prediction with the smallest error bound: extrapolated from the
      // nearest match on either side, or interpolated between both.
      PoseCorrection predicted;
      double gap = std::numeric_limits<double>::infinity();
      double bound = std::numeric_limits<double>::infinity();
      bool interpolated = false;
      // Distance travelled bounds a multipath switch (a metre within tens
      // of metres), time a smooth drift.
      auto metres_to = [&](int q) {
        return (obs_[q].vehicle - obs_[o].vehicle).norm();
      };
      for (int q : {before, after}) {
        if (q < 0) continue;
        const double dt = std::abs(t - input_.observations[q].time_s);
        const double b = options_.resolve_base_m +
                         std::max(options_.drift_rate_m_per_s * dt,
                                  options_.max_drift_per_metre * metres_to(q));
        if (b < bound) {
          bound = b;
          gap = dt;
          predicted = hypotheses_[q][chosen_[q]].correction;
        }
      }
      if (before >= 0 && after >= 0) {
        const double tb = input_.observations[before].time_s;
        const double ta = input_.observations[after].time_s;
        const PoseCorrection& cb =
            hypotheses_[before][chosen_[before]].correction;
        const PoseCorrection& ca =
            hypotheses_[after][chosen_[after]].correction;
        // Neighbours further apart than the worst-case drift rate allows
        // (a jump) make the interpolation meaningless.
        const bool smooth = (cb.shift_enu_m - ca.shift_enu_m).norm() <=
                            options_.neighbour_tolerance_m +
                                options_.max_drift_rate_m_per_s * (ta - tb);
        const double u = ta > tb ? (t - tb) / (ta - tb) : 0.5;
        // Smooth drift bends little between two matches; a switch may lie
        // anywhere between them, so the nearer match's distance counts too,
        // with the part of their difference the interpolation puts on it.
        const double switch_bound =
            options_.max_drift_per_metre *
                std::min(metres_to(before), metres_to(after)) +
            (cb.shift_enu_m - ca.shift_enu_m).norm() * std::min(u, 1.0 - u);
        const double b =
            options_.resolve_base_m +
            std::max(0.5 * options_.max_drift_acceleration_m_per_s2 * (t - tb) *
                         (ta - t),
                     switch_bound);
        if (smooth && b < bound) {
          predicted.heading_rad =
              (1.0 - u) * cb.heading_rad + u * ca.heading_rad;
          predicted.shift_enu_m =
              (1.0 - u) * cb.shift_enu_m + u * ca.shift_enu_m;
          bound = b;
          gap = std::min(t - tb, ta - t);
          interpolated = true;
        }
      }
      if (bound > options_.max_resolve_bound_m) {
        VLOG(1) << "resolve " << input_.observations[o].exposure_id
                << ": prediction bound " << bound << " m too loose";
        continue;
      }
      const std::vector<Hypothesis>& list = hypotheses_[o];
      double top = -std::numeric_limits<double>::infinity();
      for (const Hypothesis& h : list) top = std::max(top, h.aggregated);
      int pick = -1;
      double pick_distance = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < list.size(); ++i) {
        const double d = CorrectionDistance(list[i].correction, predicted,
                                            obs_[o].centroid_q);
        const bool usable = static_cast<int>(list[i].eval.hits.size()) >=
                                options_.min_hit_bands &&
                            list[i].eval.contradictions.empty() &&
                            list[i].aggregated >= top - options_.min_margin;
        if (usable && d <= bound && d < pick_distance) {
          pick = static_cast<int>(i);
          pick_distance = d;
        }
      }
      if (pick < 0) {
        VLOG(1) << "resolve " << input_.observations[o].exposure_id
                << ": no hypothesis within " << bound << " m of the "
                << "prediction";
        continue;
      }
      // Every distinct hypothesis (duplicates of the pick aside) must lie
      // clearly outside the bound.
      bool unique = true;
      for (size_t i = 0; i < list.size(); ++i) {
        if (static_cast<int>(i) == pick) continue;
        const double between = CorrectionDistance(
            list[i].correction, list[pick].correction, obs_[o].centroid_q);
        if (between < 2.0 * options_.same_correction_tolerance_m) continue;
        const double d = CorrectionDistance(list[i].correction, predicted,
                                            obs_[o].centroid_q);
        if (d < bound + options_.same_correction_tolerance_m) unique = false;
      }
      if (!unique) {
        VLOG(1) << "resolve " << input_.observations[o].exposure_id
                << ": several hypotheses near the prediction";
        continue;
      }
      const Hypothesis& h = list[pick];
      chosen_[o] = pick;
      accepted_[o] = true;
      ObservationEvidence& ev = evidence_[o];
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
                           ? index_.crossings()[h.main_crossing].crossing_id
                           : "";
      ev.reason = "resolved by trajectory continuity: the correction " +
                  std::string(interpolated ? "interpolated" : "extrapolated") +
                  " from matched exposures (" + Fixed(gap, 1) +
                  " s away; error bound " + Fixed(bound, 2) +
                  " m) selects it at " + Fixed(pick_distance, 2) +
                  " m; alone it was " + was;
    }
  }
}

std::vector<VertexMatch> Matcher::RefinedMatches(int o,
                                                 PoseCorrection* correction,
                                                 std::vector<int>* bands,
                                                 double* rms_m) const {
  const Obs& obs = obs_[o];
  const Hypothesis& h = hypotheses_[o][chosen_[o]];
  // Refine on this observation's own bands, then keep the bands whose every
  // corner fits.
  const PoseCorrection c = Refine(obs, h.eval, h.correction);
  const Eval eval = Evaluate(obs, c);
  *correction = c;
  bands->clear();
  double sum = 0.0;
  int count = 0;
  std::vector<VertexMatch> out;
  for (const Hit& hit : eval.hits) {
    const IndexedBand& db = index_.bands()[hit.db];
    if (db.implied) continue;  // no database coordinates to control with
    const ObsBand& band = obs.bands[hit.rec];
    std::array<double, 4> error;
    bool fits = true;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d p = Apply(c, obs.vehicle, band.q[k]);
      error[k] =
          (p - db.corners_enu[PermutedCorner(hit.perm, k)].head<2>()).norm();
      fits = fits && error[k] <= options_.vertex_tolerance_m;
    }
    if (!fits) continue;
    bands->push_back(db.band);
    const ObservedBand& source = obs.source->bands[hit.rec];
    for (int k = 0; k < 4; ++k) {
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

bool Matcher::RefuseUnrefined(int o) {
  PoseCorrection c;
  std::vector<int> bands;
  double rms = 0.0;
  RefinedMatches(o, &c, &bands, &rms);
  if (static_cast<int>(bands.size()) >= options_.min_hit_bands) return false;
  ObservationEvidence& ev = evidence_[o];
  accepted_[o] = false;
  ev.decision = Decision::kRefused;
  ev.reason = "after refinement only " + std::to_string(bands.size()) +
              " band(s) fit to vertex_tolerance_m = " +
              Fixed(options_.vertex_tolerance_m, 2) + " m; was: " + ev.reason;
  return true;
}

void Matcher::EmitMatches(int o) {
  ObservationEvidence& ev = evidence_[o];
  if (RefuseUnrefined(o)) return;
  const std::vector<VertexMatch> out =
      RefinedMatches(o, &ev.correction, &ev.matched_bands, &ev.vertex_rms_m);
  ev.vertex_matches = static_cast<int>(out.size());
  matches_.insert(matches_.end(), out.begin(), out.end());
}

void Matcher::DetectFaults() {
  const auto& crossings = index_.crossings();
  // Bands missing on either side, from matched observations.
  std::map<int, int> band_seen;                      // database band -> views
  std::map<int, std::vector<int64_t>> band_missing;  // -> exposures
  std::map<std::pair<int, int>, std::vector<int64_t>>
      extra;  // (crossing, side)
  std::set<int> matched_crossings;
  for (size_t o = 0; o < obs_.size(); ++o) {
    if (!accepted_[o]) continue;
    const Hypothesis& h = hypotheses_[o][chosen_[o]];
    const int64_t exposure = input_.observations[o].exposure_id;
    for (const Hit& hit : h.eval.hits) {
      ++band_seen[hit.db];
      matched_crossings.insert(index_.bands()[hit.db].crossing);
    }
    for (int b : h.eval.missing) {
      if (!index_.bands()[b].implied) band_missing[b].push_back(exposure);
    }
    if (h.main_crossing < 0) continue;
    const IndexedCrossing& crossing = crossings[h.main_crossing];
    const Eigen::Vector2d first = crossing.ToCrossing(crossing.first_end_enu);
    const Eigen::Vector2d last = crossing.ToCrossing(crossing.last_end_enu);
    for (int rec : h.eval.unexplained) {
      const Eigen::Vector2d p = crossing.ToCrossing(Apply(
          h.correction, obs_[o].vehicle, obs_[o].bands[rec].shape.centre));
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
    if (static_cast<int>(exposures.size()) < options_.min_views_for_fault ||
        band_seen.count(b)) {
      continue;
    }
    const IndexedBand& band = index_.bands()[b];
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
    faults_.push_back(fault);
  }
  for (const auto& [key, exposures] : extra) {
    if (static_cast<int>(exposures.size()) < options_.min_views_for_fault) {
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
    faults_.push_back(fault);
  }

  // Crossings missing from the database: groups of usable bands nothing
  // fits, clustered by place.
  struct Cluster {
    Eigen::Vector2d centre;
    std::vector<int64_t> exposures;
  };
  std::vector<Cluster> clusters;
  for (size_t o = 0; o < obs_.size(); ++o) {
    if (evidence_[o].decision != Decision::kNoCandidate || obs_[o].usable < 2) {
      continue;
    }
    const Eigen::Vector2d p = obs_[o].vehicle + obs_[o].centroid_q;
    Cluster* home = nullptr;
    for (Cluster& cluster : clusters) {
      if ((cluster.centre - p).norm() < 10.0) home = &cluster;
    }
    if (home == nullptr) {
      clusters.push_back({p, {}});
      home = &clusters.back();
    }
    home->exposures.push_back(input_.observations[o].exposure_id);
  }
  for (const Cluster& cluster : clusters) {
    if (static_cast<int>(cluster.exposures.size()) <
        options_.min_views_for_fault) {
      continue;
    }
    DatabaseFault fault;
    fault.kind = FaultKind::kCrossingMissingFromDatabase;
    fault.location_enu = cluster.centre;
    fault.views = static_cast<int>(cluster.exposures.size());
    fault.exposure_ids = cluster.exposures;
    fault.description =
        "a crossing seen in " + std::to_string(fault.views) + " views near E " +
        Fixed(cluster.centre.x(), 1) + " N " + Fixed(cluster.centre.y(), 1) +
        " (measured trajectory) has no database crossing within the drift "
        "gate: missing from the database";
    faults_.push_back(fault);
  }

  // Crossings gone from the street: fully in view of several exposures (with
  // the correction of the nearest match) and never fitted by anything seen.
  if (!visibility_.enabled()) return;
  std::set<int> touched;  // crossings some hypothesis explains bands of
  for (const std::vector<Hypothesis>& list : hypotheses_) {
    for (const Hypothesis& h : list) {
      for (const Hit& hit : h.eval.hits) {
        touched.insert(index_.bands()[hit.db].crossing);
      }
    }
  }
  std::vector<std::pair<double, PoseCorrection>> known;
  for (int o : by_time_) {
    if (accepted_[o]) {
      known.emplace_back(input_.observations[o].time_s,
                         hypotheses_[o][chosen_[o]].correction);
    }
  }
  std::map<int, std::vector<int64_t>> should_have_seen;
  std::vector<int> near;
  for (const ExposurePose& exposure : input_.exposures) {
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
    index_.CrossingsWithin(pose.p_enu.head<2>(), visibility_.range_m(), &near);
    for (int crossing : near) {
      if (touched.count(crossing)) continue;
      const IndexedCrossing& x = crossings[crossing];
      int visible = 0;
      for (int b : x.bands) {
        visible += visibility_.BandVisible(pose, index_.bands()[b]) ? 1 : 0;
      }
      if (visible >= std::min<int>(3, static_cast<int>(x.bands.size()))) {
        should_have_seen[crossing].push_back(exposure.exposure_id);
      }
    }
  }
  for (const auto& [crossing, exposures] : should_have_seen) {
    if (static_cast<int>(exposures.size()) < options_.min_views_for_fault) {
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
    faults_.push_back(fault);
  }
}

MatchResult Matcher::Run(const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  PrepareObservations();
  const int n = static_cast<int>(obs_.size());
  hypotheses_.assign(n, {});
  candidate_bands_.assign(n, 0);
  chosen_.assign(n, -1);
  accepted_.assign(n, false);
  ambiguous_.assign(n, false);
  evidence_.assign(n, ObservationEvidence());
  for (int o = 0; o < n; ++o) {
    const CrossingObservation& source = input_.observations[o];
    ObservationEvidence& ev = evidence_[o];
    ev.exposure_id = source.exposure_id;
    ev.group_id = source.group_id;
    ev.time_s = source.time_s;
    ev.bands = static_cast<int>(source.bands.size());
    ev.usable_bands = obs_[o].usable;
    GenerateHypotheses(o);
    if (progress && (o % 64 == 0 || o + 1 == n)) progress(o + 1, n);
  }
  window_.assign(n, {0, 0});
  Aggregate();
  for (int o = 0; o < n; ++o) DecideAlone(o);
  // Only observations whose match survives refinement may vouch for their
  // neighbours.
  for (int o = 0; o < n; ++o) {
    if (accepted_[o]) RefuseUnrefined(o);
  }
  CheckContinuity();
  ResolveFromNeighbours();
  DetectShiftedCrossings();
  for (int o : by_time_) {
    if (accepted_[o]) EmitMatches(o);
  }
  DetectFaults();
  MatchResult result;
  result.summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  Finish(&result);
  return result;
}

void Matcher::Finish(MatchResult* result) {
  // Faults explain decisions: add them to the reasons of the observations
  // of the crossings concerned.
  std::map<std::string, std::vector<const DatabaseFault*>> by_crossing;
  for (const DatabaseFault& fault : faults_) {
    if (!fault.crossing_id.empty()) {
      by_crossing[fault.crossing_id].push_back(&fault);
    }
  }
  MatchSummary& summary = result->summary;
  std::set<std::string> crossings;
  for (size_t o = 0; o < evidence_.size(); ++o) {
    ObservationEvidence& ev = evidence_[o];
    if (ev.decision != Decision::kMatched) {
      ev.crossing_id.clear();
    }
    const std::string& id =
        ev.decision == Decision::kMatched
            ? ev.crossing_id
            : (chosen_[o] >= 0 && hypotheses_[o][chosen_[o]].main_crossing >= 0
                   ? index_
                         .crossings()[hypotheses_[o][chosen_[o]].main_crossing]
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
        if (inconsistent_.count(static_cast<int>(o))) {
          ++summary.inconsistent;
        } else if (ambiguous_[o]) {
          ++summary.ambiguous;
        }
        break;
      case Decision::kNoCandidate:
        ++summary.no_candidate;
        break;
    }
  }
  summary.vertex_matches = static_cast<int>(matches_.size());
  summary.crossings_matched = static_cast<int>(crossings.size());
  summary.faults = static_cast<int>(faults_.size());
  result->matches = std::move(matches_);
  result->evidence = std::move(evidence_);
  result->faults = std::move(faults_);
}

}  // namespace

std::string MatchOptions::Check() const {
  std::ostringstream out;
  auto positive = [&](const char* name, double value) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      out << name << " = " << value << ": must be > 0";
      return false;
    }
    return true;
  };
  auto non_negative = [&](const char* name, double value) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      out << name << " = " << value << ": must be >= 0";
      return false;
    }
    return true;
  };
  if (!positive("max_drift_m", max_drift_m) ||
      !non_negative("sd_gate_factor", sd_gate_factor) ||
      !positive("max_heading_error_rad", max_heading_error_rad) ||
      !positive("min_band_length_m", min_band_length_m) ||
      !positive("max_band_length_m", max_band_length_m) ||
      !positive("min_band_width_m", min_band_width_m) ||
      !positive("max_band_width_m", max_band_width_m) ||
      !positive("max_length_difference_m", max_length_difference_m) ||
      !positive("max_width_difference_m", max_width_difference_m) ||
      !positive("hit_tolerance_m", hit_tolerance_m) ||
      !positive("vertex_tolerance_m", vertex_tolerance_m) ||
      !non_negative("missing_band_weight", missing_band_weight) ||
      !positive("max_missing_views", max_missing_views) ||
      !non_negative("contradiction_weight", contradiction_weight) ||
      !non_negative("unexplained_band_weight", unexplained_band_weight) ||
      !non_negative("visibility_margin_px", visibility_margin_px) ||
      !non_negative("visibility_safety_px", visibility_safety_px) ||
      !non_negative("visibility_range_m", visibility_range_m) ||
      !non_negative("window_s", window_s) ||
      !positive("same_correction_tolerance_m", same_correction_tolerance_m) ||
      !non_negative("drift_rate_m_per_s", drift_rate_m_per_s) ||
      !positive("min_margin", min_margin) ||
      !non_negative("min_strong_margin", min_strong_margin) ||
      !positive("probe_range_m", probe_range_m) ||
      !non_negative("neighbour_window_s", neighbour_window_s) ||
      !positive("neighbour_tolerance_m", neighbour_tolerance_m) ||
      !non_negative("max_drift_rate_m_per_s", max_drift_rate_m_per_s) ||
      !positive("max_informative_tolerance_m", max_informative_tolerance_m) ||
      !non_negative("resolve_base_m", resolve_base_m) ||
      !non_negative("max_drift_per_metre", max_drift_per_metre) ||
      !non_negative("max_drift_acceleration_m_per_s2",
                    max_drift_acceleration_m_per_s2) ||
      !non_negative("max_resolve_bound_m", max_resolve_bound_m) ||
      !positive("max_sd_ratio", max_sd_ratio) ||
      !positive("shifted_crossing_threshold_m", shifted_crossing_threshold_m)) {
    return out.str();
  }
  if (max_heading_error_rad >= 0.5) {
    out << "max_heading_error_rad = " << max_heading_error_rad
        << ": must be < 0.5 (bands would pair with crossings of other roads)";
    return out.str();
  }
  if (min_band_length_m >= max_band_length_m) {
    out << "min_band_length_m = " << min_band_length_m
        << ": must be < max_band_length_m = " << max_band_length_m;
    return out.str();
  }
  if (min_band_width_m >= max_band_width_m) {
    out << "min_band_width_m = " << min_band_width_m
        << ": must be < max_band_width_m = " << max_band_width_m;
    return out.str();
  }
  if (hit_tolerance_m >= 0.5) {
    out << "hit_tolerance_m = " << hit_tolerance_m
        << ": must be < 0.5 (half the band period, or neighbouring bands "
           "would explain each other)";
    return out.str();
  }
  if (min_hit_bands < 1) {
    out << "min_hit_bands = " << min_hit_bands << ": must be >= 1";
    return out.str();
  }
  if (min_views_for_fault < 1) {
    out << "min_views_for_fault = " << min_views_for_fault << ": must be >= 1";
    return out.str();
  }
  return "";
}

const char* FaultKindName(FaultKind kind) {
  switch (kind) {
    case FaultKind::kCrossingMissingFromDatabase:
      return "crossing_missing_from_database";
    case FaultKind::kCrossingGoneFromStreet:
      return "crossing_gone_from_street";
    case FaultKind::kBandMissingFromStreet:
      return "band_missing_from_street";
    case FaultKind::kBandMissingFromDatabase:
      return "band_missing_from_database";
    case FaultKind::kCrossingShifted:
      return "crossing_shifted";
  }
  return "unknown";
}

std::string MatchSummary::BriefReport() const {
  std::ostringstream out;
  if (!IsUsable()) return "match: not run: " + message;
  out << "match: " << observations << " observations: " << matched
      << " matched (" << resolved_by_neighbours << " by continuity), "
      << refused << " refused (" << ambiguous << " ambiguous, " << inconsistent
      << " inconsistent), " << no_candidate << " without candidate; "
      << vertex_matches << " vertex matches on " << crossings_matched
      << " crossings; " << faults << " database faults; " << Fixed(seconds, 2)
      << " s";
  return out.str();
}

Eigen::Vector3d CorrectedEnu(const Pose& measured,
                             const PoseCorrection& correction,
                             const Eigen::Vector3d& p_body) {
  const Pose pose = CorrectedPose(measured, correction);
  return pose.q_enu_body * p_body + pose.p_enu;
}

MatchResult MatchBands(const MatchInput& input, const MatchOptions& options,
                       const std::function<void(int, int)>& progress) {
  MatchResult result;
  const std::string problem = options.Check();
  if (!problem.empty()) {
    result.summary.message = "MatchOptions: " + problem;
    return result;
  }
  if (input.index == nullptr) {
    result.summary.message = "MatchInput: no road-mark index";
    return result;
  }
  Matcher matcher(input, options);
  result = matcher.Run(progress);
  LOG(INFO) << result.summary.BriefReport();
  return result;
}

}  // namespace zebrageo
