#include "reconstruction/search_volume.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0));
}

}  // namespace

std::string SearchVolumeOptions::Check() const {
  OptionCheck check;
  check.Require(std::abs(nominal_road_normal_body.norm() - 1.0) < 1e-3,
                "nominal_road_normal_body", nominal_road_normal_body.norm(),
                "must be a unit vector (its norm is shown)");
  OPTION_GT(check, nominal_camera_height_m, 0.0);
  OPTION_GT(check, initial_slab_half_thickness_m, 0.0);
  OPTION_LT(check, initial_slab_half_thickness_m, nominal_camera_height_m);
  OPTION_IN(check, initial_tolerance_angle_rad, "[", 0.0, 0.5, ")");
  OPTION_GE(check, initialization_exposures, 1);
  OPTION_GT(check, slab_half_thickness_m, 0.0);
  OPTION_IN(check, tolerance_angle_rad, "[", 0.0, 0.5, ")");
  OPTION_GE(check, running_window, 1);
  OPTION_GT(check, max_plane_change_rad, 0.0);
  OPTION_GT(check, max_plane_change_m, 0.0);
  return check.problem();
}

DisparityRange SlabDisparities(const RoadRectification& rectification,
                               const RoadPlane& prior,
                               double slab_half_thickness_m,
                               double tolerance_angle_rad) {
  const RoadRectification* rect = &rectification;
  const Eigen::Vector3d centre = rect->left_centre_body();
  const Eigen::Vector3d nadir = prior.Project(centre);
  const double fb = rect->focal_px() * rect->baseline_m();
  const double tan_theta = std::tan(tolerance_angle_rad);
  return [rect, prior, centre, nadir, fb, tan_theta, slab_half_thickness_m](
             double x, double y, double* d_min, double* d_max) {
    // The virtual z component of RayBody is 1, so the ray parameter of a
    // plane crossing is the depth Z, and the disparity is fB / Z.
    const Eigen::Vector3d ray = rect->RayBody(0, Eigen::Vector2d(x, y));
    const double denominator = prior.normal_body.dot(ray);
    if (!(denominator > 1e-9)) return false;
    const double depth =
        (prior.offset_m - prior.normal_body.dot(centre)) / denominator;
    if (!(depth > 0.0)) return false;
    const double distance = (centre + depth * ray - nadir).norm();
    const double half = slab_half_thickness_m + distance * tan_theta;
    const double near =
        (prior.offset_m - half - prior.normal_body.dot(centre)) / denominator;
    const double far =
        (prior.offset_m + half - prior.normal_body.dot(centre)) / denominator;
    if (!(far > 0.0)) return false;
    *d_min = fb / far - rect->disparity_offset_px();
    *d_max = (near > 0.0 ? fb / near : 1e9) - rect->disparity_offset_px();
    return true;
  };
}

RoadPlane NominalRoadPlane(const Rig& rig, const SearchVolumeOptions& options) {
  RoadPlane nominal;
  nominal.normal_body = options.nominal_road_normal_body.normalized();
  double mean_depth = 0.0;
  int count = 0;
  for (const auto& pair : rig.stereo_pairs) {
    for (int camera : pair) {
      mean_depth +=
          nominal.normal_body.dot(rig.cameras[camera].T_body_cam.translation());
      ++count;
    }
  }
  nominal.offset_m = mean_depth / count + options.nominal_camera_height_m;
  return nominal;
}

std::vector<int> InitializationExposures(int count,
                                         const SearchVolumeOptions& options) {
  std::vector<int> init_exposures;
  const int n = count;
  const int wanted = std::min(n, options.initialization_exposures);
  for (int k = 0; k < wanted; ++k) {
    const int index = static_cast<int>((k + 0.5) * n / wanted);
    if (init_exposures.empty() || init_exposures.back() != index) {
      init_exposures.push_back(std::min(index, n - 1));
    }
  }
  return init_exposures;
}

RoadPlane MedianPlane(const std::vector<RoadPlane>& planes) {
  std::vector<double> x, y, z, offset;
  for (const RoadPlane& p : planes) {
    x.push_back(p.normal_body.x());
    y.push_back(p.normal_body.y());
    z.push_back(p.normal_body.z());
    offset.push_back(p.offset_m);
  }
  RoadPlane plane;
  plane.normal_body =
      Eigen::Vector3d(Median(x), Median(y), Median(z)).normalized();
  plane.offset_m = Median(offset);
  return plane;
}

RoadPlaneTracker::RoadPlaneTracker(const RoadPlane& initial,
                                   const SearchVolumeOptions& options)
    : plane_(initial), options_(options) {}

void RoadPlaneTracker::Add(const RoadPlane& fit) {
  if (AngleBetween(fit.normal_body, plane_.normal_body) >
          options_.max_plane_change_rad ||
      std::abs(fit.offset_m - plane_.offset_m) > options_.max_plane_change_m) {
    return;
  }
  recent_.push_back(fit);
  if (static_cast<int>(recent_.size()) > options_.running_window) {
    recent_.pop_front();
  }
}

void RoadPlaneTracker::Update() {
  if (!recent_.empty()) {
    plane_ =
        MedianPlane(std::vector<RoadPlane>(recent_.begin(), recent_.end()));
  }
}

}  // namespace zebrageo
