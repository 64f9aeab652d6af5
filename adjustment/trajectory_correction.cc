#include "adjustment/trajectory_correction.h"

#include <ceres/rotation.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>

namespace zebrageo {

void CubicBSplineBasis(double u, double weights[4]) {
  const double u2 = u * u;
  const double u3 = u2 * u;
  const double v = 1.0 - u;
  weights[0] = v * v * v / 6.0;
  weights[1] = (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0;
  weights[2] = (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0;
  weights[3] = u3 / 6.0;
}

TrajectoryCorrection::TrajectoryCorrection(double start_time, double end_time,
                                           double knot_spacing_s,
                                           bool track_frame)
    : start_(start_time), spacing_(knot_spacing_s), track_frame_(track_frame) {
  CHECK_GT(end_time, start_time);
  CHECK_GT(knot_spacing_s, 0.0);
  num_segments_ = std::max(
      1,
      static_cast<int>(std::ceil((end_time - start_time) / spacing_ - 1e-9)));
  Knot zero;
  zero.fill(0.0);
  knots_.assign(num_segments_ + 3, zero);
}

void TrajectoryCorrection::Basis(double time, int* first_knot,
                                 double weights[4]) const {
  const double x = (time - start_) / spacing_;
  int segment = static_cast<int>(std::floor(x));
  segment = std::clamp(segment, 0, num_segments_ - 1);
  const double u = std::clamp(x - segment, 0.0, 1.0);
  *first_knot = segment;
  CubicBSplineBasis(u, weights);
}

Eigen::Matrix<double, 6, 1> TrajectoryCorrection::Evaluate(double time) const {
  int first = 0;
  double w[4];
  Basis(time, &first, w);
  Eigen::Matrix<double, 6, 1> c = Eigen::Matrix<double, 6, 1>::Zero();
  for (int j = 0; j < 4; ++j) {
    c += w[j] * Eigen::Map<const Eigen::Matrix<double, 6, 1>>(
                    knots_[first + j].data());
  }
  return c;
}

Eigen::Matrix3d TrackFrame(const Pose& ins_pose) {
  Eigen::Vector3d forward = ins_pose.q_enu_body * Eigen::Vector3d::UnitX();
  forward.z() = 0.0;
  if (forward.norm() < 1e-6) forward = Eigen::Vector3d::UnitX();
  forward.normalize();
  Eigen::Matrix3d R;
  R.col(0) = forward;
  R.col(2) = Eigen::Vector3d::UnitZ();
  R.col(1) = R.col(2).cross(forward);
  return R;
}

Eigen::Matrix3d TrajectoryCorrection::Frame(const Pose& ins_pose) const {
  return track_frame_ ? TrackFrame(ins_pose) : Eigen::Matrix3d::Identity();
}

Pose TrajectoryCorrection::Apply(double time, const Pose& ins_pose) const {
  const Eigen::Matrix<double, 6, 1> c = Evaluate(time);
  const Eigen::Matrix3d R_enu_track = Frame(ins_pose);
  const Eigen::Vector3d dtheta = R_enu_track * c.head<3>();
  const double angle = dtheta.norm();
  const Eigen::Quaterniond dq =
      angle > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, dtheta / angle))
                  : Eigen::Quaterniond::Identity();
  Pose corrected;
  corrected.q_enu_body = (dq * ins_pose.q_enu_body).normalized();
  corrected.p_enu = ins_pose.p_enu + R_enu_track * c.tail<3>();
  return corrected;
}

}  // namespace zebrageo
