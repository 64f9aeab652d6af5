#include "tests/support/synthetic_reconstruction.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "simulator/noise.h"
#include "tests/support/synthetic_view_internal.h"

namespace zebrageo::support {
namespace {

using sim::Band;
using sim::Gaussian;
using sim::Uniform;

// Purposes of the sub-generators (sim::SubSeed).
enum Purpose : uint64_t {
  kModelSeed = 301,
  kReconstructionSeed = 302,
  kProbeSeed = 303,
};

Eigen::Vector3d Centre(const std::array<Eigen::Vector3d, 4>& q) {
  return 0.25 * (q[0] + q[1] + q[2] + q[3]);
}

// True when the horizontal position of `p` lies inside the convex quad `q`
// (either orientation).
bool InsideQuad(const std::array<Eigen::Vector3d, 4>& q,
                const Eigen::Vector2d& p) {
  int positive = 0, negative = 0;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = q[k].head<2>();
    const Eigen::Vector2d b = q[(k + 1) % 4].head<2>();
    const double cross =
        (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    (cross >= 0.0 ? positive : negative)++;
  }
  return positive == 4 || negative == 4;
}

// The two corner indices of each short side (the band's ends), in ring
// order: {k, k+1} for the two shortest edges.
std::array<std::array<int, 2>, 2> BandEnds(
    const std::array<Eigen::Vector3d, 4>& q) {
  const double e01 = (q[1] - q[0]).norm() + (q[3] - q[2]).norm();
  const double e12 = (q[2] - q[1]).norm() + (q[0] - q[3]).norm();
  if (e01 < e12) return {{{0, 1}, {2, 3}}};
  return {{{1, 2}, {3, 0}}};
}

// How the vehicles hide a band from a stereo pair: 0 nothing, 1 one end
// only (which end in *end), 2 more than an end.
int Occlusion(const sim::World& world, const std::array<Eigen::Vector3d, 4>& q,
              const CameraView& left, const CameraView& right, int* end) {
  const auto ends = BandEnds(q);
  bool corner_hidden[4] = {false, false, false, false};
  bool middle_hidden = false;
  for (const CameraView* view : {&left, &right}) {
    for (int k = 0; k < 4; ++k) {
      corner_hidden[k] |= HiddenByVehicle(world, view->centre_enu, q[k]);
    }
    // The middle of the band and of its long sides.
    const Eigen::Vector3d middles[3] = {Centre(q),
                                        0.5 * (q[ends[0][0]] + q[ends[1][1]]),
                                        0.5 * (q[ends[0][1]] + q[ends[1][0]])};
    for (const Eigen::Vector3d& p : middles) {
      middle_hidden |= HiddenByVehicle(world, view->centre_enu, p);
    }
  }
  const bool end_hidden[2] = {
      corner_hidden[ends[0][0]] || corner_hidden[ends[0][1]],
      corner_hidden[ends[1][0]] || corner_hidden[ends[1][1]]};
  if (!end_hidden[0] && !end_hidden[1] && !middle_hidden) return 0;
  if (middle_hidden || (end_hidden[0] && end_hidden[1])) return 2;
  *end = end_hidden[0] ? 0 : 1;
  return 1;
}

uint64_t HashPoint(uint64_t seed, int64_t exposure_id,
                   const Eigen::Vector3d& p) {
  const auto ix = static_cast<int64_t>(std::floor(p.x() * 10.0));
  const auto iy = static_cast<int64_t>(std::floor(p.y() * 10.0));
  return sim::HashLattice(
      ix, iy, sim::Mix64(seed + static_cast<uint64_t>(exposure_id)));
}

}  // namespace

ReconstructionModel ReconstructionModel::Random(uint64_t seed) {
  std::mt19937_64 rng(sim::SubSeed(seed, kModelSeed));
  ReconstructionModel m;
  m.margin_px = Uniform(&rng, 5.0, 20.0);
  m.near_recall = Uniform(&rng, 0.97, 1.0);
  m.near_range_m = Uniform(&rng, 7.0, 9.0);
  m.far_range_m = Uniform(&rng, 11.0, 12.0);
  m.far_recall = Uniform(&rng, 0.2, 0.9);
  m.ray_sigma_at_5m_m = Uniform(&rng, 0.004, 0.006);
  m.range_exponent = Uniform(&rng, 1.3, 1.6);
  m.pixel_sigma_px = Uniform(&rng, 0.2, 0.4);
  m.cut_short_probability = Uniform(&rng, 0.0, 0.02);
  m.hidden_end_probability = Uniform(&rng, 0.0, 0.04);
  m.probe_unknown_share = Uniform(&rng, 0.0, 0.3);
  return m;
}

double ReconstructionModel::RecallAt(double range_m) const {
  if (range_m <= near_range_m) return near_recall;
  if (range_m >= far_range_m) return far_recall;
  const double u = (range_m - near_range_m) / (far_range_m - near_range_m);
  return near_recall + u * (far_recall - near_recall);
}

std::string ReconstructionModel::Check() const {
  auto bad = [](const char* name, double value, const char* rule) {
    std::ostringstream out;
    out << name << " = " << value << ": must be " << rule;
    return out.str();
  };
  if (!(margin_px >= 0.0)) return bad("margin_px", margin_px, ">= 0");
  if (!(min_depth_m > 0.0)) return bad("min_depth_m", min_depth_m, "> 0");
  if (!(near_range_m > 0.0 && far_range_m > near_range_m &&
        max_range_m >= far_range_m)) {
    return bad("far_range_m", far_range_m,
               "> near_range_m > 0 and <= max_range_m");
  }
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"near_recall", near_recall},
        {"far_recall", far_recall},
        {"cut_short_probability", cut_short_probability},
        {"hidden_end_probability", hidden_end_probability},
        {"shared_share", shared_share},
        {"probe_unknown_share", probe_unknown_share},
        {"inferred_score_factor", inferred_score_factor}}) {
    if (!(value >= 0.0 && value <= 1.0)) return bad(name, value, "in [0, 1]");
  }
  if (!(ray_sigma_at_5m_m >= 0.0 && min_sigma_m >= 0.0 &&
        perpendicular_share >= 0.0 && pixel_sigma_px >= 0.0 &&
        inferred_sigma_m >= 0.0)) {
    return "noise sds must be >= 0";
  }
  return "";
}

