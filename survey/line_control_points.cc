#include "survey/line_control_points.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace zebrageo {

Eigen::Matrix2d LineSqrtInformation(const Eigen::Matrix3d& covariance_body,
                                    const Eigen::Matrix3d& R_enu_body,
                                    const Eigen::Vector3d& across_enu,
                                    double db_sigma_xy_m, double db_sigma_z_m) {
  Eigen::Matrix<double, 2, 3> J;
  J.row(0) = across_enu.transpose();
  J.row(1) = Eigen::Vector3d::UnitZ().transpose();
  Eigen::Matrix2d C =
      J * R_enu_body * covariance_body * R_enu_body.transpose() * J.transpose();
  C(0, 0) += db_sigma_xy_m * db_sigma_xy_m;
  C(1, 1) += db_sigma_z_m * db_sigma_z_m;
  // C = L L^T  ->  S = L^-1 whitens: S C S^T = I.
  const Eigen::Matrix2d L = C.llt().matrixL();
  return L.inverse();
}

bool CorrectedPoseAt(const CorrectedTrajectory& trajectory, double time,
                     Pose* pose) {
  const auto& samples = *trajectory.samples;
  if (samples.size() < 2 || trajectory.poses->size() != samples.size() ||
      time < samples.front().time || time > samples.back().time) {
    return false;
  }
  const auto it = std::upper_bound(
      samples.begin(), samples.end(), time,
      [](double t, const TrajectorySample& s) { return t < s.time; });
  const size_t i = std::min<size_t>(
      std::max<ptrdiff_t>(0, it - samples.begin() - 1), samples.size() - 2);
  const double span = samples[i + 1].time - samples[i].time;
  const double u = span > 0.0 ? (time - samples[i].time) / span : 0.0;
  *pose =
      InterpolatePoses((*trajectory.poses)[i], (*trajectory.poses)[i + 1], u);
  return true;
}

double PosteriorSdAt(const CorrectedTrajectory& trajectory, double time) {
  const auto& samples = *trajectory.samples;
  if (samples.empty()) return 0.0;
  const auto it = std::lower_bound(
      samples.begin(), samples.end(), time,
      [](const TrajectorySample& s, double t) { return s.time < t; });
  const TrajectorySample& s = it == samples.end() ? samples.back() : *it;
  return std::hypot(s.sd_enu_m.x(), s.sd_enu_m.y());
}

std::vector<double> CrossTrackTimes(
    const std::vector<LineControlPoint>& control) {
  std::vector<double> times;
  for (const LineControlPoint& c : control) {
    if (!c.along_track && c.sqrt_information.row(0).norm() > 0.0) {
      times.push_back(c.time);
    }
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

std::vector<double> FittedCrossTrackTimes(
    const std::vector<LineControlPoint>& control,
    const CorrectedTrajectory& trajectory, double max_residual_m) {
  std::vector<LineControlPoint> fitted;
  for (const LineControlPoint& c : control) {
    Pose pose;
    if (!CorrectedPoseAt(trajectory, c.time, &pose)) continue;
    const double residual =
        c.across_enu.dot(pose.T_enu_body() * c.p_body - c.db_point_enu);
    if (std::abs(residual) <= max_residual_m) fitted.push_back(c);
  }
  return CrossTrackTimes(fitted);
}

}  // namespace zebrageo
