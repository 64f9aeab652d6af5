// Frames and geodesy: WGS84 geodetic <-> the survey's local ENU frame, and
// the INS attitude chain.
//
// Frames (see SURVEY_FORMAT.md):
//   geodetic  WGS84 latitude, longitude (degrees), ellipsoidal height (m).
//   enu       the working frame: local east-north-up tangent frame at the
//             survey origin (GeographicLib::LocalCartesian). Metres.
//   ned@P     the local north-east-down frame AT THE VEHICLE's position P;
//             the INS attitude is given relative to it. Over a few km its
//             axes differ from the origin's by ~1e-3 rad, centimetres at 10 m.
//   body      vehicle/INS frame: x forward, y right, z down (FRD).
// Attitude: R_ned_body = Rz(heading) * Ry(pitch) * Rx(roll), heading from true
// north, clockwise seen from above. Angles here are radians.
#ifndef ZEBRAGEO_SURVEY_GEODESY_H_
#define ZEBRAGEO_SURVEY_GEODESY_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <GeographicLib/LocalCartesian.hpp>

namespace zebrageo {

struct Geodetic {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_m = 0.0;  // ellipsoidal
};

// INS attitude, radians.
struct Attitude {
  double roll = 0.0;
  double pitch = 0.0;
  double heading = 0.0;
};

// Rotation of `angle` radians about one axis (right-handed, active).
Eigen::Matrix3d RotationX(double angle);
Eigen::Matrix3d RotationY(double angle);
Eigen::Matrix3d RotationZ(double angle);

// R_ned_body = Rz(heading) * Ry(pitch) * Rx(roll).
Eigen::Matrix3d RotationNedFromBody(const Attitude& attitude);
// Inverse of RotationNedFromBody, normalised to the output conventions:
// heading in [0, 2pi), roll in (-pi, pi], pitch in [-pi/2, pi/2].
Attitude AttitudeFromRotationNedBody(const Eigen::Matrix3d& R_ned_body);

// Maps NED vectors to ENU vectors at the same point (swap x/y, negate z).
Eigen::Matrix3d RotationEnuFromNed();

// The survey's working frame. Immutable after construction, cheap to copy.
class LocalFrame {
 public:
  // Throws InputError-free std::invalid_argument on a latitude outside
  // [-90, 90] or non-finite values (the caller adds the file context).
  explicit LocalFrame(const Geodetic& origin);

  const Geodetic& origin() const { return origin_; }

  Eigen::Vector3d EnuFromGeodetic(const Geodetic& geodetic) const;
  Geodetic GeodeticFromEnu(const Eigen::Vector3d& p_enu) const;

  // R_enu_nedP: maps vectors of the NED frame at `at` (the vehicle's
  // position) into the working ENU frame.
  Eigen::Matrix3d RotationEnuFromNedAt(const Geodetic& at) const;

  // Body-to-ENU rotation of a vehicle at `at` with INS `attitude`:
  // R_enu_body = R_enu_nedP * R_ned_body.
  Eigen::Matrix3d RotationEnuFromBody(const Geodetic& at,
                                      const Attitude& attitude) const;
  // Inverse: the INS attitude (relative to NED at `at`) of R_enu_body.
  Attitude AttitudeFromRotationEnuBody(const Geodetic& at,
                                       const Eigen::Matrix3d& R_enu_body) const;

 private:
  Geodetic origin_;
  GeographicLib::LocalCartesian local_cartesian_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_GEODESY_H_