std::string ReconstructionModel::Brief() const {
  std::ostringstream out;
  out.precision(2);
  out << "recall " << near_recall << "->" << far_recall << "@" << far_range_m
      << "m, noise " << 100.0 * ray_sigma_at_5m_m << "cm@5m^" << range_exponent
      << ", cut " << cut_short_probability << ", inferred "
      << hidden_end_probability << ", probe? " << probe_unknown_share;
  return out.str();
}

bool HiddenByVehicle(const sim::World& world, const Eigen::Vector3d& from,
                     const Eigen::Vector3d& to) {
  for (const sim::ParkedVehicle& vehicle : world.vehicles) {
    const sim::VerticalBox& box = vehicle.box;
    // Slab test in the box's frame (u, v, z), the segment's parameter in
    // [0, 1) (the end point itself lies on the road, not in the box).
    const Eigen::Vector2d u = box.axis_u, v = box.axis_v();
    const Eigen::Vector2d a = from.head<2>() - box.centre;
    const Eigen::Vector2d b = to.head<2>() - box.centre;
    const double origin[3] = {a.dot(u), a.dot(v), from.z()};
    const double delta[3] = {b.dot(u) - origin[0], b.dot(v) - origin[1],
                             to.z() - from.z()};
    const double lo[3] = {-box.half_u, -box.half_v, box.z0};
    const double hi[3] = {box.half_u, box.half_v, box.z1};
    double t0 = 0.0, t1 = 0.999;
    bool miss = false;
    for (int axis = 0; axis < 3 && !miss; ++axis) {
      if (std::abs(delta[axis]) < 1e-12) {
        miss = origin[axis] < lo[axis] || origin[axis] > hi[axis];
        continue;
      }
      double ta = (lo[axis] - origin[axis]) / delta[axis];
      double tb = (hi[axis] - origin[axis]) / delta[axis];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (!miss) return true;
  }
  return false;
}

std::map<int64_t, Pose> TruePoses(const sim::SimulatedSurvey& survey) {
  const Trajectory truth(survey.motion.truth, survey.frame);
  std::map<int64_t, Pose> poses;
  for (const Exposure& exposure : survey.exposures.exposures) {
    Pose pose;
    if (truth.InterpolatePose(exposure.time, &pose)) {
      poses[exposure.exposure_id] = pose;
    }
  }
  return poses;
}

namespace {

// One band seen whole by one stereo pair: its corners (ENU) and pixels.
struct BandView {
  int band = -1;  // index into World::bands
  double range_m = 0.0;
  std::array<Eigen::Vector3d, 4> corners;
  std::array<Eigen::Vector2d, 4> uv_left, uv_right;
};

// False unless every corner of `band` lies in front of both cameras and
// projects inside both images, and its centre is within range.
bool SeeWhole(const ReconstructionModel& model, const sim::Band& band,
              const CameraView& left, const CameraView& right, BandView* view) {
  view->corners = band.corners;
  view->range_m = (Centre(band.corners) - left.centre_enu).norm();
  if (view->range_m > model.max_range_m) return false;
  for (int k = 0; k < 4; ++k) {
    if (!ProjectInside(left, band.corners[k], model.min_depth_m,
                       model.margin_px, &view->uv_left[k]) ||
        !ProjectInside(right, band.corners[k], model.min_depth_m,
                       model.margin_px, &view->uv_right[k])) {
      return false;
    }
  }
  return true;
}

// Everything random about one band view, drawn up front so that one
// decision does not shift the random stream of the others.
struct ViewDraws {
  double recall = 0.0;
  double fault = 0.0;
  int end = 0;
  double cut_m = 0.0;
  int ring_shift = 0;
};

ViewDraws Draw(std::mt19937_64* rng) {
  ViewDraws d;
  d.recall = Uniform(rng, 0.0, 1.0);
  d.fault = Uniform(rng, 0.0, 1.0);
  d.end = Uniform(rng, 0.0, 1.0) < 0.5 ? 0 : 1;
  d.cut_m = Uniform(rng, 0.25, 1.0);
  d.ring_shift = sim::UniformInt(rng, 0, 3);
  return d;
}

// Moves one end of the band `cut_m` towards the other (a stain or worn
// paint where the reconstruction sees the end): false when that would leave
// less than 1.5 m.
bool CutShort(const CameraView& left, const CameraView& right, int end,
              double cut_m, BandView* view) {
  std::array<Eigen::Vector3d, 4>& q = view->corners;
  const auto ends = BandEnds(q);
  const Eigen::Vector3d end0 = 0.5 * (q[ends[0][0]] + q[ends[0][1]]);
  const Eigen::Vector3d end1 = 0.5 * (q[ends[1][0]] + q[ends[1][1]]);
  if ((end0 - end1).norm() - cut_m < 1.5) return false;
  const Eigen::Vector3d along = (end1 - end0).normalized();
  const double sign = end == 0 ? 1.0 : -1.0;
  for (int k : ends[end]) {
    q[k] += sign * cut_m * along;
    left.camera->Project(left.T_cam_enu * q[k], &view->uv_left[k]);
    right.camera->Project(right.T_cam_enu * q[k], &view->uv_right[k]);
  }
  return true;
}

// Appends the band's four vertices: body frame of the true pose plus noise
// mostly along the left camera's viewing ray (part shared by the band),
// pixels plus noise; an inferred end (-1: none) adds its sd along the band.
void AppendVertices(const ReconstructionModel& model, const BandView& view,
                    const CameraView& left, const Eigen::Isometry3d& T_body_enu,
                    int inferred_end, int ring_shift, ReconstructedVertex base,
                    std::mt19937_64* rng,
                    std::vector<ReconstructedVertex>* vertices) {
  const std::array<Eigen::Vector3d, 4>& q = view.corners;
  const auto ends = BandEnds(q);
  const Eigen::Vector3d along =
      (Centre(q) - 0.5 * (q[ends[0][0]] + q[ends[0][1]])).normalized();
  const double sigma_ray =
      model.ray_sigma_at_5m_m *
      std::pow(std::max(view.range_m, 1.0) / 5.0, model.range_exponent);
  const double sigma_across =
      std::max(model.min_sigma_m, model.perpendicular_share * sigma_ray);
  const double own = std::sqrt(1.0 - model.shared_share);
  const double shared = std::sqrt(model.shared_share);
  const Eigen::Vector3d ray = (Centre(q) - left.centre_enu).normalized();
  const Eigen::Vector3d side = ray.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = side.cross(ray);
  auto draw = [&](double share) {
    return Eigen::Vector3d(Gaussian(rng, share * sigma_ray) * ray +
                           Gaussian(rng, share * sigma_across) * side +
                           Gaussian(rng, share * sigma_across) * up);
  };
  const Eigen::Vector3d common = draw(shared);
  const Eigen::Matrix3d cov_enu =
      sigma_ray * sigma_ray * ray * ray.transpose() +
      sigma_across * sigma_across *
          (Eigen::Matrix3d::Identity() - ray * ray.transpose());
  const Eigen::Matrix3d R_body_enu = T_body_enu.linear();
  const double px = model.pixel_sigma_px;
  for (int label = 0; label < 4; ++label) {
    const int k = (label + ring_shift) % 4;
    const bool inferred_corner =
        inferred_end >= 0 &&
        (k == ends[inferred_end][0] || k == ends[inferred_end][1]);
    Eigen::Vector3d noise = common + draw(own);
    Eigen::Matrix3d cov = cov_enu;
    if (inferred_corner) {
      noise += Gaussian(rng, model.inferred_sigma_m) * along;
      cov += model.inferred_sigma_m * model.inferred_sigma_m * along *
             along.transpose();
    }
    ReconstructedVertex v = base;
    v.vertex = label;
    v.p_body = T_body_enu * (q[k] + noise);
    v.covariance_body = R_body_enu * cov * R_body_enu.transpose();
    v.uv_left =
        view.uv_left[k] + Eigen::Vector2d(Gaussian(rng, px), Gaussian(rng, px));
    v.uv_right = view.uv_right[k] +
                 Eigen::Vector2d(Gaussian(rng, px), Gaussian(rng, px));
    v.score = inferred_end >= 0 ? 0.9 * model.inferred_score_factor : 0.9;
    vertices->push_back(v);
  }
}

}  // namespace

SyntheticReconstruction SynthesiseReconstruction(
    const sim::SimulatedSurvey& survey, const ReconstructionModel& model,
    uint64_t seed) {
  std::mt19937_64 rng(sim::SubSeed(seed, kReconstructionSeed));
  const sim::World& world = survey.world;
  SyntheticReconstruction out;
  int64_t next_band_id = 1;
  int64_t next_group_id = 1;
  ForEachStereoView(
      survey, TruePoses(survey),
      [&](const Exposure& exposure, int pair, const Pose&,
          const Eigen::Isometry3d& T_body_enu, const CameraView& left,
          const CameraView& right) {
        std::map<int, int64_t> group_of_crossing;
        for (int b = 0; b < static_cast<int>(world.bands.size()); ++b) {
          const sim::Band& band = world.bands[b];
          BandView view;
          view.band = b;
          if (!SeeWhole(model, band, left, right, &view)) continue;
          ++out.views_in_range;
          const ViewDraws draws = Draw(&rng);
          int hidden_end = -1;
          const int occlusion =
              Occlusion(world, view.corners, left, right, &hidden_end);
          if (occlusion != 0) ++out.views_hidden;
          if (occlusion == 2 || draws.recall >= model.RecallAt(view.range_m)) {
            continue;
          }
          bool inferred = occlusion == 1;
          bool cut_short = false;
          if (!inferred && draws.fault < model.hidden_end_probability) {
            inferred = true;
            hidden_end = draws.end;
          } else if (!inferred &&
                     draws.fault < model.hidden_end_probability +
                                       model.cut_short_probability) {
            cut_short = CutShort(left, right, draws.end, draws.cut_m, &view);
          }
          // The real stage infers an end from the crossing's other bands, and
          // not far away.
          if (inferred &&
              (world.crossings[band.crossing].num_street_bands < 4 ||
               view.range_m > model.max_inferred_range_m)) {
            continue;
          }
          ++out.views_reconstructed;
          auto [group_it, added] =
              group_of_crossing.emplace(band.crossing, next_group_id);
          if (added) ++next_group_id;
          ReconstructedVertex base;
          base.exposure_id = exposure.exposure_id;
          base.pair = pair;
          base.band_id = next_band_id++;
          base.group_id = group_it->second;
          out.truth_of_band[base.band_id] = {b, view.range_m, cut_short,
                                             inferred};
          AppendVertices(model, view, left, T_body_enu,
                         inferred ? hidden_end : -1, draws.ring_shift, base,
                         &rng, &out.vertices);
        }
      });
  return out;
}

TruthPaintProbe::TruthPaintProbe(const sim::SimulatedSurvey& survey,
                                 const ReconstructionModel& model,
                                 uint64_t seed)
    : survey_(survey),
      unknown_share_(model.probe_unknown_share),
      seed_(sim::SubSeed(seed, kProbeSeed)),
      true_pose_(TruePoses(survey)) {
  for (const sim::ExposureEvent& e : survey.motion.exposures) {
    s_of_exposure_[e.exposure_id] = e.s_m;
  }
}

bool TruthPaintProbe::IsPainted(const Eigen::Vector3d& p_enu,
                                double s_hint) const {
  const sim::World& world = survey_.world;
  for (const Band& band : world.bands) {
    if ((Centre(band.corners) - p_enu).head<2>().squaredNorm() > 16.0) {
      continue;
    }
    if (InsideQuad(band.corners, p_enu.head<2>())) return true;
  }
  double s = 0.0, l = 0.0;
  if (!world.road.ToRoadCoordinates(p_enu.head<2>(), s_hint, &s, &l)) {
    return false;
  }
  for (const sim::LinePiece& line : world.lines) {
    if (s >= line.s0 && s <= line.s1 &&
        std::abs(l - line.l_m) <= 0.5 * line.width_m) {
      return true;
    }
  }
  for (const sim::StopLine& stop : world.stop_lines) {
    if (l >= stop.l0 && l <= stop.l1 &&
        std::abs(s - stop.s_m) <= 0.5 * stop.width_m) {
      return true;
    }
  }
  return false;
}

PaintEvidence TruthPaintProbe::Classify(
    int64_t exposure_id, const Pose& pose, const BandCornersEnu& band,
    const std::vector<BandCornersEnu>& seen) const {
  // As the image probe: nothing to compare the band with, no verdict.
  if (seen.empty() || survey_.rig.stereo_pairs.empty()) {
    return PaintEvidence::kUnknown;
  }
  const auto pose_it = true_pose_.find(exposure_id);
  const auto s_it = s_of_exposure_.find(exposure_id);
  if (pose_it == true_pose_.end() || s_it == s_of_exposure_.end()) {
    return PaintEvidence::kUnknown;
  }
  const Eigen::Vector3d centre = Centre(band);
  if (sim::HashToUnit(HashPoint(seed_, exposure_id, centre)) < unknown_share_) {
    return PaintEvidence::kUnknown;
  }
  // Where the image pixels of the band (seen from `pose`) really look.
  const Eigen::Isometry3d T_true_assumed =
      pose_it->second.T_enu_body() * pose.T_enu_body().inverse();
  const CameraView left =
      ViewOf(survey_.rig, survey_.rig.stereo_pairs[0][0], pose_it->second);
  constexpr int kGrid = 5;
  int inside = 0, painted = 0, total = 0;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      // The middle half of the band, bilinear in its corners.
      const double a = 0.25 + 0.5 * i / (kGrid - 1);
      const double b = 0.25 + 0.5 * j / (kGrid - 1);
      const Eigen::Vector3d p_assumed = (1 - a) * (1 - b) * band[0] +
                                        a * (1 - b) * band[1] +
                                        a * b * band[2] + (1 - a) * b * band[3];
      const Eigen::Vector3d p = T_true_assumed * p_assumed;
      ++total;
      Eigen::Vector2d uv;
      if (!ProjectInside(left, p, 0.5, 0.0, &uv)) continue;
      ++inside;
      if (HiddenByVehicle(survey_.world, left.centre_enu, p)) {
        return PaintEvidence::kUnknown;
      }
      painted += IsPainted(p, s_it->second) ? 1 : 0;
    }
  }
  if (inside < 0.8 * total) return PaintEvidence::kUnknown;
  if (painted >= 0.6 * inside) return PaintEvidence::kPaint;
  if (painted <= 0.05 * inside) return PaintEvidence::kBareRoad;
  return PaintEvidence::kUnknown;
}

}  // namespace zebrageo::support
