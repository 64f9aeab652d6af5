#include "tests/support/synthetic_lines.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "simulator/noise.h"
#include "tests/support/synthetic_view_internal.h"

namespace zebrageo::support {
namespace {

// Purpose of the sub-generator (sim::SubSeed; the bands use 301-303).
constexpr uint64_t kLineSeed = 304;

// The paint of one lane line of the street: points along its middle.
struct PaintedLine {
  RoadLineType type = RoadLineType::kLaneSolid;
  std::vector<Eigen::Vector3d> points;
};

std::vector<PaintedLine> PaintedLines(const sim::World& world,
                                      double spacing_m) {
  std::vector<PaintedLine> lines;
  for (const sim::LinePiece& piece : world.lines) {
    PaintedLine line;
    line.type = piece.type == "lane_dashed" ? RoadLineType::kLaneDashed
                                            : RoadLineType::kLaneSolid;
    const int n = std::max(
        1, static_cast<int>(std::floor((piece.s1 - piece.s0) / spacing_m)));
    for (int k = 0; k <= n; ++k) {
      const double s = piece.s0 + (piece.s1 - piece.s0) * k / n;
      line.points.push_back(world.road.SurfacePoint(s, piece.l_m));
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

// Whether the pair sees paint point `p` (inside both images, in range,
// beside the vehicle, hidden by no parked vehicle); its pixels in *uv.
bool Seen(const sim::World& world, const ReconstructionModel& model,
          const LineSynthesisOptions& options, const Pose& pose,
          const CameraView& left, const CameraView& right,
          const Eigen::Vector3d& p, Eigen::Vector2d uv[2]) {
  if ((p - left.centre_enu).norm() > options.max_range_m) return false;
  const Eigen::Vector3d right_of = pose.q_enu_body * Eigen::Vector3d::UnitY();
  if (std::abs((p - pose.p_enu).dot(right_of)) > options.max_lateral_m) {
    return false;
  }
  return ProjectInside(left, p, model.min_depth_m, model.margin_px, &uv[0]) &&
         ProjectInside(right, p, model.min_depth_m, model.margin_px, &uv[1]) &&
         !HiddenByVehicle(world, left.centre_enu, p) &&
         !HiddenByVehicle(world, right.centre_enu, p);
}

// Range noise of the band synthesis: sd along the left camera's ray and
// across it at `range_m`.
Eigen::Vector2d Sigmas(const ReconstructionModel& model, double range_m) {
  const double ray =
      model.ray_sigma_at_5m_m *
      std::pow(std::max(range_m, 1.0) / 5.0, model.range_exponent);
  return {ray, std::max(model.min_sigma_m, model.perpendicular_share * ray)};
}

// Appends one reconstructed line: the paint points `run` of `line`, with a
// noise part shared by the line (the road plane under it) and one per
// point, in the body frame of the true pose.
void AppendLine(const ReconstructionModel& model, const PaintedLine& line,
                const std::vector<int>& run,
                const std::vector<std::array<Eigen::Vector2d, 2>>& uv,
                const CameraView& left, const Eigen::Isometry3d& T_body_enu,
                ReconstructedLinePoint base, std::mt19937_64* rng,
                std::vector<ReconstructedLinePoint>* points) {
  const Eigen::Vector3d middle = line.points[run[run.size() / 2]];
  const Eigen::Vector3d ray0 = (middle - left.centre_enu).normalized();
  const Eigen::Vector2d sigma0 =
      Sigmas(model, (middle - left.centre_enu).norm());
  const double shared = std::sqrt(model.shared_share);
  const double own = std::sqrt(1.0 - model.shared_share);
  const Eigen::Vector3d common =
      sim::Gaussian(rng, shared * sigma0.x()) * ray0 +
      sim::Gaussian(rng, shared * sigma0.y()) * Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d R_body_enu = T_body_enu.linear();
  for (size_t i = 0; i < run.size(); ++i) {
    const Eigen::Vector3d& p = line.points[run[i]];
    const Eigen::Vector3d ray = (p - left.centre_enu).normalized();
    const Eigen::Vector2d sigma = Sigmas(model, (p - left.centre_enu).norm());
    const Eigen::Vector3d side =
        ray.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d up = side.cross(ray);
    const Eigen::Vector3d noise = common +
                                  sim::Gaussian(rng, own * sigma.x()) * ray +
                                  sim::Gaussian(rng, own * sigma.y()) * side +
                                  sim::Gaussian(rng, own * sigma.y()) * up;
    const Eigen::Matrix3d cov_enu =
        sigma.x() * sigma.x() * ray * ray.transpose() +
        sigma.y() * sigma.y() *
            (Eigen::Matrix3d::Identity() - ray * ray.transpose());
    ReconstructedLinePoint out = base;
    out.point = static_cast<int>(i);
    out.p_body = T_body_enu * (p + noise);
    out.covariance_body = R_body_enu * cov_enu * R_body_enu.transpose();
    const double px = model.pixel_sigma_px;
    out.uv_left = uv[i][0] + Eigen::Vector2d(sim::Gaussian(rng, px),
                                             sim::Gaussian(rng, px));
    out.uv_right = uv[i][1] + Eigen::Vector2d(sim::Gaussian(rng, px),
                                              sim::Gaussian(rng, px));
    points->push_back(out);
  }
}

}  // namespace

std::vector<ReconstructedLinePoint> SynthesiseLinePoints(
    const sim::SimulatedSurvey& survey, const ReconstructionModel& model,
    uint64_t seed, const LineSynthesisOptions& options) {
  std::mt19937_64 rng(sim::SubSeed(seed, kLineSeed));
  const sim::World& world = survey.world;
  const std::vector<PaintedLine> lines = PaintedLines(world, options.spacing_m);
  std::vector<ReconstructedLinePoint> points;
  int64_t next_line_id = 1;
  ForEachStereoView(
      survey, TruePoses(survey),
      [&](const Exposure& exposure, int pair, const Pose& pose,
          const Eigen::Isometry3d& T_body_enu, const CameraView& left,
          const CameraView& right) {
        for (const PaintedLine& line : lines) {
          // Runs of consecutive points seen: a vehicle hiding the middle of
          // a line splits it in two.
          std::vector<std::vector<int>> runs(1);
          std::vector<std::vector<std::array<Eigen::Vector2d, 2>>> uvs(1);
          for (int j = 0; j < static_cast<int>(line.points.size()); ++j) {
            Eigen::Vector2d uv[2];
            if (Seen(world, model, options, pose, left, right, line.points[j],
                     uv)) {
              runs.back().push_back(j);
              uvs.back().push_back({uv[0], uv[1]});
            } else if (!runs.back().empty()) {
              runs.emplace_back();
              uvs.emplace_back();
            }
          }
          for (size_t r = 0; r < runs.size(); ++r) {
            const std::vector<int>& run = runs[r];
            if (static_cast<int>(run.size()) < options.min_points) continue;
            const double recall = sim::Uniform(&rng, 0.0, 1.0);
            const Eigen::Vector3d middle = line.points[run[run.size() / 2]];
            if (recall >= model.RecallAt((middle - left.centre_enu).norm())) {
              continue;
            }
            ReconstructedLinePoint base;
            base.exposure_id = exposure.exposure_id;
            base.pair = pair;
            base.line_id = next_line_id++;
            base.type = line.type;
            AppendLine(model, line, run, uvs[r], left, T_body_enu, base, &rng,
                       &points);
          }
        }
      });
  return points;
}

}  // namespace zebrageo::support
