#include "survey/geodesy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

Eigen::Matrix3d FromRowMajor(const std::vector<double>& m) {
  Eigen::Matrix3d R;
  R << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  return R;
}

}  // namespace

Eigen::Matrix3d RotationX(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

Eigen::Matrix3d RotationY(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

Eigen::Matrix3d RotationZ(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Eigen::Matrix3d RotationNedFromBody(const Attitude& attitude) {
  return RotationZ(attitude.heading) * RotationY(attitude.pitch) *
         RotationX(attitude.roll);
}

Attitude AttitudeFromRotationNedBody(const Eigen::Matrix3d& R) {
  // R = Rz(h) Ry(p) Rx(r): R(2,0) = -sin(p), R(1,0)/R(0,0) = tan(h),
  // R(2,1)/R(2,2) = tan(r).
  Attitude attitude;
  attitude.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  attitude.heading = std::atan2(R(1, 0), R(0, 0));
  attitude.roll = std::atan2(R(2, 1), R(2, 2));
  if (attitude.heading < 0.0) attitude.heading += 2.0 * kPi;
  if (attitude.heading >= 2.0 * kPi) attitude.heading -= 2.0 * kPi;
  if (attitude.roll <= -kPi) attitude.roll += 2.0 * kPi;
  return attitude;
}

Eigen::Matrix3d RotationEnuFromNed() {
  Eigen::Matrix3d R;
  R << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  return R;
}

LocalFrame::LocalFrame(const Geodetic& origin) : origin_(origin) {
  if (!std::isfinite(origin.lat_deg) || !std::isfinite(origin.lon_deg) ||
      !std::isfinite(origin.h_m) || std::abs(origin.lat_deg) > 90.0) {
    throw std::invalid_argument(
        "invalid ENU origin (" + std::to_string(origin.lat_deg) + ", " +
        std::to_string(origin.lon_deg) + ", " + std::to_string(origin.h_m) +
        "): latitude must be in [-90, 90] and all values finite");
  }
  local_cartesian_.Reset(origin.lat_deg, origin.lon_deg, origin.h_m);
}

Eigen::Vector3d LocalFrame::EnuFromGeodetic(const Geodetic& g) const {
  Eigen::Vector3d p;
  local_cartesian_.Forward(g.lat_deg, g.lon_deg, g.h_m, p.x(), p.y(), p.z());
  return p;
}

Geodetic LocalFrame::GeodeticFromEnu(const Eigen::Vector3d& p_enu) const {
  Geodetic g;
  local_cartesian_.Reverse(p_enu.x(), p_enu.y(), p_enu.z(), g.lat_deg,
                           g.lon_deg, g.h_m);
  return g;
}

Eigen::Matrix3d LocalFrame::RotationEnuFromNedAt(const Geodetic& at) const {
  // LocalCartesian::Forward's M maps vectors of the ENU frame at `at` into
  // the origin's ENU frame (GeographicLib docs, LocalCartesian.hpp).
  std::vector<double> m(9);
  double x, y, z;
  local_cartesian_.Forward(at.lat_deg, at.lon_deg, at.h_m, x, y, z, m);
  return FromRowMajor(m) * RotationEnuFromNed();
}

Eigen::Matrix3d LocalFrame::RotationEnuFromBody(
    const Geodetic& at, const Attitude& attitude) const {
  return RotationEnuFromNedAt(at) * RotationNedFromBody(attitude);
}

Attitude LocalFrame::AttitudeFromRotationEnuBody(
    const Geodetic& at, const Eigen::Matrix3d& R_enu_body) const {
  return AttitudeFromRotationNedBody(RotationEnuFromNedAt(at).transpose() *
                                     R_enu_body);
}

}  // namespace zebrageo
