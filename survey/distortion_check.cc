#include "survey/distortion_check.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "survey/csv.h"
#include "survey/math_util.h"

namespace zebrageo {

std::string RadialDistortionProblem(const Camera& camera) {
  const std::array<double, 5> d = camera.distortion();
  const double k1 = d[0], k2 = d[1], k3 = d[4];
  // The farthest image corner, normalised (distorted) radius.
  double corner_rd = 0.0;
  for (const double u : {-0.5, camera.width() - 0.5}) {
    for (const double v : {-0.5, camera.height() - 0.5}) {
      corner_rd =
          std::max(corner_rd, std::hypot((u - camera.cx()) / camera.fx(),
                                         (v - camera.cy()) / camera.fy()));
    }
  }
  auto distorted = [&](double r) {
    const double r2 = r * r;
    return r * (1.0 + r2 * (k1 + r2 * (k2 + r2 * k3)));
  };
  const std::string coefficients = "k1 = " + FormatDouble(k1) +
                                   ", k2 = " + FormatDouble(k2) +
                                   ", k3 = " + FormatDouble(k3);
  // Geometric steps of 0.1% from a micro-radian up to 87 degrees off axis.
  constexpr double kMaxR = 20.0;
  double previous = 0.0;
  for (double r = 1e-6; r <= kMaxR; r *= 1.001) {
    const double rd = distorted(r);
    if (!(rd > previous)) {
      return "the radial distortion (" + coefficients +
             ") folds the image: the distorted radius stops growing at " +
             FormatFixed(previous * camera.fx(), 0) +
             " px from the principal point, inside the image (its corner is " +
             FormatFixed(corner_rd * camera.fx(), 0) +
             " px away): two rays would meet on one pixel";
    }
    if (rd >= corner_rd) {
      const double scale = rd / r;
      if (scale < 0.25 || scale > 4.0) {
        return "the radial distortion (" + coefficients +
               ") scales the radius of the image's corner by " +
               FormatFixed(scale, scale >= 10.0 ? 0 : 2) +
               " (a lens: 0.25 to 4): its farthest corner would look " +
               FormatFixed(std::atan(r) * 180.0 / kPi, 2) +
               " deg off the optical axis, not the " +
               FormatFixed(std::atan(corner_rd) * 180.0 / kPi, 1) +
               " deg its focal length gives; a coefficient in the wrong "
               "unit or place?";
      }
      return "";
    }
    previous = rd;
  }
  return "";
}

}  // namespace zebrageo
