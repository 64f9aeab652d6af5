// Reprojection error of a BAL (Bundler) camera, see bal_problem.h:
//   P = R(w) X + t,  p = -P.xy / P.z,  r = f (1 + k1 |p|^2 + k2 |p|^4) p - uv
// Blocks: camera [w(3) angle-axis rad, t(3), f px, k1, k2] (world to camera),
// point X (3, world frame). Residual in pixels, unweighted.
//
// Two implementations: the templated functor (autodiff, the reference) and an
// analytic cost function with the same residual, twice as fast to evaluate,
// used by the BAL solver. Their Jacobians are compared with numeric
// differentiation in tests/adjustment/bal_problem_test.cc.
#ifndef ZEBRAGEO_ADJUSTMENT_BAL_SNAVELY_REPROJECTION_ERROR_H_
#define ZEBRAGEO_ADJUSTMENT_BAL_SNAVELY_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <cmath>

namespace zebrageo {

struct SnavelyReprojectionError {
  SnavelyReprojectionError(double observed_x, double observed_y)
      : observed_x(observed_x), observed_y(observed_y) {}

  template <typename T>
  bool operator()(const T* const camera, const T* const point,
                  T* residuals) const {
    T p[3];
    ceres::AngleAxisRotatePoint(camera, point, p);
    p[0] += camera[3];
    p[1] += camera[4];
    p[2] += camera[5];
    const T xp = -p[0] / p[2];
    const T yp = -p[1] / p[2];
    const T r2 = xp * xp + yp * yp;
    const T distortion = T(1) + r2 * (camera[7] + camera[8] * r2);
    residuals[0] = camera[6] * distortion * xp - T(observed_x);
    residuals[1] = camera[6] * distortion * yp - T(observed_y);
    return true;
  }

  static ceres::CostFunction* Create(double observed_x, double observed_y) {
    return new ceres::AutoDiffCostFunction<SnavelyReprojectionError, 2, 9, 3>(
        new SnavelyReprojectionError(observed_x, observed_y));
  }

  double observed_x;
  double observed_y;
};

// Same residual with hand-written Jacobians. With w = theta * n, R(w + dw) =
// Exp(J_l(w) dw) R(w), so d(R X)/dw = -[R X]x J_l(w) with the left Jacobian
// J_l(w) = I + (1 - cos theta)/theta^2 [w]x + (theta - sin theta)/theta^3
// [w]x^2 (Barfoot, "State Estimation for Robotics", 7.1.5).
class SnavelyReprojectionCost : public ceres::SizedCostFunction<2, 9, 3> {
 public:
  SnavelyReprojectionCost(double observed_x, double observed_y)
      : observed_(observed_x, observed_y) {}

  static ceres::CostFunction* Create(double observed_x, double observed_y) {
    return new SnavelyReprojectionCost(observed_x, observed_y);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* camera = parameters[0];
    const Eigen::Map<const Eigen::Vector3d> w(camera);
    const Eigen::Map<const Eigen::Vector3d> X(parameters[1]);
    const double theta2 = w.squaredNorm();
    Eigen::Matrix3d R;
    Eigen::Matrix3d W;  // [w]x
    W << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
    double a, b;  // J_l = I + a W + b W^2
    if (theta2 > 1e-12) {
      const double theta = std::sqrt(theta2);
      const double s = std::sin(theta);
      const double c = std::cos(theta);
      R = Eigen::Matrix3d::Identity() + (s / theta) * W +
          ((1.0 - c) / theta2) * W * W;
      a = (1.0 - c) / theta2;
      b = (theta - s) / (theta2 * theta);
    } else {
      // First order, as ceres::AngleAxisRotatePoint near zero.
      R = Eigen::Matrix3d::Identity() + W;
      a = 0.5;
      b = 1.0 / 6.0;
    }
    const Eigen::Vector3d RX = R * X;
    const Eigen::Vector3d P =
        RX + Eigen::Vector3d(camera[3], camera[4], camera[5]);
    const double inv_z = 1.0 / P.z();
    const Eigen::Vector2d p(-P.x() * inv_z, -P.y() * inv_z);
    const double f = camera[6];
    const double k1 = camera[7];
    const double k2 = camera[8];
    const double r2 = p.squaredNorm();
    const double distortion = 1.0 + r2 * (k1 + k2 * r2);
    residuals[0] = f * distortion * p.x() - observed_.x();
    residuals[1] = f * distortion * p.y() - observed_.y();
    if (jacobians == nullptr) return true;

    // d(pixel)/dp = f (distortion I + 2 (k1 + 2 k2 r2) p p^T)
    const double dd_dr2 = k1 + 2.0 * k2 * r2;
    const Eigen::Matrix2d d_pixel_d_p =
        f * (distortion * Eigen::Matrix2d::Identity() +
             2.0 * dd_dr2 * p * p.transpose());
    // dp/dP for p = -P.xy / P.z.
    Eigen::Matrix<double, 2, 3> d_p_d_P;
    d_p_d_P << -inv_z, 0.0, P.x() * inv_z * inv_z, 0.0, -inv_z,
        P.y() * inv_z * inv_z;
    const Eigen::Matrix<double, 2, 3> A = d_pixel_d_p * d_p_d_P;

    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 9, Eigen::RowMajor>> J(jacobians[0]);
      Eigen::Matrix3d RXx;
      RXx << 0.0, -RX.z(), RX.y(), RX.z(), 0.0, -RX.x(), -RX.y(), RX.x(), 0.0;
      const Eigen::Matrix3d J_l =
          Eigen::Matrix3d::Identity() + a * W + b * W * W;
      J.block<2, 3>(0, 0) = -A * RXx * J_l;
      J.block<2, 3>(0, 3) = A;
      J.col(6) = distortion * p;
      J.col(7) = f * r2 * p;
      J.col(8) = f * r2 * r2 * p;
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J(jacobians[1]);
      J = A * R;
    }
    return true;
  }

 private:
  Eigen::Vector2d observed_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_BAL_SNAVELY_REPROJECTION_ERROR_H_
