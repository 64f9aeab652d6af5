// The band's own plane (Soheilian et al., section 5): fitted on the 3D
// points of its two long sides along the band, so that a crossing on a
// cambered road is not constrained to be planar; the band's vertices are
// projected onto it.
//
// Frames: body (FRD), metres; the plane frame of long_sides.h.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_PLANE_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_PLANE_H_

#include <Eigen/Core>
#include <vector>

#include "reconstruction/long_sides.h"
#include "reconstruction/road_plane.h"

namespace zebrageo {

// Least-squares plane of a band and the variance of its height at a point:
// z = a x + b y + c in the band's own frame (x along, y across, z normal).
struct BandPlaneFit {
  RoadPlane plane;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis, y_axis;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of (a, b, c)
  double rms_m = 0.0;
  int count = 0;

  double HeightVariance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - centroid;
    const Eigen::Vector3d j(d.dot(x_axis), d.dot(y_axis), 1.0);
    return j.dot(covariance * j);
  }
};

// Least-squares plane of `points`; its axes: x along `along`, z along
// `normal` (orientation). False for fewer than 3 points or collinear ones.
bool FitBandPlane(const std::vector<Eigen::Vector3d>& points,
                  const Eigen::Vector3d& along, const Eigen::Vector3d& normal,
                  double min_sigma_m, BandPlaneFit* fit);

// FitBandPlane, then again without the points more than 3 rms (at least
// 1 cm) off the plane (mismatched edge points).
bool FitRobustBandPlane(std::vector<Eigen::Vector3d> points,
                        const Eigen::Vector3d& along,
                        const Eigen::Vector3d& normal, double min_sigma_m,
                        BandPlaneFit* fit);

// The plane of the band between the long sides lo and hi from their
// points within `margin_m` of its extent [begin_m, end_m] along it only: a
// side may run on beyond it (along a lane line, a vehicle's shadow), and
// what it runs on to may not lie on the road (a 3 cm height rms tilted a
// band's plane by 2 degrees and moved its ends 20 cm out, sim08).
bool FitPlaneOfBand(const std::vector<EdgePoint3d>& points,
                    const PlaneFrame& frame, const LongSide& lo,
                    const LongSide& hi, double begin_m, double end_m,
                    double margin_m, double min_sigma_m, BandPlaneFit* fit);

// Lifts a plane-frame point vertically (along the frame normal) onto the
// band plane.
Eigen::Vector3d OnBandPlane(const PlaneFrame& frame, const RoadPlane& plane,
                            const Eigen::Vector2d& q);

// `side` fitted again on its points within `margin_m` of the band's extent
// [begin_m, end_m] along its set's direction, when it runs on beyond that
// by more than margin_m and at least half of its points are within.
LongSide SideAlongBand(const std::vector<EdgePoint3d>& points,
                       const PlaneFrame& frame, const LongSide& side,
                       double begin_m, double end_m, double margin_m);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_PLANE_H_
