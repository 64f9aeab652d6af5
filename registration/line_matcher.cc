#include "registration/line_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

bool Compatible(const std::string& a, const std::string& b) {
  const bool stop_a = a == "stop_line", stop_b = b == "stop_line";
  const bool lane_a = a.rfind("lane_", 0) == 0,
             lane_b = b.rfind("lane_", 0) == 0;
  return (stop_a && stop_b) || (lane_a && lane_b);
}

// Nearest point (horizontally) of segment ab to p; t in [0, 1].
double SegmentDistance2d(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
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

}  // namespace

std::string LineMatchOptions::Check() const {
  std::ostringstream e;
  if (!(gate_m > 0.0) || !(max_height_m > 0.0)) {
    e << "gate_m and max_height_m must be positive";
  } else if (!(min_separation_ratio >= 1.0)) {
    e << "min_separation_ratio must be at least 1";
  } else if (!(max_angle_rad > 0.0 && max_angle_rad < M_PI / 2)) {
    e << "max_angle_rad must be in (0, pi/2)";
  } else if (!(min_matched_share > 0.0 && min_matched_share <= 1.0)) {
    e << "min_matched_share must be in (0, 1]";
  }
  const std::string error = e.str();
  return error.empty() ? error : "line matching options: " + error;
}

double DatabaseLineGrade(const DatabaseLineEnu& line, int segment, double t,
                         double half_window_m) {
  const std::vector<Eigen::Vector3d>& p = line.points;
  const int n = static_cast<int>(p.size());
  if (segment < 0 || segment + 1 >= n) return 0.0;
  // Horizontal arc length of each vertex.
  std::vector<double> arc(n, 0.0);
  for (int i = 1; i < n; ++i) {
    arc[i] = arc[i - 1] + (p[i] - p[i - 1]).head<2>().norm();
  }
  const double at = arc[segment] + t * (arc[segment + 1] - arc[segment]);
  double sw = 0.0, ss = 0.0, sz = 0.0, sss = 0.0, ssz = 0.0;
  for (int i = 0; i < n; ++i) {
    if (std::abs(arc[i] - at) > half_window_m) continue;
    const double s_i = arc[i] - at;
    sw += 1.0;
    ss += s_i;
    sz += p[i].z();
    sss += s_i * s_i;
    ssz += s_i * p[i].z();
  }
  const double denominator = sw * sss - ss * ss;
  if (sw >= 3.0 && denominator > 1e-9) {
    return (sw * ssz - ss * sz) / denominator;
  }
  const double run = arc[segment + 1] - arc[segment];
  return run > 1e-6 ? (p[segment + 1].z() - p[segment].z()) / run : 0.0;
}

std::vector<DatabaseLineEnu> DatabaseLinesEnu(const RoadmarkDatabase& database,
                                              const LocalFrame& frame) {
  std::vector<DatabaseLineEnu> out;
  for (const RoadmarkLine& line : database.lines) {
    if (line.points.size() < 2) continue;
    DatabaseLineEnu enu;
    enu.id = line.id;
    enu.type = line.type;
    enu.sigma_xy_m = line.sigma_xy_m;
    enu.sigma_z_m = line.sigma_z_m;
    for (const Geodetic& g : line.points) {
      enu.points.push_back(frame.EnuFromGeodetic(g));
    }
    out.push_back(std::move(enu));
  }
  return out;
}

std::vector<LinePointMatch> MatchLinePoints(
    const std::vector<LinePointEnu>& points,
    const std::vector<DatabaseLineEnu>& database,
    const LineMatchOptions& options) {
  std::vector<LinePointMatch> out;
  // Lines farther than this cannot change a decision: a point is kept when
  // its nearest line is within gate_m and every other one is beyond both
  // gate_m and min_separation_ratio times that.
  const double radius =
      std::max(1.0, options.min_separation_ratio) * options.gate_m;
  const SegmentGrid grid(database, std::max(2.0, radius));
  std::map<int, std::vector<int>> near;
  size_t begin = 0;
  while (begin < points.size()) {
    size_t end = begin + 1;
    while (end < points.size() &&
           points[end].line_id == points[begin].line_id) {
      ++end;
    }
    // The reconstructed line's direction (first to last point).
    Eigen::Vector2d direction =
        (points[end - 1].p_enu - points[begin].p_enu).head<2>();
    const bool has_direction = direction.norm() > 0.3;
    direction.normalize();
    std::vector<LinePointMatch> matches;
    std::map<int, int> votes;
    for (size_t i = begin; i < end; ++i) {
      const LinePointEnu& p = points[i];
      // Nearest compatible line, and the nearest other line of any type.
      Nearest best, second;
      grid.Near(p.p_enu.head<2>(), radius, &near);
      for (const auto& [l, segments] : near) {
        const DatabaseLineEnu& line = database[l];
        Nearest n;
        for (const int s : segments) {
          double t = 0.0;
          const double d = SegmentDistance2d(p.p_enu, line.points[s],
                                             line.points[s + 1], &t);
          if (d < n.distance) n = {l, s, t, d};
        }
        if (!Compatible(p.type, line.type)) {
          second.distance = std::min(second.distance, n.distance);
        } else if (n.distance < best.distance) {
          second.distance = std::min(second.distance, best.distance);
          best = n;
        } else {
          second.distance = std::min(second.distance, n.distance);
        }
      }
      if (best.line < 0 || best.distance > options.gate_m ||
          second.distance < options.min_separation_ratio * best.distance ||
          second.distance < options.gate_m) {
        continue;
      }
      const DatabaseLineEnu& line = database[best.line];
      const Eigen::Vector3d& a = line.points[best.segment];
      const Eigen::Vector3d& b = line.points[best.segment + 1];
      Eigen::Vector3d along(b.x() - a.x(), b.y() - a.y(), 0.0);
      if (along.norm() < 1e-6) continue;
      along.normalize();
      if (has_direction && std::abs(direction.dot(along.head<2>())) <
                               std::cos(options.max_angle_rad)) {
        continue;
      }
      LinePointMatch m;
      m.point = static_cast<int>(i);
      m.db_line = best.line;
      m.db_segment = best.segment;
      m.db_segment_t = best.t;
      m.db_point_enu = a + best.t * (b - a);
      m.along_enu = along;
      m.across_enu = Eigen::Vector3d(-along.y(), along.x(), 0.0);
      m.distance_m = (p.p_enu - m.db_point_enu).dot(m.across_enu);
      m.height_m = p.p_enu.z() - m.db_point_enu.z();
      if (std::abs(m.height_m) > options.max_height_m) continue;
      matches.push_back(m);
      ++votes[best.line];
    }
    // One database line for the whole reconstructed line.
    if (votes.size() == 1 &&
        matches.size() >= options.min_matched_share * (end - begin)) {
      out.insert(out.end(), matches.begin(), matches.end());
    }
    begin = end;
  }
  return out;
}

