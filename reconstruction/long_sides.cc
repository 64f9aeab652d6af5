#include "reconstruction/long_sides.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "reconstruction/segment_grouping.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

constexpr int kDirectionBins = 180;

}  // namespace

std::string ZebraSpecification::Check() const {
  OptionCheck check;
  OPTION_GT(check, band_width_m, 0.05);
  OPTION_GT(check, band_width_tolerance_m, 0.0);
  OPTION_LT(check, band_width_tolerance_m, band_width_m);
  OPTION_GT(check, min_band_length_m, band_width_m);
  OPTION_GE(check, max_band_length_m, min_band_length_m);
  return check.problem();
}

std::string LongSideOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, polygon_tolerance_m, 0.0);
  OPTION_GT(check, max_chain_gap_m, 0.0);
  OPTION_GT(check, min_segment_length_m, 0.0);
  OPTION_IN(check, direction_tolerance_rad, "(", 0.0, 0.8, ")");
  OPTION_GE(check, max_directions, 1);
  OPTION_GT(check, accumulator_cell_m, 0.0);
  OPTION_GT(check, low_vote_fraction, 0.0);
  OPTION_GE(check, high_vote_fraction, low_vote_fraction);
  OPTION_GT(check, pass1_max_gap_m, 0.0);
  OPTION_GT(check, pass1_max_offset_m, 0.0);
  OPTION_GT(check, pass1_max_angle_rad, 0.0);
  OPTION_GT(check, pass2_max_gap_m, 0.0);
  OPTION_GT(check, pass2_max_offset_m, 0.0);
  OPTION_GT(check, pass2_max_angle_rad, 0.0);
  OPTION_GE(check, pass1_min_length_m, 0.0);
  OPTION_GT(check, min_long_side_length_m, 0.0);
  OPTION_GE(check, height_smoothing_half_window, 0);
  return check.problem();
}

void RegulariseChainHeights(const RoadPlane& road,
                            const Eigen::Vector3d& left_centre_body,
                            int half_window, EdgeChain3d* chain) {
  std::vector<EdgePoint3d>& points = chain->points;
  const int n = static_cast<int>(points.size());
  for (EdgePoint3d& p : points) p.p_chain_body = p.p_body;
  if (half_window <= 0 || n < 3) return;
  std::vector<double> height(n), smooth(n);
  for (int i = 0; i < n; ++i) height[i] = road.SignedDistance(points[i].p_body);
  std::vector<char> use(n, 1);
  // Two pointers over the window; sums of 1, u, u^2, h, u h of the used
  // points (u relative to the chain's first point).
  auto fit = [&]() {
    const int u0 = points[0].index_in_chain;
    double s0 = 0, su = 0, suu = 0, sh = 0, suh = 0;
    int lo = 0, hi = 0;  // window [lo, hi)
    for (int i = 0; i < n; ++i) {
      const int ui = points[i].index_in_chain;
      while (hi < n && points[hi].index_in_chain <= ui + half_window) {
        if (use[hi]) {
          const double u = points[hi].index_in_chain - u0;
          s0 += 1.0;
          su += u;
          suu += u * u;
          sh += height[hi];
          suh += u * height[hi];
        }
        ++hi;
      }
      while (points[lo].index_in_chain < ui - half_window) {
        if (use[lo]) {
          const double u = points[lo].index_in_chain - u0;
          s0 -= 1.0;
          su -= u;
          suu -= u * u;
          sh -= height[lo];
          suh -= u * height[lo];
        }
        ++lo;
      }
      if (s0 < 3.0) {
        smooth[i] = height[i];
        continue;
      }
      const double mean_u = su / s0;
      const double mean_h = sh / s0;
      const double var_u = suu / s0 - mean_u * mean_u;
      const double cov = suh / s0 - mean_u * mean_h;
      const double slope = var_u > 1e-6 ? cov / var_u : 0.0;
      smooth[i] = mean_h + slope * ((ui - u0) - mean_u);
    }
  };
  fit();
  std::vector<double> residual(n);
  for (int i = 0; i < n; ++i) residual[i] = std::abs(height[i] - smooth[i]);
  std::vector<double> sorted = residual;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double limit = std::max(0.005, 3.0 * 1.4826 * sorted[n / 2]);
  for (int i = 0; i < n; ++i) use[i] = residual[i] <= limit;
  fit();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d ray = points[i].p_body - left_centre_body;
    const double denominator = road.normal_body.dot(ray);
    if (!(std::abs(denominator) > 1e-9)) continue;
    const double t =
        (smooth[i] + road.offset_m - road.normal_body.dot(left_centre_body)) /
        denominator;
    if (t > 0.0) points[i].p_chain_body = left_centre_body + t * ray;
  }
}

