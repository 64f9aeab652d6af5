// The simulated road: centreline, longitudinal profile and cross-section.
//
// Frames: ENU of the survey (metres). Road coordinates (s, l): s = arc
// length along the centreline from its start, l = signed horizontal distance
// from it, positive to the LEFT of the driving direction (+s). The surface
// point of (s, l) is
//   xy = centre(s) + l * left_normal(s),  z = crown_height(s) + cross(l).
// Angles are radians; `heading` here is the tangent's angle from east,
// counter-clockwise (the ENU math angle), NOT the INS heading.
//
// The centreline is a sequence of straights, clothoids (curvature linear in
// s) and circular arcs, stored as nodes every kNodeSpacing metres; between
// nodes the curvature is linear, so positions are exact integrals of the
// heading (3-point Gauss-Legendre, exact to ~1e-13 m over a node).
#ifndef ZEBRAGEO_SIMULATOR_ROAD_H_
#define ZEBRAGEO_SIMULATOR_ROAD_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace zebrageo::sim {

struct RoadSpec {
  double length_m = 500.0;  // centreline length
  double width_m = 8.0;
  double crossfall = 0.02;
  double crown_rounding_m = 0.3;
  // Slope of the ground beyond the kerbs, rising away from the road.
  double sidewalk_slope = 0.015;
  double max_grade = 0.03;
  double grade_wavelength_m = 400.0;
  double curved_share = 0.4;
  double min_curve_radius_m = 120.0;
  double max_curve_radius_m = 600.0;
  double transition_length_m = 20.0;
  double start_heading_rad = 0.0;  // ENU math angle of the tangent at s = 0
  double start_height_m = 0.0;     // crown height at s = 0
};

class Road {
 public:
  static constexpr double kNodeSpacing = 0.5;

  // A random road from `spec`. The heading stays within 80 degrees of the
  // start heading, so the road never crosses itself.
  static Road Generate(const RoadSpec& spec, uint64_t seed);
  // A straight, level road (tests).
  static Road Straight(const RoadSpec& spec);

  double length_m() const { return length_; }
  double width_m() const { return spec_.width_m; }
  const RoadSpec& spec() const { return spec_; }

  Eigen::Vector2d Centre(double s) const;
  double Heading(double s) const;
  double Curvature(double s) const;
  Eigen::Vector2d Tangent(double s) const;
  Eigen::Vector2d LeftNormal(double s) const;

  double CrownHeight(double s) const;
  double Grade(double s) const;  // d crown_height / ds
  // Height of the cross-section relative to the crown, and its slope d/dl.
  double CrossSection(double l) const;
  double CrossSectionSlope(double l) const;
  // Both at once (one square root), for the renderer's inner loop.
  void CrossSectionAndSlope(double l, double* z, double* slope) const;
  double Height(double s, double l) const {
    return CrownHeight(s) + CrossSection(l);
  }
  Eigen::Vector3d SurfacePoint(double s, double l) const;

  // Road coordinates of the horizontal position `xy` (Newton iterations on
  // the foot point, from `s_guess`). False if they do not converge.
  bool ToRoadCoordinates(const Eigen::Vector2d& xy, double s_guess, double* s,
                         double* l) const;
  // Height of the surface above `xy`.
  double SurfaceHeightAt(const Eigen::Vector2d& xy, double s_guess) const;

  // Straight segments and arcs as (s_start, s_end, curvature at start, at
  // end), for meta.json.
  struct Segment {
    double s0, s1, kappa0, kappa1;
  };
  const std::vector<Segment>& segments() const { return segments_; }

 private:
  struct Node {
    double x, y, theta, kappa, dkappa;  // dkappa: d kappa / ds up to next
  };
  struct GradeWave {
    double amplitude, wavenumber, phase;  // grade = sum a cos(k s + phase)
  };
  void BuildNodes();
  int NodeIndex(double s) const;

  RoadSpec spec_;
  double length_ = 0.0;
  std::vector<Segment> segments_;
  std::vector<Node> nodes_;
  std::vector<GradeWave> grade_waves_;
};

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_ROAD_H_
