// The search volume of edge matching (Soheilian et al., section 3.1): a
// slab around the road plane whose half-thickness grows with the distance
// from the cameras (the tolerance angle theta on the rig's attitude over
// the road), and the road plane it is centred on: a nominal plane below
// the cameras, estimated on a few exposures, then tracked as the median of
// the latest per-pair fits.
//
// Frames: body (FRD), metres; rectified pixels for disparities (see
// road_rectification.h).
#ifndef ZEBRAGEO_RECONSTRUCTION_SEARCH_VOLUME_H_
#define ZEBRAGEO_RECONSTRUCTION_SEARCH_VOLUME_H_

#include <Eigen/Core>
#include <deque>
#include <string>
#include <vector>

#include "reconstruction/edge_matching.h"
#include "reconstruction/road_plane.h"
#include "reconstruction/road_rectification.h"
#include "survey/rig.h"

namespace zebrageo {

struct SearchVolumeOptions {
  // Nominal road normal in the body frame, pointing down (body +z for a
  // level vehicle). Only a starting point: the plane is estimated.
  Eigen::Vector3d nominal_road_normal_body = Eigen::Vector3d::UnitZ();
  // Nominal height of the cameras over the road along that normal, metres
  // (roof-mounted mapping cameras: 2 to 3 m).
  double nominal_camera_height_m = 2.3;
  // Half-thickness of the slab while the plane is first estimated: covers
  // the error of the nominal height.
  double initial_slab_half_thickness_m = 1.0;
  double initial_tolerance_angle_rad = 0.1;
  // Exposures (spread over the survey) used for the first estimate.
  int initialization_exposures = 8;
  // Slab once the plane is known: half-thickness at the cameras, plus
  // distance * tan(tolerance_angle_rad) (vehicle roll and pitch on its
  // suspension, road camber).
  double slab_half_thickness_m = 0.15;
  double tolerance_angle_rad = 0.03;
  // The running plane is the median of the last this-many per-pair fits.
  int running_window = 15;
  // Per-pair fits farther than this from the running plane (angle, offset)
  // do not update it.
  double max_plane_change_rad = 0.05;
  double max_plane_change_m = 0.15;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("nominal_road_normal_body", nominal_road_normal_body);
    v("nominal_camera_height_m", nominal_camera_height_m);
    v("initial_slab_half_thickness_m", initial_slab_half_thickness_m);
    v("initial_tolerance_angle_rad", initial_tolerance_angle_rad);
    v("initialization_exposures", initialization_exposures);
    v("slab_half_thickness_m", slab_half_thickness_m);
    v("tolerance_angle_rad", tolerance_angle_rad);
    v("running_window", running_window);
    v("max_plane_change_rad", max_plane_change_rad);
    v("max_plane_change_m", max_plane_change_m);
  }
};

// The residual disparities of the slab around `prior` (half-thickness
// slab_half_thickness_m at the cameras' nadir, plus distance *
// tan(tolerance_angle_rad)) for the left rectified pixels of
// `rectification`, which must outlive the result.
DisparityRange SlabDisparities(const RoadRectification& rectification,
                               const RoadPlane& prior,
                               double slab_half_thickness_m,
                               double tolerance_angle_rad);

// The nominal road plane: along nominal_road_normal_body,
// nominal_camera_height_m below the mean of the rig's stereo cameras.
RoadPlane NominalRoadPlane(const Rig& rig, const SearchVolumeOptions& options);

// Indices of the initialization_exposures exposures (of `count`, in time
// order) spread over the survey, on which the plane is first estimated.
std::vector<int> InitializationExposures(int count,
                                         const SearchVolumeOptions& options);

// Component-wise median of plane normals and offsets (normal made unit):
// robust to a few wrong per-pair fits. `planes` must not be empty.
RoadPlane MedianPlane(const std::vector<RoadPlane>& planes);

// The running road plane while exposures are processed in time order: the
// median of the last running_window per-pair fits close to it.
class RoadPlaneTracker {
 public:
  RoadPlaneTracker(const RoadPlane& initial,
                   const SearchVolumeOptions& options);
  const RoadPlane& plane() const { return plane_; }
  // Remembers a per-pair fit, unless it is farther than
  // max_plane_change_rad / max_plane_change_m from plane().
  void Add(const RoadPlane& fit);
  // plane() becomes the median of the remembered fits (none: unchanged).
  void Update();

 private:
  RoadPlane plane_;
  SearchVolumeOptions options_;
  std::deque<RoadPlane> recent_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_SEARCH_VOLUME_H_
