// The cross-track offset from the road lines alone (line_offset.h).
#include "registration/line_offset.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

#include "registration/line_geometry_internal.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {

using line_geometry_internal::Compatible;
using line_geometry_internal::SegmentDistance2d;
using line_geometry_internal::SegmentGrid;

namespace {

// A point's vote: the shift that puts it on a database line, and where the
// point lies across the road.
struct Vote {
  double offset_m = 0.0;
  int point = 0;
  double lateral_m = 0.0;
  double weight = 1.0;
};

// A lane line of the other kind (dashed on solid) fits only a quarter as
// well: a shift by one lane puts a divider's dashes on the edge line, and
// periodic lanes would otherwise fit a lane away as well as in place.
constexpr double kOtherKindWeight = 0.25;

// The shifts along `left` within +-max_offset_m that put point `p` on a
// compatible database line (a segment's normal must be within 45 degrees
// of `left`: lines running with the vehicle).
void VotesOf(const LinePointEnu& p, int index, const Eigen::Vector2d& left,
             const std::vector<DatabaseLineEnu>& database,
             const SegmentGrid& grid, const LateralOffsetOptions& options,
             std::map<int, std::vector<int>>* near, std::vector<Vote>* votes) {
  const double reach = options.max_offset_m + options.tolerance_m;
  grid.Near(p.p_enu.head<2>(), reach, near);
  for (const auto& [l, segments] : *near) {
    const DatabaseLineEnu& line = database[l];
    if (!Compatible(p.type, line.type)) continue;
    for (const int s : segments) {
      const Eigen::Vector3d& a = line.points[s];
      const Eigen::Vector3d& b = line.points[s + 1];
      Eigen::Vector2d along = (b - a).head<2>();
      if (along.norm() < 1e-6) continue;
      along.normalize();
      const Eigen::Vector2d normal(-along.y(), along.x());
      const double c = left.dot(normal);
      if (std::abs(c) < std::sqrt(0.5)) continue;
      const double o = -(p.p_enu - a).head<2>().dot(normal) / c;
      if (std::abs(o) > options.max_offset_m) continue;
      double t = 0.0;
      Eigen::Vector3d shifted = p.p_enu;
      shifted.head<2>() += o * left;
      if (SegmentDistance2d(shifted, a, b, &t) > options.tolerance_m) continue;
      votes->push_back({o, index, p.p_enu.head<2>().dot(left),
                        p.type == line.type ? 1.0 : kOtherKindWeight});
    }
  }
}

// The distinct points voting within tolerance_m of `offset` (each its best
// weight), and their spread across the road. `votes` sorted by offset.
double PointsNear(const std::vector<Vote>& votes, double offset,
                  const LateralOffsetOptions& options, double* spread,
                  std::vector<double>* offsets) {
  auto first =
      std::lower_bound(votes.begin(), votes.end(), offset - options.tolerance_m,
                       [](const Vote& v, double o) { return v.offset_m < o; });
  std::map<int, double> points;  // point, best weight
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  if (offsets != nullptr) offsets->clear();
  for (auto v = first;
       v != votes.end() && v->offset_m <= offset + options.tolerance_m; ++v) {
    double& weight = points[v->point];
    weight = std::max(weight, v->weight);
    low = std::min(low, v->lateral_m);
    high = std::max(high, v->lateral_m);
    if (offsets != nullptr) offsets->push_back(v->offset_m);
  }
  if (spread != nullptr) *spread = points.empty() ? 0.0 : high - low;
  double score = 0.0;
  for (const auto& [point, weight] : points) score += weight;
  return score;
}

// The window's decision from its votes.
LateralOffset Decide(std::vector<Vote> votes,
                     const LateralOffsetOptions& options) {
  std::sort(votes.begin(), votes.end(), [](const Vote& a, const Vote& b) {
    return a.offset_m < b.offset_m;
  });
  const int bins =
      static_cast<int>(std::floor(options.max_offset_m / options.bin_m));
  std::vector<std::pair<double, double>> scores;  // offset, points
  for (int k = -bins; k <= bins; ++k) {
    const double offset = k * options.bin_m;
    scores.push_back(
        {offset, PointsNear(votes, offset, options, nullptr, nullptr)});
  }
  // The best (ties: the smallest shift), then the best far from it.
  const auto best = std::max_element(
      scores.begin(), scores.end(), [](const auto& a, const auto& b) {
        return a.second < b.second ||
               (a.second == b.second && std::abs(a.first) > std::abs(b.first));
      });
  LateralOffset out;
  out.points = best->second;
  for (const auto& [offset, points] : scores) {
    if (std::abs(offset - best->first) >= options.min_separation_m) {
      out.runner_up_points = std::max(out.runner_up_points, points);
    }
  }
  std::vector<double> offsets;
  PointsNear(votes, best->first, options, &out.spread_m, &offsets);
  out.offset_m = offsets.empty() ? best->first : Median(offsets);
  out.decided = out.points >= options.min_points &&
                out.points >= options.min_ratio * out.runner_up_points &&
                out.spread_m >= options.min_spread_m;
  return out;
}

// The shift within continuity_m of `reference` most points vote for, when
// at least min_continuity_points do: decided by continuity.
bool DecideNear(const std::vector<Vote>& votes, double reference,
                const LateralOffsetOptions& options, LateralOffset* window) {
  const int steps =
      static_cast<int>(std::floor(options.continuity_m / options.bin_m));
  double best_points = 0.0, best_offset = reference;
  for (int k = -steps; k <= steps; ++k) {
    const double offset = reference + k * options.bin_m;
    const double points = PointsNear(votes, offset, options, nullptr, nullptr);
    if (points > best_points) {
      best_points = points;
      best_offset = offset;
    }
  }
  if (best_points < options.min_continuity_points) return false;
  std::vector<double> offsets;
  window->points =
      PointsNear(votes, best_offset, options, &window->spread_m, &offsets);
  window->offset_m = offsets.empty() ? best_offset : Median(offsets);
  window->decided =
      std::abs(window->offset_m - reference) <= options.continuity_m;
  return window->decided;
}

// Undecided windows next to decided ones (by index, at most
// continuity_windows apart), nearest first, until none changes.
void DecideByContinuity(const std::vector<std::vector<Vote>>& votes,
                        const std::vector<int64_t>& index,
                        const LateralOffsetOptions& options,
                        std::vector<LateralOffset>* windows) {
  for (int gap = 1; gap <= options.continuity_windows; ++gap) {
    bool changed = true;
    while (changed) {
      changed = false;
      for (size_t w = 0; w < windows->size(); ++w) {
        if ((*windows)[w].decided) continue;
        // The decided neighbours `gap` windows away or nearer: one, or two
        // that agree.
        std::vector<double> references;
        for (size_t v = 0; v < windows->size(); ++v) {
          const int64_t d = std::abs(index[v] - index[w]);
          if (v != w && (*windows)[v].decided && d <= gap) {
            references.push_back((*windows)[v].offset_m);
          }
        }
        if (references.empty()) continue;
        const auto [lo, hi] =
            std::minmax_element(references.begin(), references.end());
        if (*hi - *lo > options.continuity_m) continue;
        if (DecideNear(votes[w], Median(references), options, &(*windows)[w])) {
          (*windows)[w].by_continuity = gap;
          changed = true;
        }
      }
    }
  }
}

}  // namespace

