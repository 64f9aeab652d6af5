// Internal to registration/: the database lines' geometry the line
// matcher (line_matcher.cc) and the lateral offset search (line_offset.cc)
// share.
#ifndef ZEBRAGEO_REGISTRATION_LINE_GEOMETRY_INTERNAL_H_
#define ZEBRAGEO_REGISTRATION_LINE_GEOMETRY_INTERNAL_H_

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "registration/line_matcher.h"

namespace zebrageo {
namespace line_geometry_internal {

inline bool Compatible(const std::string& a, const std::string& b) {
  const bool stop_a = a == "stop_line", stop_b = b == "stop_line";
  const bool lane_a = a.rfind("lane_", 0) == 0,
             lane_b = b.rfind("lane_", 0) == 0;
  return (stop_a && stop_b) || (lane_a && lane_b);
}

// Nearest point (horizontally) of segment ab to p; t in [0, 1].
inline double SegmentDistance2d(const Eigen::Vector3d& p,
                                const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, double* t) {
  const Eigen::Vector2d d = (b - a).head<2>();
  const double l2 = d.squaredNorm();
  *t = l2 > 0.0 ? std::clamp((p - a).head<2>().dot(d) / l2, 0.0, 1.0) : 0.0;
  return (p.head<2>() - (a.head<2>() + *t * d)).norm();
}

struct Nearest {
  int line = -1;
  int segment = -1;
  double t = 0.0;
  double distance = std::numeric_limits<double>::infinity();
};

// The database's segments in a uniform grid, so that a point meets only
// the segments near it (a city's database holds tens of thousands of lines).
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<DatabaseLineEnu>& database, double cell_m)
      : cell_m_(cell_m) {
    for (int l = 0; l < static_cast<int>(database.size()); ++l) {
      const auto& points = database[l].points;
      for (int s = 0; s + 1 < static_cast<int>(points.size()); ++s) {
        const Eigen::Vector2d a = points[s].head<2>();
        const Eigen::Vector2d b = points[s + 1].head<2>();
        const auto [x0, y0] = Cell(a.cwiseMin(b));
        const auto [x1, y1] = Cell(a.cwiseMax(b));
        for (int64_t x = x0; x <= x1; ++x) {
          for (int64_t y = y0; y <= y1; ++y)
            cells_[Key(x, y)].push_back({l, s});
        }
      }
    }
  }

  // Every segment with a part within `radius` of p (and a few more), each
  // once, grouped by line in `out`.
  void Near(const Eigen::Vector2d& p, double radius,
            std::map<int, std::vector<int>>* out) const {
    out->clear();
    const Eigen::Vector2d r(radius, radius);
    const auto [x0, y0] = Cell(p - r);
    const auto [x1, y1] = Cell(p + r);
    for (int64_t x = x0; x <= x1; ++x) {
      for (int64_t y = y0; y <= y1; ++y) {
        const auto it = cells_.find(Key(x, y));
        if (it == cells_.end()) continue;
        for (const auto& [line, segment] : it->second) {
          (*out)[line].push_back(segment);
        }
      }
    }
    for (auto& [line, segments] : *out) {
      std::sort(segments.begin(), segments.end());
      segments.erase(std::unique(segments.begin(), segments.end()),
                     segments.end());
    }
  }

 private:
  std::pair<int64_t, int64_t> Cell(const Eigen::Vector2d& p) const {
    return {static_cast<int64_t>(std::floor(p.x() / cell_m_)),
            static_cast<int64_t>(std::floor(p.y() / cell_m_))};
  }
  static uint64_t Key(int64_t x, int64_t y) {
    return (static_cast<uint64_t>(x) << 32) ^
           (static_cast<uint64_t>(y) & 0xffffffffULL);
  }
  double cell_m_;
  std::unordered_map<uint64_t, std::vector<std::pair<int, int>>> cells_;
};

}  // namespace line_geometry_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_LINE_GEOMETRY_INTERNAL_H_
