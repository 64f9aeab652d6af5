#include "simulator/road.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

#include "simulator/noise.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

// Rounds a length to whole node spacings (at least one), so segment ends fall
// on nodes and the curvature is linear between consecutive nodes.
double RoundToNodes(double length) {
  return std::max(1.0, std::round(length / Road::kNodeSpacing)) *
         Road::kNodeSpacing;
}

// Integral over [0, u] of (cos, sin) of theta0 + k0 t + dk t^2 / 2, by
// 3-point Gauss-Legendre (exact for degree-5 polynomials; over half a metre
// of road the integrand is polynomial to ~1e-13).
Eigen::Vector2d IntegrateHeading(double theta0, double k0, double dk,
                                 double u) {
  static constexpr double kNodes[3] = {-0.7745966692414834, 0.0,
                                       0.7745966692414834};
  static constexpr double kWeights[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < 3; ++i) {
    const double t = 0.5 * u * (kNodes[i] + 1.0);
    const double theta = theta0 + k0 * t + 0.5 * dk * t * t;
    sum += kWeights[i] * Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
  return 0.5 * u * sum;
}

}  // namespace

Road Road::Generate(const RoadSpec& spec, uint64_t seed) {
  std::mt19937_64 rng(seed);
  Road road;
  road.spec_ = spec;
  // Plan: straights and curves (transition, arc, transition) until the
  // length is reached; the share of curves approximates spec.curved_share.
  double s = 0.0;
  double heading_offset = 0.0;  // accumulated turn, radians
  const double max_offset = 80.0 * kPi / 180.0;
  while (s < spec.length_m) {
    const bool curve = spec.curved_share > 0.0 &&
                       Bernoulli(&rng, spec.curved_share) && s > 0.0;
    if (!curve) {
      // Mean straight ~ 100 m; with share c of curves of mean ~90 m the
      // drawn probability above gives roughly the requested share.
      const double length = RoundToNodes(Uniform(&rng, 40.0, 160.0));
      road.segments_.push_back({s, s + length, 0.0, 0.0});
      s += length;
      continue;
    }
    const double log_r = Uniform(
        &rng, std::log(spec.min_curve_radius_m),
        std::log(std::max(spec.min_curve_radius_m, spec.max_curve_radius_m)));
    const double radius = std::exp(log_r);
    double angle = Uniform(&rng, 12.0, 50.0) * kPi / 180.0;
    // Turn back towards the start heading when far from it.
    double sign = Bernoulli(&rng, 0.5) ? 1.0 : -1.0;
    if (std::abs(heading_offset) > 0.35) sign = heading_offset > 0 ? -1 : 1;
    const double kappa = sign / radius;
    const double transition = spec.transition_length_m > 0.0
                                  ? RoundToNodes(spec.transition_length_m)
                                  : 0.0;
    // Each transition turns by kappa * transition / 2.
    double arc = angle * radius - transition;
    if (std::abs(heading_offset + sign * angle) > max_offset) {
      arc = std::max(
          0.0, (max_offset - std::abs(heading_offset)) * radius - transition);
    }
    arc = arc > 0.0 ? RoundToNodes(arc) : 0.0;
    if (transition > 0.0) {
      road.segments_.push_back({s, s + transition, 0.0, kappa});
      s += transition;
    }
    if (arc > 0.0) {
      road.segments_.push_back({s, s + arc, kappa, kappa});
      s += arc;
    }
    if (transition > 0.0) {
      road.segments_.push_back({s, s + transition, kappa, 0.0});
      s += transition;
    }
    heading_offset += kappa * (arc + transition);
  }
  road.length_ = s;
  // Grade: three sinusoids, amplitudes summing to max_grade.
  double weights[3];
  double total = 0.0;
  for (double& w : weights) {
    w = Uniform(&rng, 0.3, 1.0);
    total += w;
  }
  for (double w : weights) {
    const double wavelength = spec.grade_wavelength_m * Uniform(&rng, 1.0, 3.0);
    road.grade_waves_.push_back({spec.max_grade * w / total,
                                 2.0 * kPi / wavelength,
                                 Uniform(&rng, 0.0, 2.0 * kPi)});
  }
  road.BuildNodes();
  return road;
}

Road Road::Straight(const RoadSpec& spec) {
  Road road;
  road.spec_ = spec;
  road.length_ = RoundToNodes(spec.length_m);
  road.segments_.push_back({0.0, road.length_, 0.0, 0.0});
  road.BuildNodes();
  return road;
}

void Road::BuildNodes() {
  const int n = static_cast<int>(std::lround(length_ / kNodeSpacing)) + 1;
  nodes_.resize(n);
  size_t segment = 0;
  Node node{0.0, 0.0, spec_.start_heading_rad, 0.0, 0.0};
  for (int i = 0; i < n; ++i) {
    const double s = i * kNodeSpacing;
    while (segment + 1 < segments_.size() &&
           s >= segments_[segment].s1 - 1e-9) {
      ++segment;
    }
    const Segment& seg = segments_[segment];
    const double rate = (seg.kappa1 - seg.kappa0) / (seg.s1 - seg.s0);
    node.kappa = seg.kappa0 + rate * (s - seg.s0);
    node.dkappa = rate;
    nodes_[i] = node;
    // Advance to the next node.
    const Eigen::Vector2d d =
        IntegrateHeading(node.theta, node.kappa, rate, kNodeSpacing);
    node.x += d.x();
    node.y += d.y();
    node.theta +=
        node.kappa * kNodeSpacing + 0.5 * rate * kNodeSpacing * kNodeSpacing;
  }
}

