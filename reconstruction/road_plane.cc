#include "reconstruction/road_plane.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>
#include <sstream>

#include "survey/option_check.h"

namespace zebrageo {

bool RoadPlane::IntersectRay(const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& direction,
                             Eigen::Vector3d* p_body) const {
  const double denominator = normal_body.dot(direction);
  if (std::abs(denominator) < 1e-12) return false;
  const double t = (offset_m - normal_body.dot(origin)) / denominator;
  if (!(t > 0.0)) return false;
  *p_body = origin + t * direction;
  return true;
}

std::string RoadPlaneOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, ransac_tolerance_m, 0.0);
  OPTION_GE(check, ransac_iterations, 1);
  OPTION_GT(check, keep_distance_m, 0.0);
  OPTION_IN(check, max_normal_deviation_rad, "(", 0.0, 1.5, ")");
  OPTION_GE(check, min_inliers, 3);
  return check.problem();
}

bool FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& orientation,
                          RoadPlane* plane) {
  if (points.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    scatter += (p - mean) * (p - mean).transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d values = solver.eigenvalues();  // ascending
  if (!(values(1) > 1e-12)) return false;               // collinear
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (normal.dot(orientation) < 0.0) normal = -normal;
  plane->normal_body = normal;
  plane->offset_m = normal.dot(mean);
  return true;
}

RoadPlaneFit FitRoadPlane(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& expected_normal,
                          const RoadPlaneOptions& options, uint64_t seed) {
  RoadPlaneFit fit;
  const int n = static_cast<int>(points.size());
  if (n < std::max(3, options.min_inliers)) return fit;
  const Eigen::Vector3d expected = expected_normal.normalized();
  const double min_cos = std::cos(options.max_normal_deviation_rad);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best_count = 0;
  RoadPlane best;
  for (int iteration = 0; iteration < options.ransac_iterations; ++iteration) {
    const Eigen::Vector3d& a = points[pick(rng)];
    const Eigen::Vector3d& b = points[pick(rng)];
    const Eigen::Vector3d& c = points[pick(rng)];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    const double norm = normal.norm();
    if (!(norm > 1e-9)) continue;
    normal /= norm;
    if (normal.dot(expected) < 0.0) normal = -normal;
    if (normal.dot(expected) < min_cos) continue;
    const double offset = normal.dot(a);
    int count = 0;
    for (const Eigen::Vector3d& p : points) {
      count += std::abs(normal.dot(p) - offset) <= options.ransac_tolerance_m;
    }
    if (count > best_count) {
      best_count = count;
      best.normal_body = normal;
      best.offset_m = offset;
    }
  }
  if (best_count < options.min_inliers) return fit;

  // Least squares on the inliers, twice (the second with keep_distance_m).
  RoadPlane plane = best;
  double tolerance = options.ransac_tolerance_m;
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Vector3d> inliers;
    for (const Eigen::Vector3d& p : points) {
      if (std::abs(plane.SignedDistance(p)) <= tolerance) inliers.push_back(p);
    }
    RoadPlane refined;
    if (!FitPlaneLeastSquares(inliers, expected, &refined)) return fit;
    if (refined.normal_body.dot(expected) < min_cos) return fit;
    plane = refined;
    tolerance = options.keep_distance_m;
  }
  double sum_squares = 0.0;
  for (int i = 0; i < n; ++i) {
    const double distance = plane.SignedDistance(points[i]);
    if (std::abs(distance) <= options.keep_distance_m) {
      fit.inliers.push_back(i);
      sum_squares += distance * distance;
    }
  }
  if (static_cast<int>(fit.inliers.size()) < options.min_inliers) return fit;
  fit.ok = true;
  fit.plane = plane;
  fit.rms_m = std::sqrt(sum_squares / fit.inliers.size());
  return fit;
}

}  // namespace zebrageo
