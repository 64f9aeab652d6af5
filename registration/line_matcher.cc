#include "registration/line_matcher.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "registration/line_geometry_internal.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {

using line_geometry_internal::Compatible;
using line_geometry_internal::Nearest;
using line_geometry_internal::SegmentDistance2d;
using line_geometry_internal::SegmentGrid;

std::string LineMatchOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, gate_m, 0.0);
  OPTION_GT(check, max_height_m, 0.0);
  OPTION_GE(check, min_separation_ratio, 1.0);
  OPTION_IN(check, max_angle_rad, "(", 0.0, kPi / 2.0, ")");
  OPTION_IN(check, min_matched_share, "(", 0.0, 1.0, "]");
  return check.problem();
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
  OptionCheck check;
  OPTION_GT(check, window_s, 0.0);
  OPTION_GT(check, max_offset_m, 0.0);
  OPTION_GE(check, min_points, 1);
  OPTION_IN(check, min_parallel_cos, "(", 0.0, 1.0, ")");
  return check.problem();
}

namespace {

// The matches of one database line within one second: their median
// distance across the line, the line's normal there, where the database
// line is (the mean of the matched points), and how many.
struct LineSecond {
  int db_line = 0;
  int64_t second = 0;
  double distance_m = 0.0;
  Eigen::Vector2d across = Eigen::Vector2d::Zero();
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
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
    LineSecond s;
    for (int i : members) {
      distances.push_back(matches[i].distance_m);
      s.position += matches[i].db_point_enu.head<2>();
    }
    s.db_line = key.first;
    s.second = key.second;
    s.distance_m = Median(distances);
    s.across = matches[members.front()].across_enu.head<2>();
    s.position /= static_cast<double>(members.size());
    s.points = static_cast<int>(members.size());
    seconds.push_back(s);
  }
  std::stable_sort(seconds.begin(), seconds.end(),
                   [](const LineSecond& a, const LineSecond& b) {
                     return a.second < b.second;
                   });
  return seconds;
}

// Database lines closer than this across each other are one painted line
// (the dashes of a lane divider, a solid line drawn in pieces): they share
// a repaint, so one cannot vouch for another, and they are tested and
// rejected together; the lines within one metre across vote once, or a
// dashed line of many pieces would outvote the solid lines beside it.
constexpr double kSameLineM = 0.5;
constexpr double kVoteBinM = 1.0;
// Offsets this close to the worst are tied with it.
constexpr double kTiedOffsetM = 0.02;

// The median, the mean of the middle two of an even count: two other lines
// that disagree put the reference half way, blaming neither.
double MiddleOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t half = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + half, values.end());
  if (values.size() % 2 == 1) return values[half];
  const double upper = values[half];
  return 0.5 *
         (upper + *std::max_element(values.begin(), values.begin() + half));
}