PlaneFrame PlaneFrame::Make(const RoadPlane& plane,
                            const Eigen::Vector3d& x_axis,
                            const Eigen::Vector3d& point) {
  PlaneFrame frame;
  frame.normal = plane.normal_body.normalized();
  frame.e1 = (x_axis - x_axis.dot(frame.normal) * frame.normal).normalized();
  frame.e2 = frame.normal.cross(frame.e1);
  frame.origin = plane.Project(point);
  return frame;
}

std::vector<int> DouglasPeucker(const std::vector<Eigen::Vector2d>& polyline,
                                double tolerance) {
  const int n = static_cast<int>(polyline.size());
  if (n <= 2) {
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    return all;
  }
  std::vector<char> keep(n, 0);
  keep[0] = keep[n - 1] = 1;
  std::vector<std::pair<int, int>> stack = {{0, n - 1}};
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    const Eigen::Vector2d a = polyline[first];
    const Eigen::Vector2d ab = polyline[last] - a;
    const double length = ab.norm();
    int worst = -1;
    double worst_distance = tolerance;
    for (int k = first + 1; k < last; ++k) {
      const Eigen::Vector2d ak = polyline[k] - a;
      const double distance =
          length > 1e-12 ? std::abs(ab.x() * ak.y() - ab.y() * ak.x()) / length
                         : ak.norm();
      if (distance > worst_distance) {
        worst_distance = distance;
        worst = k;
      }
    }
    if (worst >= 0) {
      keep[worst] = 1;
      stack.push_back({first, worst});
      stack.push_back({worst, last});
    }
  }
  std::vector<int> kept;
  for (int k = 0; k < n; ++k) {
    if (keep[k]) kept.push_back(k);
  }
  return kept;
}

Eigen::Vector2d PrincipalDirection(const std::vector<Segment2d>& segments,
                                   double tolerance_rad, double* weight) {
  std::vector<double> histogram(kDirectionBins, 0.0);
  for (const Segment2d& s : segments) {
    const Eigen::Vector2d d = s.b - s.a;
    double angle = std::atan2(d.y(), d.x());
    if (angle < 0.0) angle += kPi;
    const int bin = std::min(kDirectionBins - 1,
                             static_cast<int>(angle / kPi * kDirectionBins));
    histogram[bin] += s.Length();
  }
  // Circular smoothing over +-2 degrees.
  const double kernel[5] = {1, 2, 3, 2, 1};
  int best_bin = 0;
  double best = -1.0;
  for (int b = 0; b < kDirectionBins; ++b) {
    double value = 0.0;
    for (int k = -2; k <= 2; ++k) {
      value +=
          kernel[k + 2] * histogram[(b + k + kDirectionBins) % kDirectionBins];
    }
    if (value > best) {
      best = value;
      best_bin = b;
    }
  }
  // Refine: length-weighted mean of doubled angles near the peak.
  const double peak = (best_bin + 0.5) * kPi / kDirectionBins;
  double c = 0.0, s = 0.0, total = 0.0;
  for (const Segment2d& seg : segments) {
    const Eigen::Vector2d d = seg.b - seg.a;
    const double angle = std::atan2(d.y(), d.x());
    double difference = std::remainder(angle - peak, kPi);
    if (std::abs(difference) > tolerance_rad) continue;
    c += seg.Length() * std::cos(2.0 * (peak + difference));
    s += seg.Length() * std::sin(2.0 * (peak + difference));
    total += seg.Length();
  }
  if (weight != nullptr) *weight = total;
  const double mean = total > 0.0 ? 0.5 * std::atan2(s, c) : peak;
  return Eigen::Vector2d(std::cos(mean), std::sin(mean));
}

