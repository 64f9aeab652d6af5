#include "reconstruction/paint_gaps.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace zebrageo {
namespace {

// The stretches along `along` of at least `min_gap` between consecutive
// points of `support` within [begin, end].
std::vector<std::pair<double, double>> SupportGaps(
    const std::vector<Eigen::Vector2d>& points_2d, const LongSide& side,
    const Eigen::Vector2d& along, double begin, double end, double min_gap) {
  std::vector<double> t;
  t.reserve(side.support.size());
  for (int i : side.support) {
    const double x = points_2d[i].dot(along);
    if (x >= begin && x <= end) t.push_back(x);
  }
  std::sort(t.begin(), t.end());
  std::vector<std::pair<double, double>> gaps;
  for (size_t k = 1; k < t.size(); ++k) {
    if (t[k] - t[k - 1] >= min_gap) gaps.push_back({t[k - 1], t[k]});
  }
  return gaps;
}

// A gap common to both long sides: where each stops and starts again.
struct CommonGap {
  double lo_start, lo_stop, hi_start, hi_stop;
};

// The gradient along the straight path from plane point a to b in
// rectified image `side`, summed pixel by pixel: b's brightness relative to
// a's in *step, and with `profile` (may be null) the brightness so far,
// (share of the path, brightness), at a and after every pixel. False when
// the path is shorter than `min_length_px` or part of it is not usable.
bool IntegrateBrightness(const PlaneFrame& frame, const RoadRectification& rect,
                         int side, const EdgeMap& edges,
                         const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         double min_length_px, double* step,
                         std::vector<std::pair<double, double>>* profile) {
  Eigen::Vector2d xa, xb;
  if (!rect.ProjectToRectified(side, frame.To3d(a), &xa) ||
      !rect.ProjectToRectified(side, frame.To3d(b), &xb)) {
    return false;
  }
  const Eigen::Vector2d span = xb - xa;
  const double length = span.norm();
  if (!(length >= min_length_px) || length > 1e4) return false;
  const Eigen::Vector2d unit = span / length;
  const int n = static_cast<int>(std::ceil(length));
  const double du = length / n;
  double brightness = 0.0;
  if (profile != nullptr) profile->push_back({0.0, 0.0});
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d x = xa + (k + 0.5) * du * unit;
    if (!edges.IsUsable(x.x(), x.y())) return false;
    const cv::Vec2f g = edges.GradientAt(x.x(), x.y());
    brightness += du * (unit.x() * g[0] + unit.y() * g[1]);
    if (profile != nullptr) profile->push_back({(k + 1.0) / n, brightness});
  }
  *step = brightness;
  return true;
}

// The brightness profile of IntegrateBrightness over at least 2 pixels;
// empty when part of the path is not usable.
std::vector<std::pair<double, double>> BrightnessProfile(
    const PlaneFrame& frame, const RoadRectification& rect, int side,
    const EdgeMap& edges, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  std::vector<std::pair<double, double>> profile;
  double step = 0.0;
  if (!IntegrateBrightness(frame, rect, side, edges, a, b, 2.0, &step,
                           &profile)) {
    profile.clear();
  }
  return profile;
}

