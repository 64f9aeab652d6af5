#include "reconstruction/transversal_search.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "survey/math_util.h"

namespace zebrageo {

PlaneLine FitPlaneLine(const std::vector<Eigen::Vector2d>& points,
                       const Eigen::Vector2d& fallback) {
  PlaneLine line;
  line.direction = fallback;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  line.point = mean;
  if (points.size() < 2) return line;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  double spread = 0.0;
  for (const Eigen::Vector2d& p : points) {
    scatter += (p - mean) * (p - mean).transpose();
    spread = std::max(spread, (p - mean).norm());
  }
  if (spread < 0.15) return line;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
  line.direction = solver.eigenvectors().col(1);
  if (line.direction.dot(fallback) < 0.0) line.direction = -line.direction;
  return line;
}

PlaneLine FitRobustPlaneLine(const std::vector<Eigen::Vector2d>& points,
                             const Eigen::Vector2d& fallback) {
  constexpr double kInlierDistance = 0.1;
  const double min_cos = std::cos(40.0 * kPi / 180.0);
  const int n = static_cast<int>(points.size());
  int best_count = 0;
  double best_residual = 1e30;
  PlaneLine best;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const Eigen::Vector2d d = points[j] - points[i];
      if (d.norm() < 0.3) continue;
      const Eigen::Vector2d direction = d.normalized();
      if (std::abs(direction.dot(fallback)) < min_cos) continue;
      const Eigen::Vector2d normal(-direction.y(), direction.x());
      int count = 0;
      double residual = 0.0;
      for (const Eigen::Vector2d& p : points) {
        const double r = std::abs((p - points[i]).dot(normal));
        if (r <= kInlierDistance) {
          ++count;
          residual += r;
        }
      }
      if (count > best_count ||
          (count == best_count && residual < best_residual)) {
        best_count = count;
        best_residual = residual;
        best.point = points[i];
        best.direction = direction.dot(fallback) < 0.0 ? -direction : direction;
      }
    }
  }
  if (best_count < 2) {
    // The median point along the perpendicular.
    std::vector<Eigen::Vector2d> sorted = points;
    const Eigen::Vector2d along(fallback.y(), -fallback.x());
    std::sort(sorted.begin(), sorted.end(),
              [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
                return a.dot(along) < b.dot(along);
              });
    PlaneLine line;
    line.direction = fallback;
    line.point =
        sorted.empty() ? Eigen::Vector2d::Zero() : sorted[sorted.size() / 2];
    return line;
  }
  std::vector<Eigen::Vector2d> inliers;
  const Eigen::Vector2d normal(-best.direction.y(), best.direction.x());
  for (const Eigen::Vector2d& p : points) {
    if (std::abs((p - best.point).dot(normal)) <= kInlierDistance) {
      inliers.push_back(p);
    }
  }
  return FitPlaneLine(inliers, best.direction);
}

Eigen::Vector2d AtLateral(const PlaneLine& line, const Eigen::Vector2d& along,
                          const Eigen::Vector2d& normal, double lateral,
                          double shift) {
  const Eigen::Vector2d origin = line.point + shift * along;
  const double denominator = line.direction.dot(normal);
  const double t = std::abs(denominator) > 1e-9
                       ? (lateral - origin.dot(normal)) / denominator
                       : 0.0;
  return origin + t * line.direction;
}

TransversalSearch ApproximateTransversalSides(
    const BandPairs& bands, const BandOptions& options,
    const std::vector<char>& excluded) {
  const int crossings = bands.crossings;
  const int m = bands.seen;
  const std::vector<BandCandidate>& pairs = bands.pairs;
  const std::vector<LongSide>& sides = bands.sides;
  const std::vector<int>& crossing_of = bands.crossing_of;
  TransversalSearch search;
  std::vector<PlaneLine>& begin_lines = search.begin_lines;
  std::vector<PlaneLine>& end_lines = search.end_lines;
  begin_lines.resize(crossings);
  end_lines.resize(crossings);
  for (int c = 0; c < crossings; ++c) {
    double longest = 0.0;
    Eigen::Vector2d along = Eigen::Vector2d::UnitX();
    auto votes = [&](int i) {
      return crossing_of[i] == c &&
             (excluded.empty() || !excluded[static_cast<size_t>(i)]);
    };
    for (int i = 0; i < m; ++i) {
      if (!votes(i)) continue;
      longest = std::max(longest, pairs[i].end - pairs[i].begin);
      along = sides[pairs[i].lo].direction_2d;
    }
    const Eigen::Vector2d across(-along.y(), along.x());
    std::vector<Eigen::Vector2d> begins, ends;
    for (int i = 0; i < m; ++i) {
      if (!votes(i)) continue;
      if (pairs[i].end - pairs[i].begin <
          options.extremity_length_fraction * longest) {
        continue;
      }
      // The ends of the band's overlap, in the middle of the band.
      const double middle =
          0.5 * (sides[pairs[i].lo].lateral_m + sides[pairs[i].hi].lateral_m);
      begins.push_back(pairs[i].begin * along + middle * across);
      ends.push_back(pairs[i].end * along + middle * across);
    }
    begin_lines[c] = FitRobustPlaneLine(begins, across);
    end_lines[c] = FitRobustPlaneLine(ends, across);
    VLOG(2) << "crossing " << c << ": begin line "
            << begin_lines[c].point.transpose() << " dir "
            << begin_lines[c].direction.transpose() << ", end line "
            << end_lines[c].point.transpose() << " dir "
            << end_lines[c].direction.transpose() << " across "
            << across.transpose();
  }
  return search;
}

}  // namespace zebrageo
