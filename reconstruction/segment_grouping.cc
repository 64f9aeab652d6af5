#include "reconstruction/segment_grouping.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

namespace zebrageo {
namespace {

double PerpendicularDistance(const Group& g, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = p - g.centre;
  return std::abs(d.x() * g.direction.y() - d.y() * g.direction.x());
}

}  // namespace

// Total least squares line through 2D points: centre and unit direction.
void FitLine2d(const std::vector<Eigen::Vector2d>& points,
               const std::vector<int>& support, Eigen::Vector2d* centre,
               Eigen::Vector2d* direction) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i : support) mean += points[i];
  mean /= static_cast<double>(support.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int i : support) {
    scatter += (points[i] - mean) * (points[i] - mean).transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
  *centre = mean;
  *direction = solver.eigenvectors().col(1);
}

Group MakeGroup(const std::vector<Eigen::Vector2d>& points,
                std::vector<int> support, const Eigen::Vector2d& axis) {
  Group g;
  g.support = std::move(support);
  FitLine2d(points, g.support, &g.centre, &g.direction);
  if (g.direction.dot(axis) < 0.0) g.direction = -g.direction;
  const Eigen::Vector2d normal(-g.direction.y(), g.direction.x());
  g.t_min = 1e30;
  g.t_max = -1e30;
  double sum_squares = 0.0;
  for (int i : g.support) {
    const Eigen::Vector2d d = points[i] - g.centre;
    const double t = d.dot(g.direction);
    g.t_min = std::min(g.t_min, t);
    g.t_max = std::max(g.t_max, t);
    sum_squares += d.dot(normal) * d.dot(normal);
  }
  g.rms_m = std::sqrt(sum_squares / g.support.size());
  return g;
}

// Greedy best-first merging of collinear groups (an approximation of Jang
// and Hong's globally favourable grouping): candidate links are sorted by a
// normalised cost of gap, offset and angle, and merged while the merged
// group stays a line (rms below the offset threshold).
std::vector<Group> MergeCollinear(const std::vector<Eigen::Vector2d>& points,
                                  std::vector<Group> groups,
                                  const Eigen::Vector2d& axis,
                                  const GroupingThresholds& limits) {
  for (bool merged = true; merged;) {
    merged = false;
    struct Link {
      double cost;
      int i, j;
    };
    std::vector<Link> links;
    const int n = static_cast<int>(groups.size());
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const Group& a = groups[i];
        const Group& b = groups[j];
        // A band's side running on into a lane line's opposite edge, or a
        // shadow boundary, collinear with it is not one line.
        if (a.polarity != b.polarity) continue;
        const double angle =
            std::acos(std::min(1.0, std::abs(a.direction.dot(b.direction))));
        // A short group's direction is uncertain: its angle may exceed the
        // threshold as long as its ends stay within the offset (below).
        const double shorter_length = std::min(a.Length(), b.Length());
        const double max_angle =
            std::max(limits.max_angle_rad,
                     std::atan2(limits.max_offset_m, 0.5 * shorter_length));
        if (angle > max_angle) continue;
        const double a0 = (a.Begin() - a.centre).dot(axis) + a.centre.dot(axis);
        const double a1 = (a.End() - a.centre).dot(axis) + a.centre.dot(axis);
        const double b0 = (b.Begin() - b.centre).dot(axis) + b.centre.dot(axis);
        const double b1 = (b.End() - b.centre).dot(axis) + b.centre.dot(axis);
        const double gap = std::max(b0 - a1, a0 - b1);
        if (gap > limits.max_gap_m) continue;
        // The shorter group's ends must lie on the longer group's line.
        const Group& longer = a.Length() >= b.Length() ? a : b;
        const Group& shorter = a.Length() >= b.Length() ? b : a;
        const double offset =
            std::max(PerpendicularDistance(longer, shorter.Begin()),
                     PerpendicularDistance(longer, shorter.End()));
        if (offset > limits.max_offset_m) continue;
        links.push_back({std::max(0.0, gap) / limits.max_gap_m +
                             offset / limits.max_offset_m + angle / max_angle,
                         i, j});
      }
    }
    std::sort(links.begin(), links.end(), [](const Link& x, const Link& y) {
      return x.cost < y.cost || (x.cost == y.cost && x.i < y.i) ||
             (x.cost == y.cost && x.i == y.i && x.j < y.j);
    });
    std::vector<char> touched(groups.size(), 0);
    std::vector<Group> next;
    for (const Link& link : links) {
      if (touched[link.i] || touched[link.j]) continue;
      std::vector<int> support = groups[link.i].support;
      support.insert(support.end(), groups[link.j].support.begin(),
                     groups[link.j].support.end());
      Group joined = MakeGroup(points, std::move(support), axis);
      joined.polarity = groups[link.i].polarity;
      if (joined.rms_m > limits.max_offset_m) continue;
      touched[link.i] = touched[link.j] = 1;
      next.push_back(std::move(joined));
      merged = true;
    }
    for (int i = 0; i < n; ++i) {
      if (!touched[i]) next.push_back(std::move(groups[i]));
    }
    groups = std::move(next);
  }
  return groups;
}

}  // namespace zebrageo
