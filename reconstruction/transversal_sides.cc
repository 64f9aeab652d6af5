#include "reconstruction/transversal_sides.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

using Area = std::array<Eigen::Vector2d, 4>;

bool InsideConvex(const Area& area, const Eigen::Vector2d& p) {
  int sign = 0;
  for (int k = 0; k < 4; ++k) {
    const double c = Cross2d(area[(k + 1) % 4] - area[k], p - area[k]);
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

// The sub-pixel edge points along `line` inside `area` (see
// RefineImageLine): the centroids of the gradient profiles across it, with
// the profile's peak as weight.
void ProfileCentroids(const EdgeMap& edges, const Area& area,
                      const BandOptions& options, const ImageLine& current,
                      const Eigen::Vector2d& polarity,
                      std::vector<Eigen::Vector2d>* points_out,
                      std::vector<double>* weights_out) {
  const double reach = options.refine_distance_px;
  const double step = 0.5;
  const int half = static_cast<int>(std::ceil(reach / step));
  std::vector<double> profile(2 * half + 1);
  std::vector<char> seen(2 * half + 1);
  std::vector<Eigen::Vector2d>& points = *points_out;
  std::vector<double>& weights = *weights_out;
  const Eigen::Vector2d direction(-current.normal.y(), current.normal.x());
  const Eigen::Vector2d origin = current.rho * current.normal;
  double t_min = 1e30, t_max = -1e30;
  for (const Eigen::Vector2d& c : area) {
    t_min = std::min(t_min, (c - origin).dot(direction));
    t_max = std::max(t_max, (c - origin).dot(direction));
  }
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
}

// Weighted least squares line through `points`, then again without the
// points more than 3 rms (at least 0.5 px) away; `fixed_normal` (may be
// null) keeps that normal. False with fewer than min_transversal_points.
bool FitWeightedLine(const std::vector<Eigen::Vector2d>& points,
                     const std::vector<double>& weights,
                     const BandOptions& options,
                     const Eigen::Vector2d* fixed_normal, ImageLine* line) {
  ImageLine& current = *line;
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
        fixed_normal != nullptr ? *fixed_normal
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
  return true;
}

}  // namespace

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
  // The votes of an angle theta_k need phi - theta_k within the tolerance
  // (modulo 2 pi); when the angles and the tolerance span less than pi,
  // those k are a run around phi - theta0 (no wrap around can reach them).
  const double step_t = options.hough_angle_step_rad;
  const bool narrow =
      half * step_t + options.point_angle_tolerance_rad + 2.0 * step_t < kPi;
  // Every pixel with a gradient votes, weighted by its norm: transversal
  // sides far away are blurred along the road over several pixels, where
  // non-maximum suppression finds no reliable edge points.
  for (const Eigen::Vector2i& pixel : inside) {
    const float gx = edges.gx.at<float>(pixel.y(), pixel.x());
    const float gy = edges.gy.at<float>(pixel.y(), pixel.x());
    const float norm = std::hypot(gx, gy);
    if (norm < options.hough_min_gradient) continue;
    const double phi = std::atan2(gy, gx);
    // Only the angles within the tolerance of phi can vote: their range is
    // found first (with a step of margin), the test below decides.
    int k_begin = 0, k_end = n_theta;
    if (narrow) {
      const double delta = std::remainder(phi - theta0, 2.0 * kPi);
      k_begin = std::max(
          0, static_cast<int>(std::floor(
                 half + (delta - options.point_angle_tolerance_rad) / step_t)) -
                 1);
      k_end = std::min(
          n_theta,
          static_cast<int>(std::ceil(
              half + (delta + options.point_angle_tolerance_rad) / step_t)) +
              2);
    }
    for (int k = k_begin; k < k_end; ++k) {
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
  ImageLine current = *line;
  for (int round = 0; round < 3; ++round) {
    std::vector<Eigen::Vector2d> points;
    std::vector<double> weights;
    ProfileCentroids(edges, area, options, current, polarity, &points,
                     &weights);
    if (!FitWeightedLine(points, weights, options, fixed_normal, &current)) {
      return false;
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

}  // namespace zebrageo
