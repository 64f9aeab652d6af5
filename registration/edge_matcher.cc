#include "registration/edge_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// The horizontal unit direction of a band's long sides.
Eigen::Vector2d LongAxis(const std::array<Eigen::Vector3d, 4>& c) {
  const Eigen::Vector2d a = (c[1] - c[0]).head<2>();
  const Eigen::Vector2d b = (c[2] - c[1]).head<2>();
  return (a.norm() >= b.norm() ? a : b).normalized();
}

// The edge through `points` (ordered), its line and extent.
DatabaseCrossingEdge EdgeThrough(const std::string& crossing_id,
                                 std::vector<Eigen::Vector3d> points,
                                 double sigma_xy_m) {
  DatabaseCrossingEdge edge;
  edge.crossing_id = crossing_id;
  edge.sigma_xy_m = sigma_xy_m;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& p : points) centre += p.head<2>();
  centre /= static_cast<double>(points.size());
  // The principal direction, signed the way the points run.
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d d = p.head<2>() - centre;
    scatter += d * d.transpose();
  }
  const double angle =
      0.5 * std::atan2(2.0 * scatter(0, 1), scatter(0, 0) - scatter(1, 1));
  Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
  if (direction.dot((points.back() - points.front()).head<2>()) < 0.0) {
    direction = -direction;
  }
  edge.point = centre;
  edge.direction = direction;
  edge.from_m = std::numeric_limits<double>::infinity();
  edge.to_m = -edge.from_m;
  for (const Eigen::Vector3d& p : points) {
    const double s = (p.head<2>() - centre).dot(direction);
    edge.from_m = std::min(edge.from_m, s);
    edge.to_m = std::max(edge.to_m, s);
  }
  edge.points = std::move(points);
  return edge;
}

}  // namespace

std::string CrossingEdgeMatchOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, gate_m, 0.0);
  OPTION_GE(check, min_separation_ratio, 1.0);
  OPTION_IN(check, max_angle_rad, "(", 0.0, 1.0, ")");
  OPTION_GT(check, max_spread_m, 0.0);
  OPTION_GE(check, extent_margin_m, 0.0);
  return check.problem();
}

std::vector<DatabaseCrossingEdge> DatabaseCrossingEdges(
    const RoadmarkDatabase& database, const LocalFrame& frame) {
  std::map<std::string, std::vector<const RoadmarkBand*>> crossings;
  for (const RoadmarkBand& band : database.bands) {
    crossings[band.crossing_id].push_back(&band);
  }
  std::vector<DatabaseCrossingEdge> edges;
  for (const auto& [id, bands] : crossings) {
    if (bands.size() < 2) continue;
    std::vector<std::array<Eigen::Vector3d, 4>> corners;
    double sigma_xy = 0.0;
    for (const RoadmarkBand* band : bands) {
      std::array<Eigen::Vector3d, 4> c;
      for (int k = 0; k < 4; ++k)
        c[k] = frame.EnuFromGeodetic(band->corners[k]);
      corners.push_back(c);
      sigma_xy = std::max(sigma_xy, band->sigma_xy_m);
    }
    // The crossing's band direction u, each band's signed alike.
    const Eigen::Vector2d first = LongAxis(corners.front());
    Eigen::Vector2d u = Eigen::Vector2d::Zero();
    for (const auto& c : corners) {
      const Eigen::Vector2d a = LongAxis(c);
      u += a.dot(first) >= 0.0 ? a : -a;
    }
    u.normalize();
    const Eigen::Vector2d w(-u.y(), u.x());  // across the bands, u's left
    // Each band's end mid-points: +u end and -u end.
    std::vector<std::pair<double, Eigen::Vector3d>> plus, minus;
    for (const auto& c : corners) {
      std::array<int, 4> order = {0, 1, 2, 3};
      std::sort(order.begin(), order.end(), [&](int i, int j) {
        return c[i].head<2>().dot(u) < c[j].head<2>().dot(u);
      });
      const Eigen::Vector3d low = 0.5 * (c[order[0]] + c[order[1]]);
      const Eigen::Vector3d high = 0.5 * (c[order[2]] + c[order[3]]);
      minus.emplace_back(low.head<2>().dot(w), low);
      plus.emplace_back(high.head<2>().dot(w), high);
    }
    // The +u edge has its paint towards -u: running along w, the paint is
    // on its left (left of w is -u). The -u edge runs along -w.
    std::sort(plus.begin(), plus.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::sort(minus.begin(), minus.end(),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    for (const auto* side : {&plus, &minus}) {
      std::vector<Eigen::Vector3d> points;
      for (const auto& [s, p] : *side) points.push_back(p);
      edges.push_back(EdgeThrough(id, std::move(points), sigma_xy));
      edges.back().id = id + (side == &plus ? ":edge+" : ":edge-");
    }
  }
  return edges;
}

std::vector<CrossingEdgeMatch> MatchCrossingEdges(
    const std::vector<std::vector<Eigen::Vector3d>>& edges,
    const std::vector<DatabaseCrossingEdge>& database,
    const CrossingEdgeMatchOptions& options) {
  std::vector<CrossingEdgeMatch> out;
  const double cos_max = std::cos(options.max_angle_rad);
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    const std::vector<Eigen::Vector3d>& points = edges[e];
    if (points.size() < 2) continue;
    const Eigen::Vector2d run = (points.back() - points.front()).head<2>();
    if (run.norm() < 0.5) continue;
    const Eigen::Vector2d direction = run.normalized();
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    double second_distance = best_distance, best_offset = 0.0;
    for (int d = 0; d < static_cast<int>(database.size()); ++d) {
      const DatabaseCrossingEdge& db = database[d];
      if (direction.dot(db.direction) < cos_max) continue;
      std::vector<double> offsets;
      int within = 0;
      for (const Eigen::Vector3d& p : points) {
        const Eigen::Vector2d r = p.head<2>() - db.point;
        offsets.push_back(r.dot(db.Normal()));
        const double s = r.dot(db.direction);
        within += s >= db.from_m - options.extent_margin_m &&
                  s <= db.to_m + options.extent_margin_m;
      }
      // Most points on the database edge: it may lack an end band.
      const int n = static_cast<int>(points.size());
      const bool inside = within >= std::max(2, (2 * n + 2) / 3);
      const double offset = Median(offsets);
      double spread = 0.0;
      for (double o : offsets) spread = std::max(spread, std::abs(o - offset));
      // An edge elsewhere along its line (another crossing on the same
      // side of a junction) still competes.
      const double distance =
          inside ? std::abs(offset)
                 : std::max(std::abs(offset), options.extent_margin_m);
      if (inside && spread <= options.max_spread_m &&
          distance < best_distance) {
        second_distance = std::min(second_distance, best_distance);
        best = d;
        best_distance = distance;
        best_offset = offset;
      } else {
        second_distance = std::min(second_distance, distance);
      }
    }
    if (best < 0 || best_distance > options.gate_m ||
        second_distance < options.gate_m ||
        second_distance < options.min_separation_ratio * best_distance) {
      continue;
    }
    out.push_back({e, best, best_offset});
  }
  return out;
}

}  // namespace zebrageo
