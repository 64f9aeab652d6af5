// Internal to the synthetic reconstruction (bands and lines): a camera of
// the rig placed with a TRUE pose, and what it images.
#ifndef ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_VIEW_INTERNAL_H_
#define ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_VIEW_INTERNAL_H_

#include <Eigen/Geometry>
#include <cstdint>
#include <map>

#include "simulator/simulated_survey.h"
#include "survey/rig.h"
#include "survey/trajectory.h"

namespace zebrageo::support {

struct CameraView {
  Eigen::Isometry3d T_cam_enu;
  Eigen::Vector3d centre_enu;
  const Camera* camera;
};

inline CameraView ViewOf(const Rig& rig, int camera, const Pose& pose) {
  const Eigen::Isometry3d T_enu_cam =
      pose.T_enu_body() * rig.cameras[camera].T_body_cam;
  return {T_enu_cam.inverse(), T_enu_cam.translation(),
          &rig.cameras[camera].camera};
}

// False unless `p_enu` lies min_depth_m in front of the camera and
// projects margin_px inside its image (*uv).
inline bool ProjectInside(const CameraView& view, const Eigen::Vector3d& p_enu,
                          double min_depth_m, double margin_px,
                          Eigen::Vector2d* uv) {
  const Eigen::Vector3d p_cam = view.T_cam_enu * p_enu;
  if (p_cam.z() < min_depth_m) return false;
  return view.camera->Project(p_cam, uv) &&
         view.camera->IsInImage(*uv, margin_px);
}

// Calls view(exposure, pair, true pose, T_body_enu, left, right) for every
// stereo pair of every exposure of `survey` with a true pose, in order.
template <typename View>
void ForEachStereoView(const sim::SimulatedSurvey& survey,
                       const std::map<int64_t, Pose>& true_pose, View view) {
  const Rig& rig = survey.rig;
  for (const Exposure& exposure : survey.exposures.exposures) {
    const auto pose_it = true_pose.find(exposure.exposure_id);
    if (pose_it == true_pose.end()) continue;
    const Pose& pose = pose_it->second;
    const Eigen::Isometry3d T_body_enu = pose.T_enu_body().inverse();
    for (int pair = 0; pair < static_cast<int>(rig.stereo_pairs.size());
         ++pair) {
      view(exposure, pair, pose, T_body_enu,
           ViewOf(rig, rig.stereo_pairs[pair][0], pose),
           ViewOf(rig, rig.stereo_pairs[pair][1], pose));
    }
  }
}

}  // namespace zebrageo::support

#endif  // ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_VIEW_INTERNAL_H_