std::vector<AccumulatorComponent> ParallelLineComponents(
    const std::vector<Segment2d>& segments, const Eigen::Vector2d& direction,
    const ZebraSpecification& zebra, const LongSideOptions& options) {
  std::vector<AccumulatorComponent> components;
  if (segments.empty()) return components;
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  const double cell = options.accumulator_cell_m;
  double low_s = 1e30, high_s = -1e30;
  for (const Segment2d& s : segments) {
    low_s = std::min({low_s, s.a.dot(normal), s.b.dot(normal)});
    high_s = std::max({high_s, s.a.dot(normal), s.b.dot(normal)});
  }
  const double origin = low_s - cell;
  const int cells = static_cast<int>((high_s - origin) / cell) + 2;
  std::vector<double> votes(cells, 0.0);
  for (const Segment2d& s : segments) {
    const double along = std::abs((s.b - s.a).dot(direction));
    const double s0 = std::min(s.a.dot(normal), s.b.dot(normal)) - origin;
    const double s1 = std::max(s.a.dot(normal), s.b.dot(normal)) - origin;
    const int c0 = static_cast<int>(s0 / cell);
    const int c1 = static_cast<int>(s1 / cell);
    if (c0 == c1) {
      votes[c0] += along;
      continue;
    }
    // Each cell gets the part of the segment that projects into it.
    for (int c = c0; c <= c1; ++c) {
      const double overlap =
          std::min(s1, (c + 1) * cell) - std::max(s0, c * cell);
      votes[c] += along * std::max(0.0, overlap) / (s1 - s0);
    }
  }
  const double high = options.high_vote_fraction * zebra.min_band_length_m;
  const double low = options.low_vote_fraction * zebra.min_band_length_m;
  // Runs above the low threshold; a run holding several lines (a band side
  // next to a kerb and a lane line) is split at its valleys: where the
  // votes drop below half of the peaks on both sides.
  auto emit = [&](int first, int last) {  // cells [first, last)
    double peak = 0.0, sum = 0.0, moment = 0.0;
    for (int k = first; k < last; ++k) {
      peak = std::max(peak, votes[k]);
      sum += votes[k];
      moment += votes[k] * (origin + (k + 0.5) * cell);
    }
    if (peak < high) return;
    AccumulatorComponent component;
    component.lateral_m = moment / sum;
    component.low_m = origin + first * cell;
    component.high_m = origin + last * cell;
    component.peak_votes_m = peak;
    components.push_back(component);
  };
  for (int c = 0; c < cells;) {
    if (votes[c] < low) {
      ++c;
      continue;
    }
    int end = c;
    while (end < cells && votes[end] >= low) ++end;
    int first = c;
    double left_peak = 0.0;
    for (int k = c; k < end; ++k) {
      left_peak = std::max(left_peak, votes[k]);
      // Is k a valley: below half of the left peak and of the highest
      // cell to its right within the run?
      if (votes[k] >= 0.5 * left_peak) continue;
      double right_peak = 0.0;
      for (int r = k + 1; r < end; ++r)
        right_peak = std::max(right_peak, votes[r]);
      if (votes[k] >= 0.5 * right_peak) continue;
      // Split at the lowest cell of this dip.
      int valley = k;
      while (valley + 1 < end && votes[valley + 1] <= votes[valley]) ++valley;
      emit(first, valley + 1);
      first = valley + 1;
      left_peak = 0.0;
      k = valley;
    }
    emit(first, end);
    c = end;
  }
  for (AccumulatorComponent& a : components) {
    for (const AccumulatorComponent& b : components) {
      if (std::abs(std::abs(a.lateral_m - b.lateral_m) - zebra.band_width_m) <=
          zebra.band_width_tolerance_m) {
        a.paired = true;
      }
    }
  }
  return components;
}