std::string LineConsistencyOptions::Check() const {
  std::ostringstream e;
  if (!(window_s > 0.0) || !(max_offset_m > 0.0)) {
    e << "window_s and max_offset_m must be positive";
  } else if (min_points < 1) {
    e << "min_points must be at least 1";
  } else if (!(min_parallel_cos > 0.0 && min_parallel_cos < 1.0)) {
    e << "min_parallel_cos must be in (0, 1)";
  }
  const std::string error = e.str();
  return error.empty() ? error : "line consistency options: " + error;
}

namespace {

// The matches of one database line within one second: their median
// distance across the line, the line's normal there, and how many.
struct LineSecond {
  int db_line = 0;
  int64_t second = 0;
  double distance_m = 0.0;
  Eigen::Vector2d across = Eigen::Vector2d::Zero();
  int points = 0;
};

std::vector<LineSecond> LineSeconds(const std::vector<LinePointMatch>& matches,
                                    const std::vector<double>& point_time) {
  std::map<std::pair<int, int64_t>, std::vector<int>> groups;
  for (size_t i = 0; i < matches.size(); ++i) {
    const double t = point_time.at(matches[i].point);
    groups[{matches[i].db_line, static_cast<int64_t>(std::floor(t))}].push_back(
        static_cast<int>(i));
  }
  std::vector<LineSecond> seconds;
  std::vector<double> distances;
  for (const auto& [key, members] : groups) {
    distances.clear();
    for (int i : members) distances.push_back(matches[i].distance_m);
    LineSecond s;
    s.db_line = key.first;
    s.second = key.second;
    s.distance_m = Median(distances);
    s.across = matches[members.front()].across_enu.head<2>();
    s.points = static_cast<int>(members.size());
    seconds.push_back(s);
  }
  return seconds;
}

}  // namespace

std::vector<RejectedLine> RejectInconsistentLines(
    const std::vector<LinePointMatch>& matches,
    const std::vector<double>& point_time,
    const LineConsistencyOptions& options, std::vector<LinePointMatch>* kept) {
  // Per line and second first, so that each other line counts once in a
  // reference however many points it has (a long solid line would
  // otherwise outvote every dash of the centre line).
  std::vector<LineSecond> seconds = LineSeconds(matches, point_time);
  std::stable_sort(seconds.begin(), seconds.end(),
                   [](const LineSecond& a, const LineSecond& b) {
                     return a.second < b.second;
                   });
  const int64_t window = static_cast<int64_t>(std::ceil(options.window_s));
  std::map<int, std::vector<double>> offsets_of_line;
  std::map<int, int> points_of_line;
  std::map<int, std::vector<double>> other_lines;
  std::vector<double> references;
  for (const LineSecond& s : seconds) {
    other_lines.clear();
    const auto first = std::lower_bound(
        seconds.begin(), seconds.end(), s.second - window,
        [](const LineSecond& a, int64_t t) { return a.second < t; });
    for (auto o = first; o != seconds.end() && o->second <= s.second + window;
         ++o) {
      if (o->db_line == s.db_line) continue;
      const double cos = o->across.dot(s.across);
      if (std::abs(cos) < options.min_parallel_cos) continue;
      // The other line's displacement, along this line's normal.
      other_lines[o->db_line].push_back(o->distance_m * cos);
    }
    if (other_lines.empty()) continue;
    references.clear();
    for (const auto& [line, values] : other_lines) {
      references.push_back(Median(values));
    }
    offsets_of_line[s.db_line].push_back(s.distance_m - Median(references));
    points_of_line[s.db_line] += s.points;
  }
  std::vector<RejectedLine> rejected;
  for (const auto& [line, offsets] : offsets_of_line) {
    if (points_of_line[line] < options.min_points) continue;
    const double offset = Median(offsets);
    if (std::abs(offset) > options.max_offset_m) {
      rejected.push_back({line, points_of_line[line], offset});
    }
  }
  std::sort(rejected.begin(), rejected.end(),
            [](const RejectedLine& a, const RejectedLine& b) {
              return std::abs(a.offset_m) > std::abs(b.offset_m);
            });
  kept->clear();
  for (const LinePointMatch& m : matches) {
    const bool bad = std::any_of(
        rejected.begin(), rejected.end(),
        [&](const RejectedLine& r) { return r.db_line == m.db_line; });
    if (!bad) kept->push_back(m);
  }
  return rejected;
}

}  // namespace zebrageo
