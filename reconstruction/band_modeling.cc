#include "reconstruction/band_modeling.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include "reconstruction/crossing_regularity.h"
#include "reconstruction/road_plane.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

using Area = std::array<Eigen::Vector2d, 4>;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

bool InsideConvex(const Area& area, const Eigen::Vector2d& p) {
  int sign = 0;
  for (int k = 0; k < 4; ++k) {
    const double c = Cross(area[(k + 1) % 4] - area[k], p - area[k]);
    const int s = c > 0.0 ? 1 : (c < 0.0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

// Pixels inside the area.
std::vector<Eigen::Vector2i> PixelsInArea(const EdgeMap& edges,
                                          const Area& area) {
  double y_min = 1e30, y_max = -1e30, x_min = 1e30, x_max = -1e30;
  for (const Eigen::Vector2d& c : area) {
    y_min = std::min(y_min, c.y());
    y_max = std::max(y_max, c.y());
    x_min = std::min(x_min, c.x());
    x_max = std::max(x_max, c.x());
  }
  std::vector<Eigen::Vector2i> inside;
  const int y0 = std::max(0, static_cast<int>(std::ceil(y_min)));
  const int y1 = std::min(edges.height - 1, static_cast<int>(y_max));
  const int x0 = std::max(0, static_cast<int>(std::ceil(x_min)));
  const int x1 = std::min(edges.width - 1, static_cast<int>(x_max));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      if (InsideConvex(area, Eigen::Vector2d(x, y)) &&
          (edges.usable.empty() || edges.usable.at<uint8_t>(y, x))) {
        inside.emplace_back(x, y);
      }
    }
  }
  return inside;
}

// Sum of the image gradient along the line, inside the area (1 px steps).
Eigen::Vector2d Gamma(const EdgeMap& edges, const Area& area,
                      const ImageLine& line) {
  const Eigen::Vector2d direction(-line.normal.y(), line.normal.x());
  const Eigen::Vector2d origin = line.rho * line.normal;
  double reach = 0.0;
  for (const Eigen::Vector2d& c : area) {
    reach = std::max(reach, std::abs((c - origin).dot(direction)));
  }
  Eigen::Vector2d gamma = Eigen::Vector2d::Zero();
  for (double t = -reach; t <= reach; t += 1.0) {
    const Eigen::Vector2d p = origin + t * direction;
    if (!InsideConvex(area, p) || !edges.IsUsable(p.x(), p.y())) continue;
    const cv::Vec2f g = edges.GradientAt(p.x(), p.y());
    gamma += Eigen::Vector2d(g[0], g[1]);
  }
  return gamma;
}

// Image line through two points.
ImageLine LineThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  ImageLine line;
  const Eigen::Vector2d d = (b - a).normalized();
  line.normal = Eigen::Vector2d(-d.y(), d.x());
  line.rho = line.normal.dot(a);
  return line;
}

bool Intersect(const ImageLine& a, const ImageLine& b, Eigen::Vector2d* x) {
  Eigen::Matrix2d A;
  A << a.normal.x(), a.normal.y(), b.normal.x(), b.normal.y();
  const double det = A.determinant();
  if (std::abs(det) < 1e-9) return false;
  *x = A.inverse() * Eigen::Vector2d(a.rho, b.rho);
  return true;
}

// A 2D line of the plane frame: point + t * direction.
struct PlaneLine {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
};

// TLS line through 2D points; when they are fewer than 2 or spread less
// than 0.3 m, the line through their mean along `fallback`.
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

// Robust line through the band extremities of a crossing: the line through
// two of them (at least 0.3 m apart, within 40 degrees of `fallback`, the
// perpendicular to the bands) with the most points within 0.1 m, refitted
// on those. A band cut short by an occlusion or a wrongly paired side is an
// outlier. One point, or none qualifying: the line through the median
// point along `fallback`.
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

// Point of `line` at lateral coordinate `lateral` (x . normal), shifted by
// `shift` along the band direction.
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

// Lifts a plane-frame point vertically (along the frame normal) onto the
// band plane.
Eigen::Vector3d OnBandPlane(const PlaneFrame& frame, const RoadPlane& plane,
                            const Eigen::Vector2d& q) {
  const Eigen::Vector3d p = frame.To3d(q);
  const double denominator = plane.normal_body.dot(frame.normal);
  return p - plane.SignedDistance(p) / denominator * frame.normal;
}

// Unit normal, in rectified image `side`, of the line of the band plane
// through the centre of `area_3d` along `direction_2d` (plane frame),
// oriented like `like`.
Eigen::Vector2d ImageNormalOf(const RoadRectification& rectification, int side,
                              const PlaneFrame& frame, const RoadPlane& plane,
                              const std::array<Eigen::Vector3d, 4>& area_3d,
                              const Eigen::Vector2d& direction_2d,
                              const Eigen::Vector2d& like) {
  const Eigen::Vector3d centre =
      0.25 * (area_3d[0] + area_3d[1] + area_3d[2] + area_3d[3]);
  const Eigen::Vector3d ahead =
      OnBandPlane(frame, plane, frame.To2d(centre) + 0.5 * direction_2d);
  Eigen::Vector2d a, b;
  if (!rectification.ProjectToRectified(side, centre, &a) ||
      !rectification.ProjectToRectified(side, ahead, &b)) {
    return like;
  }
  const Eigen::Vector2d d = (b - a).normalized();
  Eigen::Vector2d normal(-d.y(), d.x());
  if (normal.dot(like) < 0.0) normal = -normal;
  return normal;
}

// Least-squares plane of a band and the variance of its height at a point:
// z = a x + b y + c in the band's own frame (x along, y across, z normal).
struct BandPlaneFit {
  RoadPlane plane;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis, y_axis;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of (a, b, c)
  double rms_m = 0.0;
  int count = 0;

  double HeightVariance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - centroid;
    const Eigen::Vector3d j(d.dot(x_axis), d.dot(y_axis), 1.0);
    return j.dot(covariance * j);
  }
};

bool FitBandPlane(const std::vector<Eigen::Vector3d>& points,
                  const Eigen::Vector3d& along, const Eigen::Vector3d& normal,
                  double min_sigma_m, BandPlaneFit* fit) {
  if (!FitPlaneLeastSquares(points, normal, &fit->plane)) return false;
  const Eigen::Vector3d n = fit->plane.normal_body;
  fit->x_axis = (along - along.dot(n) * n).normalized();
  fit->y_axis = n.cross(fit->x_axis);
  fit->centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) fit->centroid += p;
  fit->centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
  double sum_squares = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - fit->centroid;
    const Eigen::Vector3d j(d.dot(fit->x_axis), d.dot(fit->y_axis), 1.0);
    normal_matrix += j * j.transpose();
    sum_squares += fit->plane.SignedDistance(p) * fit->plane.SignedDistance(p);
  }
  fit->count = static_cast<int>(points.size());
  fit->rms_m = std::sqrt(sum_squares / std::max(1, fit->count - 3));
  const double sigma = std::max(fit->rms_m, min_sigma_m);
  fit->covariance = sigma * sigma * normal_matrix.inverse();
  return true;
}

// FitBandPlane, then again without the points more than 3 rms (at least
// 1 cm) off the plane (mismatched edge points).
bool FitRobustBandPlane(std::vector<Eigen::Vector3d> points,
                        const Eigen::Vector3d& along,
                        const Eigen::Vector3d& normal, double min_sigma_m,
                        BandPlaneFit* fit) {
  if (!FitBandPlane(points, along, normal, min_sigma_m, fit)) return false;
  const double limit = std::max(0.01, 3.0 * fit->rms_m);
  const size_t before = points.size();
  points.erase(std::remove_if(points.begin(), points.end(),
                              [&](const Eigen::Vector3d& p) {
                                return std::abs(fit->plane.SignedDistance(p)) >
                                       limit;
                              }),
               points.end());
  if (points.size() == before) return true;
  return FitBandPlane(points, along, normal, min_sigma_m, fit);
}

struct BandCandidate {
  int lo = -1;  // side with the smaller lateral coordinate
  int hi = -1;
  double cost = 0.0;
  // Extent of the band (the overlap of its sides) along the direction of
  // its set: a side may run on along a lane line, the overlap does not.
  double begin = 0.0;
  double end = 0.0;
  // Completed band (see CompleteCrossings): which of lo (0) and hi (1) is
  // inferred from the crossing rather than seen, -1 for none; the standard
  // deviation of that inferred side across the band.
  int inferred = -1;
  double inferred_sigma_m = 0.0;
  // A lone long side runs between its two sides.
  bool edge_between = false;
};

// The transversal side of a band end taken from its crossing (hidden end).
struct KnownEnd {
  const PlaneLine* line = nullptr;
  double sigma_m = 0.0;
  // For the seen end of such a band: the crossing's line there, to choose
  // among the candidates (what hides the other end may have edges too).
  const PlaneLine* expected = nullptr;
  // The crossing's direction of the transversal sides (plane frame): a seen
  // end is fitted with it (only its offset), once its own direction is
  // found within max_end_angle_rad of it.
  const Eigen::Vector2d* direction = nullptr;
};

// kNoTransversal: no transversal side at an end; kDisagreement: the two
// images disagree (a vehicle hides an end in one of them).
enum class BandOutcome { kBand, kRejected, kNoTransversal, kDisagreement };

