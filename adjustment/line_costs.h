// Road lines as control (issue 9, step 3): point-to-line residuals of the
// control points registration/line_registration.h makes
// (survey/line_control_points.h).
//
// A point of a reconstructed road line (body frame, at an exposure time t)
// matched to a database line (registration/line_matcher.h) is placed in ENU
// through the corrected trajectory,
//   X = p_ins + dp + Exp(dtheta) R_ins p_body      (cost_functions.h),
// and compared with the database line there in the two directions a line
// constrains: across it (horizontal unit normal) and in height:
//   r = S [across . (X - D), (X - D).z - grade along . (X - D)]
// D: the database line's point nearest to the match (placed with the INS
// trajectory); along, grade: the horizontal direction of its segment and
// its slope (dz per horizontal metre), so the height is compared with the
// line where the corrected point lies, not where the drifting INS put it
// (a metre of along-track drift on a 3 % grade is 3 cm of height, and a
// tilt of the trajectory). S: the whitening of both uncertainties (the
// reconstruction's covariance rotated to ENU, plus the database's sigma_xy
// and sigma_z). Along the line nothing is constrained.
#ifndef ZEBRAGEO_ADJUSTMENT_LINE_COSTS_H_
#define ZEBRAGEO_ADJUSTMENT_LINE_COSTS_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>

#include "adjustment/cost_functions.h"
#include "adjustment/trajectory_correction.h"
#include "survey/line_control_points.h"
#include "survey/trajectory.h"

namespace zebrageo {

// The residual as a function of the trajectory correction c at t (6).
class LinePointError {
 public:
  LinePointError(const LineControlPoint& point, const Pose& ins_pose,
                 const Eigen::Matrix3d& R_enu_track)
      : point_(point),
        p_ins_(ins_pose.p_enu),
        R_track_(R_enu_track),
        q_body_(ins_pose.q_enu_body.toRotationMatrix() * point.p_body) {}

  template <typename T>
  bool operator()(const T* const c, T* residuals) const {
    T dtheta[3], v[3];
    const T q[3] = {T(q_body_[0]), T(q_body_[1]), T(q_body_[2])};
    for (int i = 0; i < 3; ++i) {
      dtheta[i] =
          R_track_(i, 0) * c[0] + R_track_(i, 1) * c[1] + R_track_(i, 2) * c[2];
    }
    ceres::AngleAxisRotatePoint(dtheta, q, v);
    T d[3];
    for (int i = 0; i < 3; ++i) {
      d[i] = p_ins_[i] + R_track_(i, 0) * c[3] + R_track_(i, 1) * c[4] +
             R_track_(i, 2) * c[5] + v[i] - point_.db_point_enu[i];
    }
    const T across = point_.across_enu[0] * d[0] + point_.across_enu[1] * d[1] +
                     point_.across_enu[2] * d[2];
    const T along = point_.along_enu[0] * d[0] + point_.along_enu[1] * d[1];
    const T height = d[2] - point_.grade * along;
    const Eigen::Matrix2d& S = point_.sqrt_information;
    residuals[0] = S(0, 0) * across + S(0, 1) * height;
    residuals[1] = S(1, 0) * across + S(1, 1) * height;
    return true;
  }

 private:
  LineControlPoint point_;
  Eigen::Vector3d p_ins_;
  Eigen::Matrix3d R_track_;
  Eigen::Vector3d q_body_;  // R_ins p_body
};

// LinePointError chained to the 4 knots of the spline at t.
class LinePointCost : public ceres::SizedCostFunction<2, kKnotSize, kKnotSize,
                                                      kKnotSize, kKnotSize> {
 public:
  static ceres::CostFunction* Create(const LineControlPoint& point,
                                     const Pose& ins_pose,
                                     const Eigen::Matrix3d& R_enu_track,
                                     const double weights[4]) {
    return new LinePointCost(LinePointError(point, ins_pose, R_enu_track),
                             weights);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double c[kKnotSize];
    internal::SplineCorrection(weights_, parameters, c);
    const double* inner[1] = {c};
    if (jacobians == nullptr) {
      return error_->Evaluate(inner, residuals, nullptr);
    }
    double d_c[2 * kKnotSize];
    double* inner_jacobians[1] = {d_c};
    if (!error_->Evaluate(inner, residuals, inner_jacobians)) return false;
    internal::ChainToKnots(weights_, d_c, jacobians);
    return true;
  }

 private:
  LinePointCost(const LinePointError& error, const double weights[4])
      : error_(new ceres::AutoDiffCostFunction<LinePointError, 2, kKnotSize>(
            new LinePointError(error))) {
    for (int j = 0; j < 4; ++j) weights_[j] = weights[j];
  }
  std::unique_ptr<ceres::CostFunction> error_;
  double weights_[4];
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_LINE_COSTS_H_