// Whether rectified image `side` shows road in the gap: on at least two of
// three lines along the band (at a quarter, half and three quarters of its
// width), the darkest point of the gap is darker than the brightest of the
// paint just before it and of the paint just after it by `fraction` of the
// step from the paint to the road beside the band. The long sides' points
// lie on the paint's edges, so the paint's own gap lies within theirs.
bool ImageShowsRoad(const PlaneFrame& frame, const RoadRectification& rect,
                    int side, const EdgeMap& edges, const LongSide& lo,
                    const LongSide& hi, const CommonGap& gap, double fraction) {
  // The paint is looked for this far before and after the gap; the road
  // beside the band this far out.
  constexpr double kPaintReachM = 0.2;
  constexpr double kBesideM = 0.12;
  const Eigen::Vector2d along = lo.direction_2d;
  const Eigen::Vector2d normal = lo.Normal2d();
  const double width = hi.lateral_m - lo.lateral_m;
  auto at = [&](double t, double l) { return t * along + l * normal; };
  // The paint's step to the road beside the band (> 0 for paint), in the
  // middle of the band before the gap.
  const double middle_lateral = lo.lateral_m + 0.5 * width;
  const double t_step =
      0.5 * (gap.lo_start + gap.hi_start) - 0.5 * kPaintReachM;
  double out_lo = 0.0, out_hi = 0.0;
  if (!PlaneBrightnessStep(frame, rect, side, edges, at(t_step, middle_lateral),
                           at(t_step, lo.lateral_m - kBesideM), &out_lo) ||
      !PlaneBrightnessStep(frame, rect, side, edges, at(t_step, middle_lateral),
                           at(t_step, hi.lateral_m + kBesideM), &out_hi)) {
    return false;
  }
  const double paint_step = -0.5 * (out_lo + out_hi);
  if (!(paint_step > 0.0)) return false;
  int road = 0;
  for (double f : {0.25, 0.5, 0.75}) {
    const double lateral = lo.lateral_m + f * width;
    const double start = gap.lo_start + f * (gap.hi_start - gap.lo_start);
    const double stop = gap.lo_stop + f * (gap.hi_stop - gap.lo_stop);
    const double t0 = start - kPaintReachM;
    const double t1 = stop + kPaintReachM;
    const auto profile = BrightnessProfile(frame, rect, side, edges,
                                           at(t0, lateral), at(t1, lateral));
    if (profile.empty()) continue;
    double before = -1e30, after = -1e30, darkest = 1e30;
    for (const auto& [share, brightness] : profile) {
      const double t = t0 + share * (t1 - t0);
      if (t <= start) before = std::max(before, brightness);
      if (t >= stop) after = std::max(after, brightness);
      if (t >= start && t <= stop) darkest = std::min(darkest, brightness);
    }
    if (!(darkest < 1e30)) continue;
    const double drop = std::min(before, after) - darkest;
    VLOG(3) << "gap " << start << ".." << stop << " lateral " << lateral
            << " image " << side << ": before " << before - darkest << " after "
            << after - darkest << " paint step " << paint_step;
    if (drop >= fraction * paint_step) ++road;
  }
  return road >= 2;
}

}  // namespace

bool PlaneBrightnessStep(const PlaneFrame& frame,
                         const RoadRectification& rectification, int side,
                         const EdgeMap& edges, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b, double* step) {
  return IntegrateBrightness(frame, rectification, side, edges, a, b, 1.0, step,
                             nullptr);
}

int CutAtPaintGaps(const std::vector<Eigen::Vector2d>& points_2d,
                   const PlaneFrame& frame,
                   const RoadRectification& rectification,
                   const EdgeMap edges[2], const LongSide& lo,
                   const LongSide& hi, const BandOptions& options,
                   double* begin, double* end) {
  const Eigen::Vector2d along = lo.direction_2d;
  const std::vector<std::pair<double, double>> lo_gaps =
      SupportGaps(points_2d, lo, along, *begin, *end, options.min_paint_gap_m);
  if (lo_gaps.empty()) return 0;
  const std::vector<std::pair<double, double>> hi_gaps =
      SupportGaps(points_2d, hi, along, *begin, *end, options.min_paint_gap_m);
  // The pieces between the cuts: (begin, end) along the band.
  std::vector<std::pair<double, double>> pieces;
  double piece_begin = *begin;
  for (const auto& a : lo_gaps) {
    for (const auto& b : hi_gaps) {
      // Both sides stop over a common stretch (a skewed crossing's ends
      // are offset from one side to the other, less than the gap).
      if (std::min(a.second, b.second) - std::max(a.first, b.first) <= 0.0) {
        continue;
      }
      const CommonGap gap{a.first, a.second, b.first, b.second};
      VLOG(3) << "sides " << lo.lateral_m << " " << hi.lateral_m
              << ": common gap lo " << a.first << ".." << a.second << " hi "
              << b.first << ".." << b.second;
      if (!ImageShowsRoad(frame, rectification, 0, edges[0], lo, hi, gap,
                          options.min_paint_gap_drop_fraction) ||
          !ImageShowsRoad(frame, rectification, 1, edges[1], lo, hi, gap,
                          options.min_paint_gap_drop_fraction)) {
        continue;
      }
      pieces.push_back({piece_begin, std::min(a.first, b.first)});
      piece_begin = std::max(a.second, b.second);
    }
  }
  if (pieces.empty()) return 0;
  pieces.push_back({piece_begin, *end});
  const auto longest = std::max_element(
      pieces.begin(), pieces.end(), [](const auto& x, const auto& y) {
        return x.second - x.first < y.second - y.first;
      });
  VLOG(2) << "band of sides at " << lo.lateral_m << " " << hi.lateral_m << ": "
          << pieces.size() - 1 << " paint gaps in [" << *begin << ", " << *end
          << "], kept [" << longest->first << ", " << longest->second << "]";
  *begin = longest->first;
  *end = longest->second;
  return static_cast<int>(pieces.size()) - 1;
}

}  // namespace zebrageo