double MedianOf(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// Union-find root.
int Root(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

// Extent of a side along a 2D direction of the plane frame.
void Extent(const PlaneFrame& frame, const LongSide& side,
            const Eigen::Vector2d& along, double* low, double* high) {
  const double a = frame.To2d(side.Begin()).dot(along);
  const double b = frame.To2d(side.End()).dot(along);
  *low = std::min(a, b);
  *high = std::max(a, b);
}

// `side` fitted again on its points within `margin_m` of the band's extent
// [begin_m, end_m] along its set's direction, when it runs on beyond that
// by more than margin_m and at least half of its points are within.
LongSide SideAlongBand(const std::vector<EdgePoint3d>& points,
                       const PlaneFrame& frame, const LongSide& side,
                       double begin_m, double end_m, double margin_m) {
  double low, high;
  Extent(frame, side, side.direction_2d, &low, &high);
  if (low >= begin_m - margin_m && high <= end_m + margin_m) return side;
  std::vector<int> within;
  for (int p : side.support) {
    const double t = frame.To2d(points[p].p_chain_body).dot(side.direction_2d);
    if (t >= begin_m - margin_m && t <= end_m + margin_m) within.push_back(p);
  }
  if (2 * within.size() < side.support.size() || within.size() < 10) {
    return side;
  }
  return FitLongSide(points, std::move(within), frame, side.direction_2d,
                     side.direction_set);
}

// Least-squares line y = a + b x through the points (p[0], p[index]):
// {a, b}; b = 0 when the x spread is below 1 cm.
std::array<double, 2> LinearFit(const std::vector<std::array<double, 3>>& p,
                                int index) {
  double mean_x = 0.0, mean_y = 0.0;
  for (const auto& q : p) {
    mean_x += q[0];
    mean_y += q[index];
  }
  mean_x /= static_cast<double>(p.size());
  mean_y /= static_cast<double>(p.size());
  double sxx = 0.0, sxy = 0.0;
  for (const auto& q : p) {
    sxx += (q[0] - mean_x) * (q[0] - mean_x);
    sxy += (q[0] - mean_x) * (q[index] - mean_y);
  }
  const double b = sxx > 1e-4 * static_cast<double>(p.size()) ? sxy / sxx : 0.0;
  return {mean_y - b * mean_x, b};
}

// Completes the crossings: a long side that no band took, lying where the
// crossing's regular pattern expects a band side (one band width from the
// slot of a missing band, with the polarity of that side), becomes a band
// whose other side is inferred: the same direction, one median band width
// of the crossing away. This recovers bands whose other side is hidden by
// a parked vehicle or merged with a lane line painted across the band's
// end. The transversal sides are still searched in both images, and the
// band still has to pass every check after that; its inferred side gets
// the spread of the crossing's widths as standard deviation.
void CompleteCrossings(const PlaneFrame& frame, const ZebraSpecification& zebra,
                       const BandOptions& options, int crossings,
                       const std::vector<char>& side_used,
                       std::vector<LongSide>* sides,
                       std::vector<BandCandidate>* pairs,
                       std::vector<int>* crossing_of) {
  const int n = static_cast<int>(side_used.size());
  const int m = static_cast<int>(pairs->size());
  for (int c = 0; c < crossings; ++c) {
    std::vector<double> centres, widths, contrasts, lengths;
    std::vector<std::array<double, 3>> extents;  // (centre, begin, end)
    int set = -1;
    Eigen::Vector3d direction_body = Eigen::Vector3d::Zero();
    Eigen::Vector2d along = Eigen::Vector2d::UnitX();
    for (int i = 0; i < m; ++i) {
      if ((*crossing_of)[i] != c) continue;
      const LongSide& lo = (*sides)[(*pairs)[i].lo];
      const LongSide& hi = (*sides)[(*pairs)[i].hi];
      centres.push_back(0.5 * (lo.lateral_m + hi.lateral_m));
      extents.push_back({centres.back(), (*pairs)[i].begin, (*pairs)[i].end});
      widths.push_back(hi.lateral_m - lo.lateral_m);
      contrasts.push_back(std::abs(lo.contrast));
      contrasts.push_back(std::abs(hi.contrast));
      lengths.push_back(lo.Length());
      lengths.push_back(hi.Length());
      set = lo.direction_set;
      direction_body = lo.direction_body;
      along = lo.direction_2d;
    }
    // A regular pattern needs a few bands to be trusted.
    if (static_cast<int>(centres.size()) < options.completion_min_bands) {
      continue;
    }
    std::sort(centres.begin(), centres.end());
    const double width = MedianOf(widths);
    double width_spread = 0.0;
    for (double w : widths) width_spread += (w - width) * (w - width);
    const double width_sigma =
        std::max(options.completion_min_sigma_m,
                 std::sqrt(width_spread / static_cast<double>(widths.size())));
    // Band period: the median spacing of neighbouring bands, ignoring
    // spacings across a missing band.
    std::vector<double> spacings;
    for (size_t k = 1; k < centres.size(); ++k) {
      spacings.push_back(centres[k] - centres[k - 1]);
    }
    const double smallest = *std::min_element(spacings.begin(), spacings.end());
    std::vector<double> regular;
    for (double d : spacings) {
      if (d < 1.5 * smallest) regular.push_back(d);
    }
    const double period = MedianOf(regular);
    if (!(period > width + 0.2) ||
        std::abs(width - zebra.band_width_m) > zebra.band_width_tolerance_m) {
      continue;
    }
    bool irregular = false;
    for (double d : regular) {
      irregular =
          irregular || std::abs(d - period) > options.completion_tolerance_m;
    }
    if (irregular) continue;
    // A skewed crossing's bands are offset along the band: its ends are
    // lines across the bands, begin and end linear in the lateral position.
    const std::array<double, 2> begin_line = LinearFit(extents, 1);
    const std::array<double, 2> end_line = LinearFit(extents, 2);
    const double min_contrast = 0.5 * MedianOf(contrasts);
    // Best side for each empty slot (index from the first band).
    std::map<int, std::pair<double, int>> best;  // slot -> (residual, side)
    for (int k = 0; k < n; ++k) {
      const LongSide& s = (*sides)[k];
      if (side_used[k] || s.direction_set != set) continue;
      if (std::acos(
              std::min(1.0, std::abs(s.direction_body.dot(direction_body)))) >
          options.max_side_angle_rad) {
        continue;
      }
      if (std::abs(s.contrast) < min_contrast) continue;
      // Paint brightens towards +lateral at the low side of a band.
      const double centre =
          s.lateral_m + (s.contrast > 0.0 ? 0.5 : -0.5) * width;
      // Within the crossing along the band, and no longer than its bands'
      // sides (a lane line is; a side is longer than its band's overlap
      // with the other side).
      const double begin = begin_line[0] + begin_line[1] * centre;
      const double end = end_line[0] + end_line[1] * centre;
      double s0, s1;
      Extent(frame, s, along, &s0, &s1);
      if (s1 - s0 > MedianOf(lengths) + options.completion_tolerance_m * 5.0 ||
          std::min(s1, end) - std::max(s0, begin) <
              options.min_side_overlap_fraction * (s1 - s0)) {
        continue;
      }
      const double position = (centre - centres.front()) / period;
      const int slot = static_cast<int>(std::lround(position));
      const double residual = std::abs(position - slot) * period;
      if (residual > options.completion_tolerance_m) continue;
      // One slot beyond the outer bands at most; not an occupied slot.
      const int last = static_cast<int>(
          std::lround((centres.back() - centres.front()) / period));
      if (slot < -1 || slot > last + 1) continue;
      bool occupied = false;
      for (double x : centres) {
        occupied = occupied || std::abs(x - (centres.front() + slot * period)) <
                                   0.5 * period;
      }
      if (occupied) continue;
      auto it = best.find(slot);
      if (it == best.end() || residual < it->second.first) {
        best[slot] = {residual, k};
      }
    }
    for (const auto& [slot, entry] : best) {
      const int k = entry.second;
      const LongSide seen = (*sides)[k];
      LongSide other = seen;
      const double shift = seen.contrast > 0.0 ? width : -width;
      other.lateral_m = seen.lateral_m + shift;
      other.point_body =
          seen.point_body + shift * frame.Direction3d(seen.Normal2d());
      other.contrast = -seen.contrast;
      // The band plane is fitted on the seen side and the nearest band.
      int nearest = -1;
      double nearest_distance = 1e30;
      for (int i = 0; i < m; ++i) {
        if ((*crossing_of)[i] != c) continue;
        const double d =
            std::abs((*sides)[(*pairs)[i].lo].lateral_m - other.lateral_m);
        if (d < nearest_distance) {
          nearest_distance = d;
          nearest = i;
        }
      }
      other.support.clear();
      for (int s : {(*pairs)[nearest].lo, (*pairs)[nearest].hi}) {
        const std::vector<int>& support = (*sides)[s].support;
        other.support.insert(other.support.end(), support.begin(),
                             support.end());
      }
      const int index = static_cast<int>(sides->size());
      sides->push_back(other);
      BandCandidate candidate;
      const bool seen_is_lo = seen.contrast > 0.0;
      candidate.lo = seen_is_lo ? k : index;
      candidate.hi = seen_is_lo ? index : k;
      candidate.inferred = seen_is_lo ? 1 : 0;
      candidate.inferred_sigma_m = std::hypot(
          width_sigma,
          seen.lateral_rms_m / std::sqrt(static_cast<double>(
                                   std::max<size_t>(1, seen.support.size()))));
      double s0, s1;
      Extent(frame, seen, along, &s0, &s1);
      candidate.begin = s0;
      candidate.end = s1;
      VLOG(2) << "crossing " << c << ": side " << k << " at " << seen.lateral_m
              << " completes slot " << slot << " (width " << width
              << ", period " << period << ")";
      pairs->push_back(candidate);
      crossing_of->push_back(c);
    }
  }
}

}  // namespace

std::string BandOptions::Check() const {
  std::ostringstream error;
  if (!(max_side_angle_rad > 0.0 && max_side_angle_rad < 0.5)) {
    error << "max_side_angle_rad = " << max_side_angle_rad
          << ": must be in (0, 0.5)";
  } else if (!(min_side_overlap_fraction >= 0.0 &&
               min_side_overlap_fraction <= 1.0)) {
    error << "min_side_overlap_fraction = " << min_side_overlap_fraction
          << ": must be in [0, 1]";
  } else if (!(extremity_length_fraction > 0.0 &&
               extremity_length_fraction <= 1.0)) {
    error << "extremity_length_fraction = " << extremity_length_fraction
          << ": must be in (0, 1]";
  } else if (!(transversal_search_m > 0.0)) {
    error << "transversal_search_m = " << transversal_search_m
          << ": must be > 0";
  } else if (!(side_margin_m >= 0.0)) {
    error << "side_margin_m = " << side_margin_m << ": must be >= 0";
  } else if (!(transversal_max_angle_rad > 0.0 &&
               transversal_max_angle_rad < 1.5)) {
    error << "transversal_max_angle_rad = " << transversal_max_angle_rad
          << ": must be in (0, 1.5)";
  } else if (!(point_angle_tolerance_rad > 0.0)) {
    error << "point_angle_tolerance_rad = " << point_angle_tolerance_rad
          << ": must be > 0";
  } else if (!(hough_angle_step_rad > 0.0 && hough_angle_step_rad < 0.2)) {
    error << "hough_angle_step_rad = " << hough_angle_step_rad
          << ": must be in (0, 0.2)";
  } else if (!(hough_rho_step_px > 0.0)) {
    error << "hough_rho_step_px = " << hough_rho_step_px << ": must be > 0";
  } else if (!(hough_score_fraction > 0.0 && hough_score_fraction <= 1.0)) {
    error << "hough_score_fraction = " << hough_score_fraction
          << ": must be in (0, 1]";
  } else if (!(pair_score_fraction > 0.0 && pair_score_fraction <= 1.0)) {
    error << "pair_score_fraction = " << pair_score_fraction
          << ": must be in (0, 1]";
  } else if (!(hough_min_gradient > 0.0)) {
    error << "hough_min_gradient = " << hough_min_gradient << ": must be > 0";
  } else if (!(refine_distance_px > 0.0)) {
    error << "refine_distance_px = " << refine_distance_px << ": must be > 0";
  } else if (min_transversal_points < 2) {
    error << "min_transversal_points = " << min_transversal_points
          << ": must be >= 2";
  } else if (!(max_stereo_disagreement_m > 0.0)) {
    error << "max_stereo_disagreement_m = " << max_stereo_disagreement_m
          << ": must be > 0";
  } else if (!(max_crossing_gap_m > 0.0)) {
    error << "max_crossing_gap_m = " << max_crossing_gap_m << ": must be > 0";
  } else if (!(max_band_range_m > 0.0)) {
    error << "max_band_range_m = " << max_band_range_m << ": must be > 0";
  } else if (!(min_line_sigma_px > 0.0)) {
    error << "min_line_sigma_px = " << min_line_sigma_px << ": must be > 0";
  } else if (!(min_sigma_m > 0.0)) {
    error << "min_sigma_m = " << min_sigma_m << ": must be > 0";
  } else if (!(min_end_step_fraction >= 0.0 && min_end_step_fraction < 1.0)) {
    error << "min_end_step_fraction = " << min_end_step_fraction
          << ": must be in [0, 1)";
  } else if (!(end_step_profile_px >= 1.0)) {
    error << "end_step_profile_px = " << end_step_profile_px
          << ": must be >= 1";
  } else if (completion_min_bands < 3) {
    error << "completion_min_bands = " << completion_min_bands
          << ": must be >= 3";
  } else if (!(completion_tolerance_m > 0.0)) {
    error << "completion_tolerance_m = " << completion_tolerance_m
          << ": must be > 0";
  } else if (!(completion_min_sigma_m > 0.0)) {
    error << "completion_min_sigma_m = " << completion_min_sigma_m
          << ": must be > 0";
  } else if (!(inferred_score_factor > 0.0 && inferred_score_factor <= 1.0)) {
    error << "inferred_score_factor = " << inferred_score_factor
          << ": must be in (0, 1]";
  } else if (!(max_end_angle_rad > 0.0 && max_end_angle_rad < 1.5)) {
    error << "max_end_angle_rad = " << max_end_angle_rad
          << ": must be in (0, 1.5)";
  } else if (!(max_transversal_run_on > 0.0)) {
    error << "max_transversal_run_on = " << max_transversal_run_on
          << ": must be > 0";
  } else if (!(max_inferred_range_m > 0.0)) {
    error << "max_inferred_range_m = " << max_inferred_range_m
          << ": must be > 0";
  } else if (!(hidden_end_max_rms_m > 0.0)) {
    error << "hidden_end_max_rms_m = " << hidden_end_max_rms_m
          << ": must be > 0";
  } else if (!(hidden_end_max_offset_m > 0.0)) {
    error << "hidden_end_max_offset_m = " << hidden_end_max_offset_m
          << ": must be > 0";
  } else if (!(max_length_excess_m >= 0.0)) {
    error << "max_length_excess_m = " << max_length_excess_m
          << ": must be >= 0";
  } else if (min_end_direction_observations < 2) {
    error << "min_end_direction_observations = "
          << min_end_direction_observations << ": must be >= 2";
  }
  return error.str();
}

std::vector<ImageLine> HoughTransversalCandidates(
    const EdgeMap& edges, const Area& area,
    const Eigen::Vector2d& expected_normal, const BandOptions& options) {
  std::vector<ImageLine> lines;
  const std::vector<Eigen::Vector2i> inside = PixelsInArea(edges, area);
  const double theta0 = std::atan2(expected_normal.y(), expected_normal.x());
  const int half = static_cast<int>(std::ceil(
      options.transversal_max_angle_rad / options.hough_angle_step_rad));
  const int n_theta = 2 * half + 1;
  std::vector<double> cos_t(n_theta), sin_t(n_theta);
  double rho_min = 1e30, rho_max = -1e30;
  for (int k = 0; k < n_theta; ++k) {
    const double theta = theta0 + (k - half) * options.hough_angle_step_rad;
    cos_t[k] = std::cos(theta);
    sin_t[k] = std::sin(theta);
    for (const Eigen::Vector2d& c : area) {
      const double rho = c.x() * cos_t[k] + c.y() * sin_t[k];
      rho_min = std::min(rho_min, rho);
      rho_max = std::max(rho_max, rho);
    }
  }
  const double step = options.hough_rho_step_px;
  const int n_rho = static_cast<int>((rho_max - rho_min) / step) + 2;
  std::vector<float> votes(static_cast<size_t>(n_theta) * n_rho, 0.0f);
  // Every pixel with a gradient votes, weighted by its norm: transversal
  // sides far away are blurred along the road over several pixels, where
  // non-maximum suppression finds no reliable edge points.
  for (const Eigen::Vector2i& pixel : inside) {
    const float gx = edges.gx.at<float>(pixel.y(), pixel.x());
    const float gy = edges.gy.at<float>(pixel.y(), pixel.x());
    const float norm = std::hypot(gx, gy);
    if (norm < options.hough_min_gradient) continue;
    const double phi = std::atan2(gy, gx);
    for (int k = 0; k < n_theta; ++k) {
      const double theta = theta0 + (k - half) * options.hough_angle_step_rad;
      // Oriented: only the expected polarity votes (a shadow edge across
      // the band, darkening into it, must not outvote the paint's end).
      if (std::abs(std::remainder(phi - theta, 2.0 * kPi)) >
          options.point_angle_tolerance_rad) {
        continue;
      }
      const double rho = pixel.x() * cos_t[k] + pixel.y() * sin_t[k];
      const int r = static_cast<int>(std::lround((rho - rho_min) / step));
      if (r >= 0 && r < n_rho) {
        votes[static_cast<size_t>(k) * n_rho + r] += norm;
      }
    }
  }
  if (votes.empty()) return lines;
  const float best = *std::max_element(votes.begin(), votes.end());
  if (best < options.min_transversal_points * options.hough_min_gradient) {
    return lines;
  }
  for (int k = 0; k < n_theta; ++k) {
    for (int r = 0; r < n_rho; ++r) {
      const float v = votes[static_cast<size_t>(k) * n_rho + r];
      if (v < options.hough_score_fraction * best) continue;
      bool is_max = true;
      for (int dk = -1; dk <= 1 && is_max; ++dk) {
        for (int dr = -1; dr <= 1; ++dr) {
          if (dk == 0 && dr == 0) continue;
          const int kk = k + dk, rr = r + dr;
          if (kk < 0 || rr < 0 || kk >= n_theta || rr >= n_rho) continue;
          const float w = votes[static_cast<size_t>(kk) * n_rho + rr];
          // Plateaus: the first cell in scan order is the maximum.
          if (w > v || (w == v && (dk < 0 || (dk == 0 && dr < 0)))) {
            is_max = false;
            break;
          }
        }
      }
      if (!is_max) continue;
      ImageLine line;
      line.normal = Eigen::Vector2d(cos_t[k], sin_t[k]);
      line.rho = rho_min + r * step;
      line.votes = v;
      line.gamma = Gamma(edges, area, line);
      lines.push_back(line);
    }
  }
  std::stable_sort(
      lines.begin(), lines.end(),
      [](const ImageLine& a, const ImageLine& b) { return a.votes > b.votes; });
  if (lines.size() > 10) lines.resize(10);
  return lines;
}

bool ChooseTransversalPair(const std::vector<ImageLine>& begin,
                           const std::vector<ImageLine>& end,
                           const Eigen::Vector2d& band_direction,
                           const BandOptions& options, int* t, int* l) {
  double best_score = 0.0;
  for (const ImageLine& a : begin) {
    if (a.gamma.dot(band_direction) <= 0.0) continue;
    for (const ImageLine& b : end) {
      if (b.gamma.dot(band_direction) >= 0.0) continue;
      best_score = std::max(best_score, a.gamma.norm() + b.gamma.norm());
    }
  }
  if (!(best_score > 0.0)) return false;
  double best_dot = 1e300;
  *t = *l = -1;
  for (size_t i = 0; i < begin.size(); ++i) {
    if (begin[i].gamma.dot(band_direction) <= 0.0) continue;
    for (size_t j = 0; j < end.size(); ++j) {
      if (end[j].gamma.dot(band_direction) >= 0.0) continue;
      const double score = begin[i].gamma.norm() + end[j].gamma.norm();
      if (score < options.pair_score_fraction * best_score) continue;
      const double dot = begin[i].gamma.dot(end[j].gamma);
      if (dot < best_dot) {
        best_dot = dot;
        *t = static_cast<int>(i);
        *l = static_cast<int>(j);
      }
    }
  }
  return *t >= 0;
}

bool RefineImageLine(const EdgeMap& edges, const Area& area,
                     const BandOptions& options, ImageLine* line,
                     const Eigen::Vector2d* fixed_normal) {
  // Sub-pixel edge positions along the line: at every pixel step along it,
  // the centroid of the gradient profile across it (the gradient projected
  // on the line's polarity, over the contiguous part above a third of its
  // peak). For a blurred step the profile is symmetric about the edge, so
  // the centroid is unbiased whatever the blur; the points are then fitted
  // by weighted least squares, twice, dropping outliers.
  if (!(line->gamma.norm() > 0.0)) return false;
  const Eigen::Vector2d polarity = line->gamma.normalized();
  const double reach = options.refine_distance_px;
  const double step = 0.5;
  const int half = static_cast<int>(std::ceil(reach / step));
  ImageLine current = *line;
  std::vector<double> profile(2 * half + 1);
  std::vector<char> seen(2 * half + 1);
  for (int round = 0; round < 3; ++round) {
    const Eigen::Vector2d direction(-current.normal.y(), current.normal.x());
    const Eigen::Vector2d origin = current.rho * current.normal;
    double t_min = 1e30, t_max = -1e30;
    for (const Eigen::Vector2d& c : area) {
      t_min = std::min(t_min, (c - origin).dot(direction));
      t_max = std::max(t_max, (c - origin).dot(direction));
    }
    std::vector<Eigen::Vector2d> points;
    std::vector<double> weights;
    for (double t = std::ceil(t_min); t <= t_max; t += 1.0) {
      const Eigen::Vector2d base = origin + t * direction;
      if (!InsideConvex(area, base)) continue;
      // The profile may run out of the image (an end a little inside the
      // bottom edge): the edge position holds as long as the peak and its
      // part above a third are seen, bounded by seen samples below it.
      int peak = -1;
      for (int k = -half; k <= half; ++k) {
        const Eigen::Vector2d p = base + k * step * current.normal;
        seen[k + half] = edges.IsUsable(p.x(), p.y());
        profile[k + half] = 0.0;
        if (!seen[k + half]) continue;
        const cv::Vec2f g = edges.GradientAt(p.x(), p.y());
        profile[k + half] =
            std::max(0.0, polarity.x() * g[0] + polarity.y() * g[1]);
        if (peak < 0 || profile[k + half] > profile[peak]) peak = k + half;
      }
      if (peak < 0 || !seen[half]) continue;
      const double top = profile[peak];
      if (!(top >= options.hough_min_gradient)) continue;
      if (peak == 0 || peak == 2 * half) continue;  // edge outside the window
      int lo = peak, hi = peak;
      while (lo > 0 && seen[lo - 1] && profile[lo - 1] > top / 3.0) --lo;
      while (hi < 2 * half && seen[hi + 1] && profile[hi + 1] > top / 3.0) {
        ++hi;
      }
      if ((lo > 0 && !seen[lo - 1]) || (hi < 2 * half && !seen[hi + 1])) {
        continue;  // the edge's profile is cut by the image's border
      }
      double sum = 0.0, moment = 0.0;
      for (int k = lo; k <= hi; ++k) {
        const double w = profile[k] - top / 3.0;
        sum += w;
        moment += w * (k - half) * step;
      }
      points.push_back(base + (moment / sum) * current.normal);
      weights.push_back(top);
    }
    // Weighted least squares, then without points more than 3 rms (at
    // least 0.5 px) away.
    std::vector<char> keep(points.size(), 1);
    for (int pass = 0; pass < 2; ++pass) {
      double w_sum = 0.0;
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      int count = 0;
      for (size_t k = 0; k < points.size(); ++k) {
        if (!keep[k]) continue;
        w_sum += weights[k];
        mean += weights[k] * points[k];
        ++count;
      }
      if (count < options.min_transversal_points) return false;
      mean /= w_sum;
      Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
      for (size_t k = 0; k < points.size(); ++k) {
        if (!keep[k]) continue;
        const Eigen::Vector2d d = points[k] - mean;
        scatter += weights[k] * d * d.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
      Eigen::Vector2d normal =
          fixed_normal != nullptr
              ? *fixed_normal
              : Eigen::Vector2d(solver.eigenvectors().col(0));
      if (normal.dot(current.normal) < 0.0) normal = -normal;
      current.normal = normal;
      current.rho = normal.dot(mean);
      double sum_squares = 0.0;
      for (size_t k = 0; k < points.size(); ++k) {
        if (!keep[k]) continue;
        const double r = current.Distance(points[k]);
        sum_squares += r * r;
      }
      current.support = count;
      current.rms_px = std::sqrt(sum_squares / count);
      const double limit = std::max(0.5, 3.0 * current.rms_px);
      for (size_t k = 0; k < points.size(); ++k) {
        keep[k] = std::abs(current.Distance(points[k])) <= limit;
      }
    }
  }
  current.gamma = Gamma(edges, area, current);
  *line = current;
  return true;
}

double TransversalRunOn(const EdgeMap& edges, const ImageLine& line,
                        const Eigen::Vector2d ends[2], const bool check[2]) {
  if (!(line.gamma.norm() > 0.0)) return 0.0;
  const Eigen::Vector2d polarity = line.gamma.normalized();
  const Eigen::Vector2d span = ends[1] - ends[0];
  const double width = span.norm();
  if (!(width > 2.0)) return 0.0;
  const Eigen::Vector2d unit = span / width;
  auto mean_between = [&](const Eigen::Vector2d& from, double t0, double t1,
                          const Eigen::Vector2d& direction) {
    double sum = 0.0;
    int count = 0;
    for (double t = t0; t <= t1; t += 1.0) {
      const Eigen::Vector2d p = from + t * direction;
      if (!edges.IsUsable(p.x(), p.y())) continue;
      const cv::Vec2f g = edges.GradientAt(p.x(), p.y());
      sum += polarity.x() * g[0] + polarity.y() * g[1];
      ++count;
    }
    return count >= 3 ? sum / count : std::nan("");
  };
  const double inside = mean_between(ends[0], 0.2 * width, 0.8 * width, unit);
  if (!(inside > 0.0)) return 0.0;
  double run_on = 0.0;
  for (int k = 0; k < 2; ++k) {
    if (!check[k]) continue;
    const double outside = mean_between(ends[k], 0.1 * width, 0.5 * width,
                                        k == 0 ? Eigen::Vector2d(-unit) : unit);
    if (std::isfinite(outside)) run_on = std::max(run_on, outside / inside);
  }
  return run_on;
}

double EndAngleRad(const std::array<Eigen::Vector3d, 4>& vertices) {
  const Eigen::Vector3d begin = vertices[1] - vertices[0];
  const Eigen::Vector3d end = vertices[2] - vertices[3];
  return std::atan2(begin.cross(end).norm(), std::abs(begin.dot(end)));
}

double EdgeStep(const EdgeMap& edges, const ImageLine& line,
                const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                double half_width_px) {
  const Eigen::Vector2d span = b - a;
  const double length = span.norm();
  if (!(length > 2.0)) return std::nan("");
  const Eigen::Vector2d unit = span / length;
  std::vector<double> steps;
  for (double t = 0.2 * length; t <= 0.8 * length; t += 1.0) {
    // The point of the line nearest a + t * unit.
    const Eigen::Vector2d q = a + t * unit;
    const Eigen::Vector2d p = q - line.Distance(q) * line.normal;
    // Over +-half_width_px, or as much of it as the image holds on both
    // sides (an end near the image's border), at least +-3 px: a painted
    // edge's step is within a few pixels of it.
    double step = 0.0;
    int reach = 0;
    for (int u = 0; u <= static_cast<int>(half_width_px); ++u) {
      const Eigen::Vector2d x0 = p + u * line.normal;
      const Eigen::Vector2d x1 = p - u * line.normal;
      if (!edges.IsUsable(x0.x(), x0.y()) || !edges.IsUsable(x1.x(), x1.y())) {
        break;
      }
      const cv::Vec2f g0 = edges.GradientAt(x0.x(), x0.y());
      step += line.normal.x() * g0[0] + line.normal.y() * g0[1];
      if (u > 0) {
        const cv::Vec2f g1 = edges.GradientAt(x1.x(), x1.y());
        step += line.normal.x() * g1[0] + line.normal.y() * g1[1];
      }
      reach = u;
    }
    if (reach >= 3) steps.push_back(std::abs(step));
  }
  if (steps.size() < 3) return std::nan("");
  const size_t k = (3 * steps.size()) / 4;
  std::nth_element(steps.begin(), steps.begin() + k, steps.end());
  return steps[k];
}

std::vector<Band> ModelBands(const LongSideDetection& detection,
                             const PlaneFrame& frame,
                             const RoadRectification& rectification,
                             const EdgeMap edges[2],
                             const ZebraSpecification& zebra,
                             const BandOptions& options,
                             BandModelingDebug* debug) {
  // Inferred sides (CompleteCrossings) are appended after the detected ones.
  std::vector<LongSide> sides = detection.sides;
  const int n = static_cast<int>(sides.size());

  // 1. Pairs of long sides: parallel, one band width apart, overlapping,
  // with inverse gradients and the bright paint between them.
  std::vector<BandCandidate> candidates;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const LongSide& a = sides[i];
      const LongSide& b = sides[j];
      if (i == j || a.direction_set != b.direction_set) continue;
      if (!(a.lateral_m < b.lateral_m)) continue;
      if (std::acos(
              std::min(1.0, std::abs(a.direction_body.dot(b.direction_body)))) >
          options.max_side_angle_rad) {
        continue;
      }
      const double width = b.lateral_m - a.lateral_m;
      if (std::abs(width - zebra.band_width_m) > zebra.band_width_tolerance_m) {
        continue;
      }
      if (!(a.contrast > 0.0 && b.contrast < 0.0)) continue;
      double a0, a1, b0, b1;
      Extent(frame, a, a.direction_2d, &a0, &a1);
      Extent(frame, b, a.direction_2d, &b0, &b1);
      const double overlap = std::min(a1, b1) - std::max(a0, b0);
      if (overlap <
          options.min_side_overlap_fraction * std::min(a1 - a0, b1 - b0)) {
        continue;
      }
      // Longer than any band: the inner edge of a lane line and a kerb, or
      // a lane line's two edges and a gutter, running along the crossing.
      // Taken as one of its bands it would set the crossing's ends (the
      // extremities of its longest bands) far from the painted ones.
      if (overlap > zebra.max_band_length_m + options.max_length_excess_m) {
        continue;
      }
      // The paint is one band: no gap of asphalt between the two sides, i.e.
      // no side where the paint ends (darkening) followed by one where it
      // starts again (a side paired with the far edge of a lane line next
      // to the band is not a band). A lone edge between them is a shadow
      // boundary running along the band: it must not hide the band.
      double first_end = 1e30;
      double last_start = -1e30;
      for (int k = 0; k < n; ++k) {
        const LongSide& s = sides[k];
        if (k == i || k == j || s.direction_set != a.direction_set) continue;
        if (s.lateral_m <= a.lateral_m + 0.05 ||
            s.lateral_m >= b.lateral_m - 0.05) {
          continue;
        }
        double s0, s1;
        Extent(frame, s, a.direction_2d, &s0, &s1);
        if (std::min(s1, std::min(a1, b1)) - std::max(s0, std::max(a0, b0)) <=
            0.0) {
          continue;
        }
        if (s.contrast < 0.0) first_end = std::min(first_end, s.lateral_m);
        if (s.contrast > 0.0) last_start = std::max(last_start, s.lateral_m);
      }
      if (first_end < last_start) continue;
      BandCandidate c;
      c.edge_between = first_end < 1e30 || last_start > -1e30;
      c.lo = i;
      c.hi = j;
      c.begin = std::max(a0, b0);
      c.end = std::min(a1, b1);
      c.cost =
          std::abs(width - zebra.band_width_m) / zebra.band_width_tolerance_m -
          overlap / zebra.min_band_length_m;
      candidates.push_back(c);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const BandCandidate& x, const BandCandidate& y) {
                     return x.cost < y.cost;
                   });
  std::vector<char> side_used(n, 0);
  std::vector<BandCandidate> pairs;
  for (const BandCandidate& c : candidates) {
    if (side_used[c.lo] || side_used[c.hi]) continue;
    side_used[c.lo] = side_used[c.hi] = 1;
    pairs.push_back(c);
  }
  // A band with an edge along it (a shadow boundary, or a lane line and its
  // kerb lit between two shadows) is kept only beside other bands of a
  // crossing.
  {
    std::vector<BandCandidate> kept;
    for (const BandCandidate& c : pairs) {
      int neighbours = 0;
      const LongSide& a = sides[c.lo];
      const double centre = 0.5 * (a.lateral_m + sides[c.hi].lateral_m);
      for (const BandCandidate& o : pairs) {
        const LongSide& b = sides[o.lo];
        if (o.edge_between || b.direction_set != a.direction_set) continue;
        const double other = 0.5 * (b.lateral_m + sides[o.hi].lateral_m);
        if (&o != &c &&
            std::abs(other - centre) <=
                options.max_crossing_gap_m + 2.0 * zebra.band_width_m &&
            std::min(c.end, o.end) - std::max(c.begin, o.begin) > 0.0) {
          ++neighbours;
        }
      }
      if (!c.edge_between || neighbours >= 2) kept.push_back(c);
    }
    pairs.swap(kept);
  }
  if (debug != nullptr) {
    for (const BandCandidate& c : pairs) {
      for (int s : {c.lo, c.hi}) {
        Eigen::Vector2d a, b;
        if (rectification.ProjectToRectified(0, sides[s].Begin(), &a) &&
            rectification.ProjectToRectified(0, sides[s].End(), &b)) {
          debug->band_pairs.push_back({a, b});
        }
      }
    }
  }

  // 2. Crossings: bands of one direction, side by side.
  const int m = static_cast<int>(pairs.size());
  std::vector<int> parent(m);
  std::iota(parent.begin(), parent.end(), 0);
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      const LongSide& a_lo = sides[pairs[i].lo];
      const LongSide& b_lo = sides[pairs[j].lo];
      if (a_lo.direction_set != b_lo.direction_set) continue;
      const double a_hi = sides[pairs[i].hi].lateral_m;
      const double b_hi = sides[pairs[j].hi].lateral_m;
      const double gap = std::max(b_lo.lateral_m - a_hi, a_lo.lateral_m - b_hi);
      if (gap > options.max_crossing_gap_m) continue;
      // The bands themselves overlap along their direction, not only
      // their sides: a side may run on along a lane line, and a pair of
      // lines before the crossing would join it and set its ends.
      if (std::min(pairs[i].end, pairs[j].end) -
              std::max(pairs[i].begin, pairs[j].begin) <=
          0.0) {
        continue;
      }
      parent[Root(&parent, i)] = Root(&parent, j);
    }
  }
  std::vector<int> crossing_of(m);
  {
    std::vector<int> label(m, -1);
    int next_label = 0;
    for (int i = 0; i < m; ++i) {
      const int root = Root(&parent, i);
      if (label[root] < 0) label[root] = next_label++;
      crossing_of[i] = label[root];
    }
  }

  const int crossings =
      m == 0 ? 0
             : *std::max_element(crossing_of.begin(), crossing_of.end()) + 1;
  // 2b. Bands of which one long side is hidden (a parked vehicle) or merged
  // with other paint (a lane line across the band's end).
  if (options.complete_crossings) {
    CompleteCrossings(frame, zebra, options, crossings, side_used, &sides,
                      &pairs, &crossing_of);
  }
  const int m_all = static_cast<int>(pairs.size());

  // 3. Approximate transversal sides of each crossing: regression on the
  // extremities of its longer long sides (seen bands only).
  for (int i = 0; i < m_all && VLOG_IS_ON(2); ++i) {
    const LongSide& lo = sides[pairs[i].lo];
    const Eigen::Vector3d centre_body = frame.To3d(
        0.5 * (pairs[i].begin + pairs[i].end) * lo.direction_2d +
        0.5 * (lo.lateral_m + sides[pairs[i].hi].lateral_m) * lo.Normal2d());
    VLOG(2) << "band " << i << ": sides " << pairs[i].lo << " " << pairs[i].hi
            << " set " << lo.direction_set << " lateral " << lo.lateral_m << " "
            << sides[pairs[i].hi].lateral_m << " extent " << pairs[i].begin
            << " " << pairs[i].end << " crossing " << crossing_of[i]
            << " centre_body " << centre_body.transpose();
  }
  std::vector<PlaneLine> begin_lines(crossings), end_lines(crossings);
  for (int c = 0; c < crossings; ++c) {
    double longest = 0.0;
    Eigen::Vector2d along = Eigen::Vector2d::UnitX();
    for (int i = 0; i < m; ++i) {
      if (crossing_of[i] != c) continue;
      longest = std::max(longest, pairs[i].end - pairs[i].begin);
      along = sides[pairs[i].lo].direction_2d;
    }
    const Eigen::Vector2d across(-along.y(), along.x());
    std::vector<Eigen::Vector2d> begins, ends;
    for (int i = 0; i < m; ++i) {
      if (crossing_of[i] != c) continue;
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

  // 4. Each band: plane, transversal sides, vertices. `known[e]`: the
  // transversal side of end e is not searched but taken from that line of
  // the plane frame (a hidden end, see below).
  // Directions of the band ends seen in the first pass (step 4b).
  std::vector<EndDirectionObservation>* end_directions = nullptr;
  auto model_band = [&](int i, const KnownEnd known[2],
                        Band* out) -> BandOutcome {
    // A seen side that runs on beyond the band (into a lane line, a
    // vehicle's shadow edge, within the grouping's 3 cm) is fitted again
    // on its points along the band: what it runs on to tilts its line.
    LongSide lo = sides[pairs[i].lo];
    LongSide hi = sides[pairs[i].hi];
    if (pairs[i].inferred < 0) {
      lo = SideAlongBand(detection.points, frame, lo, pairs[i].begin,
                         pairs[i].end, options.transversal_search_m);
      hi = SideAlongBand(detection.points, frame, hi, pairs[i].begin,
                         pairs[i].end, options.transversal_search_m);
    }
    const Eigen::Vector2d along = lo.direction_2d;
    const Eigen::Vector2d across = lo.Normal2d();
    // The band plane from its sides' points along the band only: a side
    // may run on beyond it (along a lane line, a vehicle's shadow), and
    // what it runs on to may not lie on the road (a 3 cm height rms tilted
    // a band's plane by 2 degrees and moved its ends 20 cm out, sim08).
    std::vector<Eigen::Vector3d> support;
    for (const LongSide* side : {&lo, &hi}) {
      for (int p : side->support) {
        const double t =
            frame.To2d(detection.points[p].p_chain_body).dot(along);
        if (t < pairs[i].begin - options.transversal_search_m ||
            t > pairs[i].end + options.transversal_search_m) {
          continue;
        }
        support.push_back(detection.points[p].p_body);
      }
    }
    BandPlaneFit plane_fit;
    if (!FitRobustBandPlane(support, lo.direction_body, frame.normal,
                            options.min_sigma_m, &plane_fit)) {
      return BandOutcome::kRejected;
    }
    const RoadPlane& plane = plane_fit.plane;
    VLOG(2) << "band " << i << ": plane normal "
            << plane.normal_body.transpose() << " rms " << plane_fit.rms_m
            << " n " << plane_fit.count << " side height rms "
            << lo.height_rms_m << " " << hi.height_rms_m << " lateral rms "
            << lo.lateral_rms_m << " " << hi.lateral_rms_m;
    double lateral_lo = lo.lateral_m + options.side_margin_m;
    double lateral_hi = hi.lateral_m - options.side_margin_m;
    // A completed band's transversal sides are searched on its seen half:
    // what hides the other side (a vehicle) must not vote.
    const double seen_share = 0.55 * (hi.lateral_m - lo.lateral_m);
    if (pairs[i].inferred == 1) lateral_hi = lo.lateral_m + seen_share;
    if (pairs[i].inferred == 0) lateral_lo = hi.lateral_m - seen_share;
    const int crossing = crossing_of[i];
    // Search areas (3D corners on the band plane), begin then end.
    std::array<std::array<Eigen::Vector3d, 4>, 2> areas_3d;
    for (int e = 0; e < 2; ++e) {
      const PlaneLine& line =
          e == 0 ? begin_lines[crossing] : end_lines[crossing];
      const double s = options.transversal_search_m;
      const Eigen::Vector2d corners[4] = {
          AtLateral(line, along, across, lateral_lo, -s),
          AtLateral(line, along, across, lateral_hi, -s),
          AtLateral(line, along, across, lateral_hi, s),
          AtLateral(line, along, across, lateral_lo, s)};
      for (int k = 0; k < 4; ++k) {
        areas_3d[e][k] = OnBandPlane(frame, plane, corners[k]);
      }
    }
    // The band direction and the expected transversal normal in the image.
    const Eigen::Vector3d band_centre =
        0.5 * (OnBandPlane(frame, plane, frame.To2d(lo.point_body)) +
               OnBandPlane(frame, plane, frame.To2d(hi.point_body)));
    std::array<Eigen::Vector3d, 4> vertex_sum;
    vertex_sum.fill(Eigen::Vector3d::Zero());
    std::array<std::array<Eigen::Vector3d, 4>, 2> vertex_side;
    double line_sigma_px[2][2] = {{0, 0}, {0, 0}};
    // Signed angle of each image's own end (free fit) from the crossing's
    // direction of the ends, when it is known.
    double free_angle[2][2] = {{0, 0}, {0, 0}};
    double contrast = 0.0;
    int views = 0;
    bool failed = false;
    bool transversal_failed = false;
    for (int side = 0; side < 2 && !failed; ++side) {
      // The band's approximate corners must be seen (the band is fully
      // visible); its search areas may run out of the image.
      Area areas[2];
      bool visible = true;
      for (int e = 0; e < 2; ++e) {
        for (int k = 0; k < 4; ++k) {
          if (!rectification.ProjectToRectified(side, areas_3d[e][k],
                                                &areas[e][k])) {
            visible = false;
          }
        }
        for (int k : {0, 1}) {
          const Eigen::Vector2d corner = 0.5 * (areas[e][k] + areas[e][3 - k]);
          // (The valid mask holds for both images: a road point has the
          // same pixel in both.)
          visible = visible && rectification.IsValid(corner.x(), corner.y());
        }
      }
      if (!visible) {
        failed = true;
        VLOG(2) << "band " << i << " side " << side
                << ": band corners not visible " << areas[0][0].transpose()
                << " / " << areas[0][1].transpose() << " / "
                << areas[1][0].transpose() << " / " << areas[1][1].transpose();
        break;
      }
      Eigen::Vector2d c0, c1, t0, t1;
      const Eigen::Vector3d dir3 = plane_fit.x_axis;
      if (!rectification.ProjectToRectified(side, band_centre, &c0) ||
          !rectification.ProjectToRectified(side, band_centre + dir3, &c1) ||
          !rectification.ProjectToRectified(side, areas_3d[0][0], &t0) ||
          !rectification.ProjectToRectified(side, areas_3d[0][1], &t1)) {
        failed = true;
        VLOG(2) << "band " << i << " side " << side << ": projection";
        break;
      }
      const Eigen::Vector2d band_direction = (c1 - c0).normalized();
      const Eigen::Vector2d transversal = (t1 - t0).normalized();
      Eigen::Vector2d expected_normal(-transversal.y(), transversal.x());
      // At the begin side the image brightens into the band (along the band
      // direction), at the end side against it.
      if (expected_normal.dot(band_direction) < 0.0) {
        expected_normal = -expected_normal;
      }
      std::vector<ImageLine> candidates_e[2];
      for (int e = 0; e < 2; ++e) {
        if (known[e].line != nullptr) continue;
        candidates_e[e] = HoughTransversalCandidates(
            edges[side], areas[e], e == 0 ? expected_normal : -expected_normal,
            options);
        if (debug != nullptr && side == 0) {
          debug->search_areas.push_back(areas[e]);
          for (const ImageLine& line : candidates_e[e]) {
            const Eigen::Vector2d d(-line.normal.y(), line.normal.x());
            const Eigen::Vector2d p = line.rho * line.normal;
            const double t_a = (areas[e][0] - p).dot(d);
            const double t_b = (areas[e][1] - p).dot(d);
            debug->candidate_lines.push_back({p + t_a * d, p + t_b * d});
          }
        }
      }
      ImageLine transversal_lines[2];
      if (known[0].line == nullptr && known[1].line == nullptr) {
        int t = -1, l = -1;
        if (!ChooseTransversalPair(candidates_e[0], candidates_e[1],
                                   band_direction, options, &t, &l)) {
          failed = transversal_failed = true;
          VLOG(2) << "band " << i << " side " << side
                  << ": no transversal pair";
          break;
        }
        transversal_lines[0] = candidates_e[0][t];
        transversal_lines[1] = candidates_e[1][l];
      } else {
        for (int e = 0; e < 2 && !failed; ++e) {
          if (known[e].line != nullptr) {
            // The known line through the band's long sides, in this image.
            Eigen::Vector2d a, b;
            failed = !rectification.ProjectToRectified(
                         side,
                         OnBandPlane(frame, plane,
                                     AtLateral(*known[e].line, along, across,
                                               lo.lateral_m, 0.0)),
                         &a) ||
                     !rectification.ProjectToRectified(
                         side,
                         OnBandPlane(frame, plane,
                                     AtLateral(*known[e].line, along, across,
                                               hi.lateral_m, 0.0)),
                         &b);
            if (!failed) transversal_lines[e] = LineThrough(a, b);
            continue;
          }
          // The seen end: the candidate of the right polarity nearest to
          // the crossing's line there (the strongest without one).
          const double sign = e == 0 ? 1.0 : -1.0;
          Eigen::Vector2d expected_xy = Eigen::Vector2d::Zero();
          const bool has_expected =
              known[e].expected != nullptr &&
              rectification.ProjectToRectified(
                  side,
                  OnBandPlane(
                      frame, plane,
                      AtLateral(*known[e].expected, along, across,
                                0.5 * (lo.lateral_m + hi.lateral_m), 0.0)),
                  &expected_xy);
          const ImageLine* chosen = nullptr;
          double best_distance = 1e30;
          for (const ImageLine& line : candidates_e[e]) {
            if (sign * line.gamma.dot(band_direction) <= 0.0) continue;
            const double distance =
                has_expected ? std::abs(line.Distance(expected_xy)) : 0.0;
            if (distance < best_distance) {
              best_distance = distance;
              chosen = &line;
            }
            if (!has_expected) break;
          }
          if (chosen == nullptr) {
            failed = transversal_failed = true;
          } else {
            transversal_lines[e] = *chosen;
          }
        }
        if (failed) {
          VLOG(2) << "band " << i << " side " << side
                  << ": no transversal side at the seen end";
          break;
        }
      }
      for (int e = 0; e < 2; ++e) {
        if (known[e].line != nullptr) continue;
        if (!RefineImageLine(edges[side], areas[e], options,
                             &transversal_lines[e])) {
          failed = transversal_failed = true;
          VLOG(2) << "band " << i << " side " << side << " end " << e
                  << ": refinement failed";
          break;
        }
        if (known[e].direction != nullptr) {
          // The crossing's direction in this image, at this end.
          const Eigen::Vector2d normal =
              ImageNormalOf(rectification, side, frame, plane, areas_3d[e],
                            *known[e].direction, transversal_lines[e].normal);
          const Eigen::Vector2d& own = transversal_lines[e].normal;
          free_angle[side][e] = std::atan2(Cross(normal, own), normal.dot(own));
          VLOG(2) << "band " << i << " side " << side << " end " << e << ": "
                  << free_angle[side][e] << " rad from the crossing's ends";
          if (!RefineImageLine(edges[side], areas[e], options,
                               &transversal_lines[e], &normal)) {
            failed = transversal_failed = true;
            break;
          }
        }
        line_sigma_px[side][e] = std::max(
            options.min_line_sigma_px,
            transversal_lines[e].rms_px /
                std::sqrt(static_cast<double>(transversal_lines[e].support)));
        contrast += transversal_lines[e].gamma.norm() /
                    std::max(1, transversal_lines[e].support);
      }
      if (failed) break;
      // Long sides in this image.
      ImageLine long_lines[2];
      for (int k = 0; k < 2; ++k) {
        const LongSide& s = k == 0 ? lo : hi;
        Eigen::Vector2d a, b;
        if (!rectification.ProjectToRectified(side, s.Begin(), &a) ||
            !rectification.ProjectToRectified(side, s.End(), &b)) {
          failed = true;
          VLOG(2) << "band " << i << " side " << side
                  << ": long side projection";
          break;
        }
        long_lines[k] = LineThrough(a, b);
      }
      if (failed) break;
      // Vertices: 0 = lo x begin, 1 = hi x begin, 2 = hi x end, 3 = lo x end.
      const int long_of[4] = {0, 1, 1, 0};
      const int end_of[4] = {0, 0, 1, 1};
      const Eigen::Vector3d centre = side == 0
                                         ? rectification.left_centre_body()
                                         : rectification.right_centre_body();
      Eigen::Vector2d corner[4];  // the vertices in this rectified image
      for (int v = 0; v < 4 && !failed; ++v) {
        if (!Intersect(long_lines[long_of[v]], transversal_lines[end_of[v]],
                       &corner[v]) ||
            !plane.IntersectRay(centre, rectification.RayBody(side, corner[v]),
                                &vertex_side[side][v])) {
          failed = true;
          VLOG(2) << "band " << i << " side " << side
                  << ": vertex intersection";
        }
      }
      if (failed) break;
      // A seen transversal edge stops at the long sides: a shadow boundary
      // across a lane line runs on over the road.
      for (int e = 0; e < 2 && !failed; ++e) {
        if (known[e].line != nullptr) continue;
        Eigen::Vector2d ends[2];
        if (!Intersect(long_lines[0], transversal_lines[e], &ends[0]) ||
            !Intersect(long_lines[1], transversal_lines[e], &ends[1])) {
          failed = true;
          break;
        }
        // Beyond a hidden long side, what hides it may have edges.
        const bool check[2] = {pairs[i].inferred != 0, pairs[i].inferred != 1};
        const double run_on =
            TransversalRunOn(edges[side], transversal_lines[e], ends, check);
        VLOG(2) << "band " << i << " side " << side << " end " << e
                << ": run-on " << run_on;
        failed = run_on > options.max_transversal_run_on;
      }
      if (failed) {
        VLOG(2) << "band " << i << " side " << side
                << ": a transversal edge runs on beyond the band";
        break;
      }
      // A seen end is the paint ending against the road: its grey-level
      // step is of the order of the long sides'. A weak Hough maximum in
      // plain paint (the band running on out of view, under the vehicle)
      // is not an end.
      {
        for (int e = 0; e < 2 && !failed; ++e) {
          if (known[e].line != nullptr) continue;
          // The long sides' step near this end (a shadow across the band
          // lowers both alike): over 8-32 % of the band from the end.
          double long_step = 0.0;
          int long_count = 0;
          for (int k = 0; k < 2; ++k) {
            if (pairs[i].inferred == k) continue;
            const Eigen::Vector2d at_end = corner[e == 0 ? k : 3 - k];
            const Eigen::Vector2d other_end = corner[e == 0 ? 3 - k : k];
            const double step = EdgeStep(edges[side], long_lines[k], at_end,
                                         at_end + 0.4 * (other_end - at_end),
                                         options.end_step_profile_px);
            if (std::isfinite(step)) {
              long_step += step;
              ++long_count;
            }
          }
          if (long_count == 0) continue;
          const double step = EdgeStep(
              edges[side], transversal_lines[e], corner[e == 0 ? 0 : 3],
              corner[e == 0 ? 1 : 2], options.end_step_profile_px);
          const double ratio = step / (long_step / long_count);
          VLOG(2) << "band " << i << " side " << side << " end " << e
                  << ": step " << ratio << " of the long sides'";
          failed = !(ratio >= options.min_end_step_fraction);
        }
        if (failed) {
          VLOG(2) << "band " << i << " side " << side
                  << ": a transversal side without the paint's step";
          break;
        }
      }
      for (int v = 0; v < 4; ++v) vertex_sum[v] += vertex_side[side][v];
      ++views;
    }
    if (failed || views != 2) {
      return transversal_failed ? BandOutcome::kNoTransversal
                                : BandOutcome::kRejected;
    }
    // A painted end is parallel to its crossing's (a stain's slanted edge
    // cutting the paint is not): each end's own direction, averaged over
    // the two images (a far end's angle is noisy in each), within
    // max_end_angle_rad of the crossing's.
    for (int e = 0; e < 2; ++e) {
      if (known[e].direction == nullptr || known[e].line != nullptr) continue;
      const double angle = 0.5 * (free_angle[0][e] + free_angle[1][e]);
      if (!(std::abs(angle) <= options.max_end_angle_rad)) {
        VLOG(2) << "band " << i << " end " << e << ": " << angle
                << " rad from the crossing's ends";
        return BandOutcome::kRejected;
      }
    }

    Band band;
    band.plane = plane;
    band.crossing = crossing;
    band.sides[0] = pairs[i].lo;
    band.sides[1] = pairs[i].hi;
    double disagreement = 0.0;
    for (int v = 0; v < 4; ++v) {
      band.vertices_body[v] = vertex_sum[v] / views;
      disagreement = std::max(disagreement,
                              (vertex_side[0][v] - vertex_side[1][v]).norm());
    }
    band.stereo_disagreement_m = disagreement;
    for (int v = 0; v < 4; ++v) {
      VLOG(3) << "band " << i << " vertex " << v << " left "
              << vertex_side[0][v].transpose() << " right "
              << vertex_side[1][v].transpose();
    }
    const Eigen::Vector3d band_middle =
        0.25 * (band.vertices_body[0] + band.vertices_body[1] +
                band.vertices_body[2] + band.vertices_body[3]);
    const double range =
        (band_middle - rectification.left_centre_body()).norm();
    if (range > options.max_band_range_m) {
      VLOG(2) << "band " << i << ": range " << range;
      return BandOutcome::kRejected;
    }
    // An inferred side or end is extrapolated: far away, its error grows
    // past what a control point may carry (a closer exposure sees it).
    const bool extrapolated = pairs[i].inferred >= 0 ||
                              known[0].line != nullptr ||
                              known[1].line != nullptr;
    if (extrapolated && range > options.max_inferred_range_m) {
      VLOG(2) << "band " << i << ": extrapolated at range " << range;
      return BandOutcome::kRejected;
    }
    if (end_directions != nullptr && !extrapolated) {
      // Each image's two ends, weighted by their angular precision: the
      // along-band error of an end grows with the square of its range.
      for (int side = 0; side < 2; ++side) {
        for (int e = 0; e < 2; ++e) {
          const Eigen::Vector3d& a = vertex_side[side][e == 0 ? 0 : 3];
          const Eigen::Vector3d& b = vertex_side[side][e == 0 ? 1 : 2];
          const double r =
              (0.5 * (a + b) - rectification.left_centre_body()).norm();
          end_directions->push_back(
              {crossing, (frame.To2d(b) - frame.To2d(a)).normalized(),
               1.0 / std::pow(std::max(r, 1.0), 4)});
        }
      }
    }
    if (disagreement > options.max_stereo_disagreement_m) {
      VLOG(2) << "band " << i << ": stereo disagreement " << disagreement;
      return BandOutcome::kDisagreement;
    }
    const Eigen::Vector3d& v0 = band.vertices_body[0];
    const Eigen::Vector3d& v1 = band.vertices_body[1];
    const Eigen::Vector3d& v2 = band.vertices_body[2];
    const Eigen::Vector3d& v3 = band.vertices_body[3];
    band.length_m = 0.5 * ((v3 - v0).norm() + (v2 - v1).norm());
    band.width_m = 0.5 * ((v1 - v0).norm() + (v2 - v3).norm()) *
                   std::abs(plane_fit.y_axis.dot((v1 - v0).normalized()));
    if (band.length_m < zebra.min_band_length_m - 0.5 ||
        band.length_m > zebra.max_band_length_m + options.max_length_excess_m) {
      VLOG(2) << "band " << i << ": length " << band.length_m;
      return BandOutcome::kRejected;
    }
    // A painted band is a parallelogram: its ends are parallel.
    const double end_angle = EndAngleRad(band.vertices_body);
    if (!(end_angle <= options.max_end_angle_rad)) {
      VLOG(2) << "band " << i << ": ends " << end_angle << " rad from parallel";
      return BandOutcome::kRejected;
    }

    // Covariance: along the band from the transversal line fits, across
    // from the long side regression, and the band plane's height error,
    // which moves a vertex along its viewing ray.
    const Eigen::Vector3d plane_normal = plane.normal_body;
    const Eigen::Vector3d x_axis = plane_fit.x_axis;
    const Eigen::Vector3d y_axis = plane_fit.y_axis;
    for (int v = 0; v < 4; ++v) {
      const Eigen::Vector3d& p = band.vertices_body[v];
      const int e = v == 0 || v == 1 ? 0 : 1;
      const LongSide& s = v == 0 || v == 3 ? lo : hi;
      const Eigen::Vector3d ray =
          (p - rectification.left_centre_body()).normalized();
      const double depth = (rectification.R_body_virt().transpose() *
                            (p - rectification.left_centre_body()))
                               .z();
      const double metres_per_px = depth / rectification.focal_px();
      // The two images' lines are independent estimates.
      const double sigma_px =
          0.5 * std::hypot(line_sigma_px[0][e], line_sigma_px[1][e]);
      const double sigma_along = known[e].line != nullptr
                                     ? known[e].sigma_m
                                     : sigma_px * metres_per_px;
      const bool inferred = pairs[i].inferred == (v == 0 || v == 3 ? 0 : 1);
      const double sigma_across =
          inferred
              ? pairs[i].inferred_sigma_m
              : std::max(options.min_sigma_m,
                         s.lateral_rms_m /
                             std::sqrt(static_cast<double>(s.support.size())));
      const double sigma_height =
          std::max(options.min_sigma_m, std::sqrt(plane_fit.HeightVariance(p)));
      const Eigen::Vector3d along_ray = ray / std::abs(plane_normal.dot(ray));
      band.covariances_body[v] =
          sigma_along * sigma_along * x_axis * x_axis.transpose() +
          sigma_across * sigma_across * y_axis * y_axis.transpose() +
          sigma_height * sigma_height * along_ray * along_ray.transpose();
    }

    // Score: width as specified, stereo agreement, contrast, flatness.
    const double width_term = std::exp(
        -0.5 * std::pow((band.width_m - zebra.band_width_m) / 0.05, 2));
    const double stereo_term =
        std::exp(-0.5 * std::pow(disagreement / 0.02, 2));
    const double contrast_term = std::min(1.0, contrast / (4.0 * 10.0));
    const double flat_term =
        std::exp(-0.5 * std::pow(plane_fit.rms_m / 0.02, 2));
    band.score = std::clamp(
        width_term * stereo_term * contrast_term * flat_term, 0.0, 1.0);
    // A completed band's hidden side is an inference, not a measurement.
    if (pairs[i].inferred >= 0) band.score *= options.inferred_score_factor;
    band.inferred_side = pairs[i].inferred;
    for (int e = 0; e < 2; ++e) {
      if (known[e].line != nullptr) {
        band.score *= options.inferred_score_factor;
        band.inferred_end = e;
      }
    }
    *out = band;
    return BandOutcome::kBand;
  };

  std::vector<Band> bands;
  std::vector<int> without_transversal;
  std::vector<EndDirectionObservation> observations;
  end_directions = options.crossing_end_direction ? &observations : nullptr;
  const KnownEnd none[2];
  std::vector<BandOutcome> outcomes(m_all);
  std::vector<Band> first(m_all);
  for (int i = 0; i < m_all; ++i) outcomes[i] = model_band(i, none, &first[i]);
  end_directions = nullptr;
  // 4b. The ends of a crossing's bands are parallel: the direction of its
  // ends, from every band seen in both images and weighted by range, is
  // far more precise than a far band's own (a 0.5 m end at 15 m spans a
  // few original pixels: its angle is noisy, and its two vertices move
  // apart, one forward, one back). Each band is modelled again with its
  // ends fitted along that direction.
  std::vector<Eigen::Vector2d> crossing_direction(crossings);
  std::vector<char> has_direction(crossings, 0);
  for (int c = 0; c < crossings && options.crossing_end_direction; ++c) {
    has_direction[c] = CrossingEndDirection(
        observations, c, options.min_end_direction_observations,
        &crossing_direction[c]);
  }
  for (int i = 0; i < m_all; ++i) {
    Band band = first[i];
    BandOutcome outcome = outcomes[i];
    if (has_direction[crossing_of[i]]) {
      KnownEnd along_crossing[2];
      for (KnownEnd& k : along_crossing) {
        k.direction = &crossing_direction[crossing_of[i]];
      }
      outcome = model_band(i, along_crossing, &band);
    }
    if (outcome == BandOutcome::kBand) bands.push_back(band);
    if (outcome == BandOutcome::kNoTransversal ||
        outcome == BandOutcome::kDisagreement) {
      without_transversal.push_back(i);
    }
  }
  if (!options.infer_hidden_ends || without_transversal.empty()) return bands;

  // 5. Hidden ends: a vehicle parked before a crossing hides the end of its
  // outer bands. The transversal sides of a crossing are one line at each
  // end; fitted on the vertices of its fully seen bands, that line gives
  // the hidden end when it is reliable: enough bands, small residuals, a
  // band next to them. The band's seen end must lie on the other line.
  // (An end hidden in one image only makes the two images disagree.)
  std::vector<std::array<PlaneLine, 2>> lines(crossings);
  std::vector<std::array<double, 2>> line_sigma(crossings, {-1.0, -1.0});
  std::vector<std::array<double, 2>> line_rms(crossings, {-1.0, -1.0});
  std::vector<std::array<double, 2>> lateral_range(crossings, {1e30, -1e30});
  for (int c = 0; c < crossings; ++c) {
    for (int e = 0; e < 2; ++e) {
      std::vector<Eigen::Vector2d> points;
      Eigen::Vector2d across = Eigen::Vector2d::UnitY();
      for (const Band& band : bands) {
        if (band.crossing != c || band.inferred_side >= 0) continue;
        const Eigen::Vector2d a =
            frame.To2d(band.vertices_body[e == 0 ? 0 : 3]);
        const Eigen::Vector2d b =
            frame.To2d(band.vertices_body[e == 0 ? 1 : 2]);
        points.push_back(a);
        points.push_back(b);
        across = sides[band.sides[0]].Normal2d();
        lateral_range[c][0] = std::min(lateral_range[c][0], a.dot(across));
        lateral_range[c][1] = std::max(lateral_range[c][1], b.dot(across));
      }
      if (static_cast<int>(points.size()) < 2 * options.completion_min_bands) {
        continue;
      }
      lines[c][e] = FitPlaneLine(points, across);
      const Eigen::Vector2d normal(-lines[c][e].direction.y(),
                                   lines[c][e].direction.x());
      double sum_squares = 0.0;
      for (const Eigen::Vector2d& p : points) {
        sum_squares += std::pow((p - lines[c][e].point).dot(normal), 2);
      }
      const double rms =
          std::sqrt(sum_squares / static_cast<double>(points.size() - 2));
      VLOG(2) << "crossing " << c << " end " << e << ": line through "
              << points.size() / 2 << " bands, rms " << rms;
      line_rms[c][e] = rms;
      if (rms <= options.hidden_end_max_rms_m) {
        line_sigma[c][e] = std::max(options.completion_min_sigma_m, 2.0 * rms);
      }
    }
  }
  for (int i : without_transversal) {
    const int c = crossing_of[i];
    if (line_rms[c][0] < 0.0 || line_rms[c][1] < 0.0) continue;
    // Next to the seen bands: at most one band period out of them.
    const LongSide& lo = sides[pairs[i].lo];
    const LongSide& hi = sides[pairs[i].hi];
    const Eigen::Vector2d across = lo.Normal2d();
    const double reach = 2.5 * zebra.band_width_m;
    const double lateral_lo = frame.To2d(lo.point_body).dot(across);
    const double lateral_hi = frame.To2d(hi.point_body).dot(across);
    if (lateral_lo < lateral_range[c][0] - reach ||
        lateral_hi > lateral_range[c][1] + reach) {
      continue;
    }
    for (int e = 0; e < 2; ++e) {
      if (line_sigma[c][e] < 0.0) continue;  // not reliable
      KnownEnd known[2];
      known[e].line = &lines[c][e];
      known[e].sigma_m = line_sigma[c][e];
      known[1 - e].expected = &lines[c][1 - e];
      if (has_direction[c]) known[1 - e].direction = &crossing_direction[c];
      Band band;
      if (model_band(i, known, &band) != BandOutcome::kBand) continue;
      // The seen end on the crossing's line of that end.
      const PlaneLine& other = lines[c][1 - e];
      const Eigen::Vector2d normal(-other.direction.y(), other.direction.x());
      double worst = 0.0;
      for (int v :
           e == 0 ? std::array<int, 2>{2, 3} : std::array<int, 2>{0, 1}) {
        worst = std::max(
            worst,
            std::abs(
                (frame.To2d(band.vertices_body[v]) - other.point).dot(normal)));
      }
      VLOG(2) << "band " << i << ": hidden end " << e << ", seen end " << worst
              << " m off the crossing's line";
      if (worst >
          std::max(options.hidden_end_max_offset_m, 3.0 * line_rms[c][1 - e])) {
        continue;
      }
      bands.push_back(band);
      break;
    }
  }
  return bands;
}

}  // namespace zebrageo
