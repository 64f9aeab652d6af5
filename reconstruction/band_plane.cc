#include "reconstruction/band_plane.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

namespace zebrageo {

bool FitBandPlane(const std::vector<Eigen::Vector3d>& points,
                  const Eigen::Vector3d& along, const Eigen::Vector3d& normal,
                  double min_sigma_m, BandPlaneFit* fit) {
  if (!FitPlaneLeastSquares(points, normal, &fit->plane)) return false;
  const Eigen::Vector3d n = fit->plane.normal_body;
  fit->x_axis = (along - along.dot(n) * n).normalized();
  fit->y_axis = n.cross(fit->x_axis);
  fit->centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) fit->centroid += p;
  fit->centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
  double sum_squares = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - fit->centroid;
    const Eigen::Vector3d j(d.dot(fit->x_axis), d.dot(fit->y_axis), 1.0);
    normal_matrix += j * j.transpose();
    sum_squares += fit->plane.SignedDistance(p) * fit->plane.SignedDistance(p);
  }
  fit->count = static_cast<int>(points.size());
  fit->rms_m = std::sqrt(sum_squares / std::max(1, fit->count - 3));
  const double sigma = std::max(fit->rms_m, min_sigma_m);
  fit->covariance = sigma * sigma * normal_matrix.inverse();
  return true;
}

bool FitRobustBandPlane(std::vector<Eigen::Vector3d> points,
                        const Eigen::Vector3d& along,
                        const Eigen::Vector3d& normal, double min_sigma_m,
                        BandPlaneFit* fit) {
  if (!FitBandPlane(points, along, normal, min_sigma_m, fit)) return false;
  const double limit = std::max(0.01, 3.0 * fit->rms_m);
  const size_t before = points.size();
  points.erase(std::remove_if(points.begin(), points.end(),
                              [&](const Eigen::Vector3d& p) {
                                return std::abs(fit->plane.SignedDistance(p)) >
                                       limit;
                              }),
               points.end());
  if (points.size() == before) return true;
  return FitBandPlane(points, along, normal, min_sigma_m, fit);
}

bool FitPlaneOfBand(const std::vector<EdgePoint3d>& points,
                    const PlaneFrame& frame, const LongSide& lo,
                    const LongSide& hi, double begin_m, double end_m,
                    double margin_m, double min_sigma_m, BandPlaneFit* fit) {
  const Eigen::Vector2d along = lo.direction_2d;
  std::vector<Eigen::Vector3d> support;
  for (const LongSide* side : {&lo, &hi}) {
    for (int p : side->support) {
      const double t = frame.To2d(points[p].p_chain_body).dot(along);
      if (t < begin_m - margin_m || t > end_m + margin_m) continue;
      support.push_back(points[p].p_body);
    }
  }
  return FitRobustBandPlane(support, lo.direction_body, frame.normal,
                            min_sigma_m, fit);
}

Eigen::Vector3d OnBandPlane(const PlaneFrame& frame, const RoadPlane& plane,
                            const Eigen::Vector2d& q) {
  const Eigen::Vector3d p = frame.To3d(q);
  const double denominator = plane.normal_body.dot(frame.normal);
  return p - plane.SignedDistance(p) / denominator * frame.normal;
}

LongSide SideAlongBand(const std::vector<EdgePoint3d>& points,
                       const PlaneFrame& frame, const LongSide& side,
                       double begin_m, double end_m, double margin_m) {
  double low, high;
  SideExtent(frame, side, side.direction_2d, &low, &high);
  if (low >= begin_m - margin_m && high <= end_m + margin_m) return side;
  std::vector<int> within;
  for (int p : side.support) {
    const double t = frame.To2d(points[p].p_chain_body).dot(side.direction_2d);
    if (t >= begin_m - margin_m && t <= end_m + margin_m) within.push_back(p);
  }
  if (2 * within.size() < side.support.size() || within.size() < 10) {
    return side;
  }
  return FitLongSide(points, std::move(within), frame, side.direction_2d,
                     side.direction_set);
}

}  // namespace zebrageo