LongSide FitLongSide(const std::vector<EdgePoint3d>& points,
                     std::vector<int> support, const PlaneFrame& frame,
                     const Eigen::Vector2d& direction_2d, int direction_set) {
  LongSide side;
  side.direction_set = direction_set;
  side.direction_2d = direction_2d;
  const Eigen::Vector2d normal(-direction_2d.y(), direction_2d.x());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : support) mean += points[i].p_chain_body;
  mean /= static_cast<double>(support.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i : support) {
    const Eigen::Vector3d d = points[i].p_chain_body - mean;
    scatter += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Eigen::Vector3d axis = solver.eigenvectors().col(2);
  if (axis.dot(frame.Direction3d(direction_2d)) < 0.0) axis = -axis;
  side.point_body = mean;
  side.direction_body = axis;
  side.t_begin = 1e30;
  side.t_end = -1e30;
  const Eigen::Vector3d across = frame.normal.cross(axis).normalized();
  double lateral_ss = 0.0, height_ss = 0.0, contrast = 0.0;
  for (int i : support) {
    const Eigen::Vector3d d = points[i].p_chain_body - mean;
    const double t = d.dot(axis);
    side.t_begin = std::min(side.t_begin, t);
    side.t_end = std::max(side.t_end, t);
    const Eigen::Vector3d r = d - t * axis;
    lateral_ss += r.dot(across) * r.dot(across);
    height_ss += r.dot(frame.normal) * r.dot(frame.normal);
    contrast += points[i].gradient.dot(normal);
  }
  const double count = static_cast<double>(support.size());
  side.lateral_rms_m = std::sqrt(lateral_ss / count);
  side.height_rms_m = std::sqrt(height_ss / count);
  side.contrast = contrast / count;
  side.lateral_m = frame.To2d(mean).dot(normal);
  side.support = std::move(support);
  return side;
}

void SideExtent(const PlaneFrame& frame, const LongSide& side,
                const Eigen::Vector2d& along, double* low, double* high) {
  const double a = frame.To2d(side.Begin()).dot(along);
  const double b = frame.To2d(side.End()).dot(along);
  *low = std::min(a, b);
  *high = std::max(a, b);
}

namespace {

// Flattens the chains into `result` (points, points_2d) and polygonises
// them: each polygon side refined by regression becomes a segment.
void PolygonSegments(const std::vector<EdgeChain3d>& chains,
                     const PlaneFrame& frame, const LongSideOptions& options,
                     LongSideDetection* detection) {
  LongSideDetection& result = *detection;
  for (const EdgeChain3d& chain : chains) {
    const int first_index = static_cast<int>(result.points.size());
    for (const EdgePoint3d& p : chain.points) {
      result.points.push_back(p);
      result.points_2d.push_back(frame.To2d(p.p_chain_body));
    }
    const int n = static_cast<int>(chain.points.size());
    int start = 0;
    for (int k = 1; k <= n; ++k) {
      const bool broken = k == n || (result.points_2d[first_index + k] -
                                     result.points_2d[first_index + k - 1])
                                            .norm() > options.max_chain_gap_m;
      if (!broken) continue;
      std::vector<Eigen::Vector2d> piece(
          result.points_2d.begin() + first_index + start,
          result.points_2d.begin() + first_index + k);
      const std::vector<int> vertices =
          DouglasPeucker(piece, options.polygon_tolerance_m);
      for (size_t v = 0; v + 1 < vertices.size(); ++v) {
        Segment2d segment;
        for (int i = vertices[v]; i <= vertices[v + 1]; ++i) {
          segment.support.push_back(first_index + start + i);
        }
        if (segment.support.size() < 4) continue;
        Eigen::Vector2d centre, direction;
        FitLine2d(result.points_2d, segment.support, &centre, &direction);
        const Eigen::Vector2d p0 = result.points_2d[segment.support.front()];
        const Eigen::Vector2d p1 = result.points_2d[segment.support.back()];
        segment.a = centre + (p0 - centre).dot(direction) * direction;
        segment.b = centre + (p1 - centre).dot(direction) * direction;
        if (segment.Length() < options.min_segment_length_m) continue;
        result.segments.push_back(std::move(segment));
      }
      start = k;
    }
  }
}

// The long sides of one paired accumulator component of direction set
// `set`: its segments among `members`, grouped in two passes, those
// longer than L_min fitted in 3D and appended to result.sides.
void ComponentSides(const std::vector<Segment2d>& members,
                    const AccumulatorComponent& component,
                    const Eigen::Vector2d& direction, int set,
                    const PlaneFrame& frame, const LongSideOptions& options,
                    LongSideDetection* detection) {
  LongSideDetection& result = *detection;
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  std::vector<Group> groups;
  for (const Segment2d& s : members) {
    const double middle = 0.5 * (s.a + s.b).dot(normal);
    if (middle < component.low_m - options.accumulator_cell_m ||
        middle > component.high_m + options.accumulator_cell_m) {
      continue;
    }
    groups.push_back(MakeGroup(result.points_2d, s.support, direction));
    double contrast = 0.0;
    for (int i : s.support) {
      contrast += result.points[i].gradient.dot(normal);
    }
    groups.back().polarity = contrast >= 0.0 ? 1 : -1;
  }
  groups = MergeCollinear(result.points_2d, std::move(groups), direction,
                          {options.pass1_max_gap_m, options.pass1_max_offset_m,
                           options.pass1_max_angle_rad});
  groups.erase(std::remove_if(groups.begin(), groups.end(),
                              [&](const Group& g) {
                                return g.Length() < options.pass1_min_length_m;
                              }),
               groups.end());
  groups = MergeCollinear(result.points_2d, std::move(groups), direction,
                          {options.pass2_max_gap_m, options.pass2_max_offset_m,
                           options.pass2_max_angle_rad});
  for (Group& g : groups) {
    VLOG(3) << "  group length " << g.Length() << " rms " << g.rms_m;
    if (g.Length() < options.min_long_side_length_m) continue;
    LongSide side =
        FitLongSide(result.points, std::move(g.support), frame, direction, set);
    VLOG(2) << "long side " << result.sides.size() << ": set " << set
            << " lateral " << side.lateral_m << " extent " << side.t_begin
            << " " << side.t_end << " contrast " << side.contrast << " points "
            << side.support.size();
    result.sides.push_back(std::move(side));
  }
}

}  // namespace

