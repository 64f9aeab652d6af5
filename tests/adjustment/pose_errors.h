// Camera pose errors against a synthetic survey's truth, computed as
// ../shared/tools/score_results.py does (mode poses): horizontal and
// vertical error of the projection centre, rotation angle of the attitude.
#ifndef ZEBRAGEO_TESTS_ADJUSTMENT_POSE_ERRORS_H_
#define ZEBRAGEO_TESTS_ADJUSTMENT_POSE_ERRORS_H_

#include <cmath>
#include <vector>

#include "survey/results.h"
#include "tests/support/synthetic_survey.h"

namespace zebrageo {

struct PoseErrors {
  double rmse_horizontal_m = 0.0;
  double rmse_vertical_m = 0.0;
  double rmse_attitude_deg = 0.0;
  double max_horizontal_m = 0.0;
  int count = 0;
};

inline PoseErrors ScorePoses(const SyntheticSurvey& survey,
                             const std::vector<CameraPose>& poses) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  PoseErrors e;
  double h2 = 0.0, v2 = 0.0, a2 = 0.0;
  for (const CameraPose& p : poses) {
    Pose pose;
    if (!truth.InterpolatePose(p.time, &pose)) continue;
    const int camera = survey.rig.FindCamera(p.camera);
    const Eigen::Isometry3d T =
        pose.T_enu_body() * survey.rig.cameras[camera].T_body_cam;
    const Eigen::Vector3d d = p.p_enu - T.translation();
    const double angle =
        Eigen::AngleAxisd(Eigen::Quaterniond(T.linear()).inverse() *
                          p.q_enu_cam)
            .angle() *
        180.0 / M_PI;
    h2 += d.head<2>().squaredNorm();
    v2 += d.z() * d.z();
    a2 += angle * angle;
    e.max_horizontal_m = std::max(e.max_horizontal_m, d.head<2>().norm());
    ++e.count;
  }
  if (e.count > 0) {
    e.rmse_horizontal_m = std::sqrt(h2 / e.count);
    e.rmse_vertical_m = std::sqrt(v2 / e.count);
    e.rmse_attitude_deg = std::sqrt(a2 / e.count);
  }
  return e;
}

// The input (drifting) trajectory's camera poses, for "before" figures.
inline std::vector<CameraPose> InputCameraPoses(const SyntheticSurvey& survey) {
  const Trajectory measured(survey.measured_samples, survey.frame);
  std::vector<CameraPose> poses;
  for (const ExposureImage& image : survey.exposures.images) {
    Pose pose;
    if (!measured.InterpolatePose(image.time, &pose)) continue;
    const Eigen::Isometry3d T =
        pose.T_enu_body() * survey.rig.cameras[image.camera].T_body_cam;
    CameraPose p;
    p.exposure_id = image.exposure_id;
    p.camera = survey.rig.cameras[image.camera].camera.name();
    p.time = image.time;
    p.p_enu = T.translation();
    p.q_enu_cam = Eigen::Quaterniond(T.linear());
    poses.push_back(p);
  }
  return poses;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_ADJUSTMENT_POSE_ERRORS_H_
