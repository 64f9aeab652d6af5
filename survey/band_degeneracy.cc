#include "survey/band_degeneracy.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Degenerate bands: corners closer than this (horizontally) are repeated,
// and a band smaller than this is no band (a real one is >= 1 m^2).
constexpr double kRepeatedCornerM = 1e-3;
constexpr double kMinBandAreaM2 = 0.01;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Sign of the turn a -> b -> c: +1 left, -1 right, 0 collinear.
int Orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  const double cross = Cross(b - a, c - a);
  return (cross > 0.0) - (cross < 0.0);
}

bool OnSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
               const Eigen::Vector2d& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) &&
         p.y() >= std::min(a.y(), b.y()) && p.y() <= std::max(a.y(), b.y());
}

// True when closed segments ab and cd share a point (touching counts).
bool SegmentsIntersect(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                       const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const int o1 = Orientation(a, b, c);
  const int o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a);
  const int o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

// Horizontal ENU offsets (metres) of geodetic points from `origin`, on the
// tangent plane of the WGS84 ellipsoid: exact to ~1e-6 relative over the
// metres of a band, and ~50x cheaper than a LocalFrame per band.
class TangentPlane {
 public:
  explicit TangentPlane(const Geodetic& origin) : origin_(origin) {
    constexpr double kA = 6378137.0;             // WGS84 semi-major axis
    constexpr double kE2 = 6.69437999014132e-3;  // first eccentricity^2
    const double s = std::sin(DegToRad(origin.lat_deg));
    const double w2 = 1.0 - kE2 * s * s;
    const double prime_vertical = kA / std::sqrt(w2);
    const double meridian = kA * (1.0 - kE2) / (w2 * std::sqrt(w2));
    east_m_per_deg_ = (prime_vertical + origin.h_m) *
                      std::cos(DegToRad(origin.lat_deg)) * DegToRad(1.0);
    north_m_per_deg_ = (meridian + origin.h_m) * DegToRad(1.0);
  }

  Eigen::Vector2d Offset(const Geodetic& p) const {
    double dlon = p.lon_deg - origin_.lon_deg;
    // A band across the antimeridian.
    if (dlon > 180.0) dlon -= 360.0;
    if (dlon < -180.0) dlon += 360.0;
    return Eigen::Vector2d(dlon * east_m_per_deg_,
                           (p.lat_deg - origin_.lat_deg) * north_m_per_deg_);
  }

 private:
  Geodetic origin_;
  double east_m_per_deg_ = 0.0;
  double north_m_per_deg_ = 0.0;
};

}  // namespace

// Computed in a tangent plane at the first corner, in metres: degrees are
// not isotropic.
std::string BandDegeneracy(const std::array<Geodetic, 4>& corners) {
  const TangentPlane plane(corners[0]);
  std::array<Eigen::Vector2d, 4> p;
  for (int i = 0; i < 4; ++i) p[i] = plane.Offset(corners[i]);
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if ((p[i] - p[j]).norm() < kRepeatedCornerM) {
        return "degenerate band: corners " + std::to_string(i) + " and " +
               std::to_string(j) + " are the same point";
      }
    }
  }
  // In a quadrilateral only opposite edges can cross.
  if (SegmentsIntersect(p[0], p[1], p[2], p[3]) ||
      SegmentsIntersect(p[1], p[2], p[3], p[0])) {
    return "degenerate band: the ring is self-intersecting (corners not in "
           "order around the band)";
  }
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) twice_area += Cross(p[i], p[(i + 1) % 4]);
  const double area = std::abs(twice_area) / 2.0;
  if (area < kMinBandAreaM2) {
    std::ostringstream problem;
    problem << "degenerate band: area " << area << " m^2 is about zero";
    return problem.str();
  }
  return "";
}

}  // namespace zebrageo
