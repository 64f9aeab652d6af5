#include "adjustment/line_control.h"

#include <Eigen/Cholesky>

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

}  // namespace zebrageo
