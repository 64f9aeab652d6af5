// The road plane (RoadPlane) and its robust estimate (Soheilian et al.,
// section 4.2): RANSAC with a 20 cm tolerance on the 3D edge points, then
// least squares on the points close to it. Frames: body (FRD), metres; the
// normal points down (see RoadPlane).
#ifndef ZEBRAGEO_RECONSTRUCTION_ROAD_PLANE_H_
#define ZEBRAGEO_RECONSTRUCTION_ROAD_PLANE_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace zebrageo {

// The road plane in the body frame: points p with normal_body . p =
// offset_m. `normal_body` is a unit vector pointing DOWN (into the road, body
// +z for a level vehicle), so offset_m is the road's depth below the body
// origin along the normal.
struct RoadPlane {
  Eigen::Vector3d normal_body = Eigen::Vector3d::UnitZ();
  double offset_m = 0.0;

  // Positive below the road, negative above (between road and cameras).
  double SignedDistance(const Eigen::Vector3d& p_body) const {
    return normal_body.dot(p_body) - offset_m;
  }
  // Orthogonal projection of a point onto the plane.
  Eigen::Vector3d Project(const Eigen::Vector3d& p_body) const {
    return p_body - SignedDistance(p_body) * normal_body;
  }
  // Intersection of the ray origin + t * direction (t > 0) with the plane.
  bool IntersectRay(const Eigen::Vector3d& origin,
                    const Eigen::Vector3d& direction,
                    Eigen::Vector3d* p_body) const;
};

struct RoadPlaneOptions {
  // RANSAC inlier distance to the plane (the paper's 20 cm).
  double ransac_tolerance_m = 0.2;
  int ransac_iterations = 300;
  // After the least-squares refinement, points farther than this from the
  // plane are not road (the paper filters at 20 cm as well).
  double keep_distance_m = 0.2;
  // Planes whose normal is farther than this from the expected normal are
  // not the road (facades, car bodies).
  double max_normal_deviation_rad = 0.25;
  // Fewer inliers than this: no plane.
  int min_inliers = 30;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("ransac_tolerance_m", ransac_tolerance_m);
    v("ransac_iterations", ransac_iterations);
    v("keep_distance_m", keep_distance_m);
    v("max_normal_deviation_rad", max_normal_deviation_rad);
    v("min_inliers", min_inliers);
  }
};

struct RoadPlaneFit {
  bool ok = false;
  RoadPlane plane;
  std::vector<int> inliers;  // indices of the points within keep_distance_m
  double rms_m = 0.0;        // of the inliers' distances
};

// Fits the road plane to `points`. `expected_normal` orients the normal
// (down) and bounds its deviation. Deterministic for a given seed.
RoadPlaneFit FitRoadPlane(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& expected_normal,
                          const RoadPlaneOptions& options, uint64_t seed);

// Least-squares plane through points (unit normal, oriented along
// `orientation`); false for fewer than 3 points or collinear ones.
bool FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points,
                          const Eigen::Vector3d& orientation, RoadPlane* plane);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_ROAD_PLANE_H_