LongSideDetection DetectLongSides(const std::vector<EdgeChain3d>& chains,
                                  const PlaneFrame& frame,
                                  const ZebraSpecification& zebra,
                                  const LongSideOptions& options) {
  LongSideDetection result;
  PolygonSegments(chains, frame, options, &result);

  const double min_set_length =
      2.0 * options.high_vote_fraction * zebra.min_band_length_m;
  std::vector<char> used(result.segments.size(), 0);
  for (int set = 0; set < options.max_directions; ++set) {
    std::vector<Segment2d> remaining;
    std::vector<int> remaining_index;
    for (size_t i = 0; i < result.segments.size(); ++i) {
      if (used[i]) continue;
      remaining.push_back(result.segments[i]);
      remaining_index.push_back(static_cast<int>(i));
    }
    if (remaining.empty()) break;
    double weight = 0.0;
    const Eigen::Vector2d direction =
        PrincipalDirection(remaining, options.direction_tolerance_rad, &weight);
    if (weight < min_set_length) break;
    result.directions.push_back(direction);
    std::vector<Segment2d> members;
    for (size_t k = 0; k < remaining.size(); ++k) {
      const Eigen::Vector2d d = (remaining[k].b - remaining[k].a).normalized();
      if (std::abs(d.x() * direction.y() - d.y() * direction.x()) <=
          std::sin(options.direction_tolerance_rad)) {
        members.push_back(remaining[k]);
        used[remaining_index[k]] = 1;
      }
    }
    const std::vector<AccumulatorComponent> components =
        ParallelLineComponents(members, direction, zebra, options);
    for (const AccumulatorComponent& component : components) {
      VLOG(3) << "set " << set << " component at " << component.lateral_m
              << " m [" << component.low_m << ", " << component.high_m
              << "], peak " << component.peak_votes_m << " m, "
              << (component.paired ? "paired" : "alone");
      if (!component.paired) continue;
      // Segments of the component, grouped in two passes.
      ComponentSides(members, component, direction, set, frame, options,
                     &result);
    }
  }
  return result;
}

}  // namespace zebrageo