// The painted line of each database line in `seconds` (the smallest
// database line index of its group): lines parallel and within kSameLineM
// across each other, seen within window_s.
std::map<int, int> PaintedLines(const std::vector<LineSecond>& seconds,
                                const LineConsistencyOptions& options) {
  std::map<int, int> parent;
  for (const LineSecond& s : seconds) parent[s.db_line] = s.db_line;
  const std::function<int(int)> root = [&](int l) {
    while (parent[l] != l) l = parent[l] = parent[parent[l]];
    return l;
  };
  const int64_t window = static_cast<int64_t>(std::ceil(options.window_s));
  for (size_t i = 0; i < seconds.size(); ++i) {
    for (size_t j = i + 1;
         j < seconds.size() && seconds[j].second <= seconds[i].second + window;
         ++j) {
      const LineSecond& a = seconds[i];
      const LineSecond& b = seconds[j];
      const double cos = a.across.dot(b.across);
      if (std::abs(cos) < options.min_parallel_cos) continue;
      // Across both normals (one short dash's direction is a degree or two
      // off): the same however the two are ordered.
      const Eigen::Vector2d normal =
          (a.across + (cos < 0.0 ? -b.across : b.across)).normalized();
      if (std::abs(normal.dot(b.position - a.position)) >= kSameLineM) {
        continue;
      }
      const int ra = root(a.db_line);
      const int rb = root(b.db_line);
      parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  std::map<int, int> painted;
  for (const auto& [line, unused] : parent) painted[line] = root(line);
  return painted;
}

// Per database line not in `excluded`: the median of its offsets from the
// other painted lines' displacements in the same window, and its points;
// a line of fewer than min_points points (a dash) takes its painted line's
// pooled offsets (its dashes are tested together).
std::map<int, std::pair<double, int>> LineOffsets(
    const std::vector<LineSecond>& seconds, const std::map<int, int>& painted,
    const std::set<int>& excluded, const LineConsistencyOptions& options) {
  const int64_t window = static_cast<int64_t>(std::ceil(options.window_s));
  std::map<int, std::vector<double>> offsets_of_line, offsets_of_painted;
  std::map<int, int> points_of_line, points_of_painted;
  std::map<int64_t, std::vector<double>> other_lines;
  std::vector<double> references;
  for (const LineSecond& s : seconds) {
    if (excluded.count(s.db_line)) continue;
    const int group = painted.at(s.db_line);
    other_lines.clear();
    const auto first = std::lower_bound(
        seconds.begin(), seconds.end(), s.second - window,
        [](const LineSecond& a, int64_t t) { return a.second < t; });
    for (auto o = first; o != seconds.end() && o->second <= s.second + window;
         ++o) {
      if (painted.at(o->db_line) == group || excluded.count(o->db_line)) {
        continue;
      }
      const double cos = o->across.dot(s.across);
      if (std::abs(cos) < options.min_parallel_cos) continue;
      const double lateral = s.across.dot(o->position - s.position);
      if (std::abs(lateral) < kSameLineM) continue;
      // The other line's displacement, along this line's normal.
      other_lines[std::llround(lateral / kVoteBinM)].push_back(o->distance_m *
                                                               cos);
    }
    if (other_lines.empty()) continue;
    references.clear();
    for (const auto& [bin, values] : other_lines) {
      references.push_back(Median(values));
    }
    const double offset = s.distance_m - MiddleOf(references);
    offsets_of_line[s.db_line].push_back(offset);
    points_of_line[s.db_line] += s.points;
    offsets_of_painted[group].push_back(offset);
    points_of_painted[group] += s.points;
  }
  std::map<int, std::pair<double, int>> out;
  for (const auto& [line, offsets] : offsets_of_line) {
    const int group = painted.at(line);
    out[line] = points_of_line[line] >= options.min_points
                    ? std::make_pair(Median(offsets), points_of_line[line])
                    : std::make_pair(Median(offsets_of_painted[group]),
                                     points_of_painted[group]);
  }
  return out;
}

}  // namespace

std::vector<RejectedLine> RejectInconsistentLines(
    const std::vector<LinePointMatch>& matches,
    const std::vector<double>& point_time,
    const LineConsistencyOptions& options, std::vector<LinePointMatch>* kept,
    std::set<int>* checked) {
  // Per line and second first, so that each other line counts once in a
  // reference however many points it has (a long solid line would
  // otherwise outvote every dash of the centre line).
  const std::vector<LineSecond> seconds = LineSeconds(matches, point_time);
  const std::map<int, int> painted = PaintedLines(seconds, options);
  // The worst line first, then the test again without it: one repainted
  // line must not make the lines beside it look offset.
  std::vector<RejectedLine> rejected;
  std::set<int> excluded;
  std::set<int> checked_lines;
  for (;;) {
    const std::map<int, std::pair<double, int>> offsets =
        LineOffsets(seconds, painted, excluded, options);
    double worst = 0.0;
    checked_lines.clear();
    for (const auto& [line, offset] : offsets) {
      VLOG(2) << "database line " << line << " (painted line "
              << painted.at(line) << "): offset " << offset.first << " m over "
              << offset.second << " points";
      if (offset.second < options.min_points) continue;
      checked_lines.insert(line);
      if (std::abs(offset.first) > options.max_offset_m) {
        worst = std::max(worst, std::abs(offset.first));
      }
    }
    if (worst == 0.0) break;
    // Lines as far off as the worst (two lines that disagree, each the
    // other's reference; the dashes of one line) go together: which one is
    // wrong is not known, and the order of the database must not decide.
    for (const auto& [line, offset] : offsets) {
      if (checked_lines.count(line) &&
          std::abs(offset.first) > options.max_offset_m &&
          std::abs(offset.first) >= worst - kTiedOffsetM) {
        int points = 0;
        for (const LineSecond& s : seconds) {
          if (s.db_line == line) points += s.points;
        }
        rejected.push_back({line, points, offset.first});
        excluded.insert(line);
      }
    }
  }
  std::stable_sort(rejected.begin(), rejected.end(),
                   [](const RejectedLine& a, const RejectedLine& b) {
                     return std::abs(a.offset_m) > std::abs(b.offset_m);
                   });
  if (checked != nullptr) *checked = checked_lines;
  kept->clear();
  for (const LinePointMatch& m : matches) {
    if (!excluded.count(m.db_line)) kept->push_back(m);
  }
  return rejected;
}

}  // namespace zebrageo