int Road::NodeIndex(double s) const {
  const int i = static_cast<int>(std::floor(s / kNodeSpacing));
  return std::clamp(i, 0, static_cast<int>(nodes_.size()) - 2);
}

Eigen::Vector2d Road::Centre(double s) const {
  const int i = NodeIndex(s);
  const Node& n = nodes_[i];
  const double u = s - i * kNodeSpacing;
  // Beyond the ends the road continues straight along the end tangent.
  if (u < 0.0 || u > kNodeSpacing) {
    const double theta = Heading(s);
    const double s_end = u < 0.0 ? 0.0 : (nodes_.size() - 1) * kNodeSpacing;
    return Centre(s_end) +
           (s - s_end) * Eigen::Vector2d(std::cos(theta), std::sin(theta));
  }
  return Eigen::Vector2d(n.x, n.y) +
         IntegrateHeading(n.theta, n.kappa, n.dkappa, u);
}

double Road::Heading(double s) const {
  const int i = NodeIndex(s);
  const Node& n = nodes_[i];
  const double u = std::clamp(s - i * kNodeSpacing, 0.0, kNodeSpacing);
  return n.theta + n.kappa * u + 0.5 * n.dkappa * u * u;
}

double Road::Curvature(double s) const {
  if (s < 0.0 || s > length_) return 0.0;
  const int i = NodeIndex(s);
  const Node& n = nodes_[i];
  return n.kappa + n.dkappa * (s - i * kNodeSpacing);
}

Eigen::Vector2d Road::Tangent(double s) const {
  const double theta = Heading(s);
  return Eigen::Vector2d(std::cos(theta), std::sin(theta));
}

Eigen::Vector2d Road::LeftNormal(double s) const {
  const double theta = Heading(s);
  return Eigen::Vector2d(-std::sin(theta), std::cos(theta));
}

double Road::CrownHeight(double s) const {
  double z = spec_.start_height_m;
  for (const GradeWave& w : grade_waves_) {
    z += w.amplitude / w.wavenumber *
         (std::sin(w.wavenumber * s + w.phase) - std::sin(w.phase));
  }
  return z;
}

double Road::Grade(double s) const {
  double g = 0.0;
  for (const GradeWave& w : grade_waves_) {
    g += w.amplitude * std::cos(w.wavenumber * s + w.phase);
  }
  return g;
}

double Road::CrossSection(double l) const {
  const double half = 0.5 * spec_.width_m;
  const double r = spec_.crown_rounding_m;
  const double a = std::min(std::abs(l), half);
  // Hyperbolic crown: slope -crossfall * a / sqrt(a^2 + r^2), -> -crossfall.
  double z = -spec_.crossfall * (std::sqrt(a * a + r * r) - r);
  if (std::abs(l) > half) z += spec_.sidewalk_slope * (std::abs(l) - half);
  return z;
}

double Road::CrossSectionSlope(double l) const {
  const double half = 0.5 * spec_.width_m;
  const double r = spec_.crown_rounding_m;
  const double sign = l < 0.0 ? -1.0 : 1.0;
  if (std::abs(l) > half) return sign * spec_.sidewalk_slope;
  return -spec_.crossfall * l / std::sqrt(l * l + r * r);
}

void Road::CrossSectionAndSlope(double l, double* z, double* slope) const {
  const double half = 0.5 * spec_.width_m;
  const double r = spec_.crown_rounding_m;
  const double a = std::min(std::abs(l), half);
  const double root = std::sqrt(a * a + r * r);
  *z = -spec_.crossfall * (root - r);
  if (std::abs(l) > half) {
    *z += spec_.sidewalk_slope * (std::abs(l) - half);
    *slope = l < 0.0 ? -spec_.sidewalk_slope : spec_.sidewalk_slope;
  } else {
    *slope = -spec_.crossfall * l / root;
  }
}

Eigen::Vector3d Road::SurfacePoint(double s, double l) const {
  const Eigen::Vector2d xy = Centre(s) + l * LeftNormal(s);
  return Eigen::Vector3d(xy.x(), xy.y(), Height(s, l));
}

bool Road::ToRoadCoordinates(const Eigen::Vector2d& xy, double s_guess,
                             double* s, double* l) const {
  double si = s_guess;
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Eigen::Vector2d d = xy - Centre(si);
    const Eigen::Vector2d t = Tangent(si);
    const double along = d.dot(t);
    const double across = t.x() * d.y() - t.y() * d.x();
    // Foot-point Newton step: the projection moves by along / (1 - k l).
    const double denominator = std::max(0.2, 1.0 - Curvature(si) * across);
    const double step = std::clamp(along / denominator, -50.0, 50.0);
    si += step;
    if (std::abs(step) < 1e-10) {
      *s = si;
      *l = across;
      return true;
    }
  }
  const Eigen::Vector2d d = xy - Centre(si);
  const Eigen::Vector2d t = Tangent(si);
  *s = si;
  *l = t.x() * d.y() - t.y() * d.x();
  return std::abs(d.dot(t)) < 1e-6;
}

double Road::SurfaceHeightAt(const Eigen::Vector2d& xy, double s_guess) const {
  double s = 0.0, l = 0.0;
  ToRoadCoordinates(xy, s_guess, &s, &l);
  return Height(s, l);
}

}  // namespace zebrageo::sim
