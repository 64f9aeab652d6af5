// Road lines as control, between their registration to the database
// (registration/line_registration.h) and the adjustment's point-to-line
// residuals (adjustment/line_costs.h): the control points, and the
// corrected trajectory the registration places the lines with.
#ifndef ZEBRAGEO_SURVEY_LINE_CONTROL_POINTS_H_
#define ZEBRAGEO_SURVEY_LINE_CONTROL_POINTS_H_

#include <Eigen/Core>
#include <vector>

#include "survey/trajectory.h"

namespace zebrageo {

// One matched line point, as the adjustment reads it.
struct LineControlPoint {
  double time = 0.0;
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d db_point_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d across_enu = Eigen::Vector3d::UnitX();  // horizontal unit
  Eigen::Vector3d along_enu = Eigen::Vector3d::UnitY();   // horizontal unit
  double grade = 0.0;  // of the database segment: dz per horizontal metre
  // Whitening of [across, up] (2 x 2, lower triangular).
  Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Identity();
  // A dash's centre on the database dash's (registration/dash_matcher.h):
  // it holds the position ALONG the dash, so across_enu holds the dash's
  // direction and row 0 of the whitening its sd; row 1 is zero (the dash's
  // points hold the height). The same residual; never a cross-track
  // discrepancy.
  bool along_track = false;
};

// S such that S C S^T = I for the 2 x 2 covariance of [across, up]:
// covariance_body rotated by R_enu_body, plus the database's sigmas.
Eigen::Matrix2d LineSqrtInformation(const Eigen::Matrix3d& covariance_body,
                                    const Eigen::Matrix3d& R_enu_body,
                                    const Eigen::Vector3d& across_enu,
                                    double db_sigma_xy_m, double db_sigma_z_m);

// A trajectory an adjustment corrected: one pose per sample (ENU), the
// samples' sd_* the posterior ones. Pointers, not owned.
struct CorrectedTrajectory {
  const std::vector<TrajectorySample>* samples = nullptr;
  const std::vector<Pose>* poses = nullptr;
  // False: the adjustment had no control and kept the input trajectory.
  bool corrected = false;
};

// The corrected body pose at `time` (InterpolatePoses, as Trajectory does:
// linear in position, slerp in attitude between the samples); false
// outside them.
bool CorrectedPoseAt(const CorrectedTrajectory& trajectory, double time,
                     Pose* pose);
// The posterior horizontal sd (radial) at `time`, from the nearest sample.
double PosteriorSdAt(const CorrectedTrajectory& trajectory, double time);

// The times of the control points that hold the position across their line
// (not the height alone, not a dash's along-track position), sorted, each
// once.
std::vector<double> CrossTrackTimes(
    const std::vector<LineControlPoint>& control);

// Of CrossTrackTimes, those at which `trajectory` fits the control point
// across its line within max_residual_m: a point it does not fit (a GNSS
// switch the smooth correction could not follow, a line moved in the
// database) measured nothing the trajectory holds.
std::vector<double> FittedCrossTrackTimes(
    const std::vector<LineControlPoint>& control,
    const CorrectedTrajectory& trajectory, double max_residual_m);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_LINE_CONTROL_POINTS_H_