std::string LateralOffsetOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_offset_m, 0.0);
  OPTION_GT(check, window_s, 0.0);
  OPTION_GT(check, bin_m, 0.0);
  OPTION_GT(check, tolerance_m, 0.0);
  OPTION_GT(check, min_separation_m, 0.0);
  OPTION_GE(check, min_spread_m, 0.0);
  OPTION_GE(check, continuity_windows, 0);
  OPTION_GE(check, continuity_m, 0.0);
  OPTION_GE(check, min_continuity_points, 1.0);
  OPTION_GE(check, min_ratio, 1.0);
  OPTION_GE(check, min_points, 1);
  OPTION_REQUIRE(check, max_offset_m / bin_m <= 1e5, max_offset_m,
                 "must be at most 1e5 bins (bin_m)");
  return check.problem();
}

std::vector<LateralOffset> SearchLateralOffsets(
    const std::vector<LinePointEnu>& points, const std::vector<double>& time_of,
    const std::vector<Eigen::Vector2d>& left_of,
    const std::vector<DatabaseLineEnu>& database,
    const LateralOffsetOptions& options) {
  std::vector<LateralOffset> out;
  if (points.empty()) return out;
  const SegmentGrid grid(database, std::max(2.0, options.max_offset_m + 1.0));
  const double start = *std::min_element(time_of.begin(), time_of.end());
  std::map<int64_t, std::vector<Vote>> windows;
  std::map<int, std::vector<int>> near;
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].type == "stop_line") continue;  // across the road
    const int64_t w = static_cast<int64_t>(
        std::floor((time_of[i] - start) / options.window_s));
    std::vector<Vote>& votes = windows[w];
    VotesOf(points[i], static_cast<int>(i), left_of[i], database, grid, options,
            &near, &votes);
  }
  std::vector<std::vector<Vote>> kept;
  std::vector<int64_t> index;
  for (auto& [w, votes] : windows) {
    std::sort(votes.begin(), votes.end(), [](const Vote& a, const Vote& b) {
      return a.offset_m < b.offset_m;
    });
    LateralOffset offset = Decide(votes, options);
    offset.start_s = start + w * options.window_s;
    out.push_back(offset);
    kept.push_back(std::move(votes));
    index.push_back(w);
  }
  if (options.continuity_windows > 0) {
    DecideByContinuity(kept, index, options, &out);
  }
  return out;
}

}  // namespace zebrageo
