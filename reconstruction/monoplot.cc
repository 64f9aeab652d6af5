#include "reconstruction/monoplot.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// True when the edge at `p` runs within max_angle of the rows: its
// gradient is within that angle of the columns.
bool AlongRows(const EdgePoint& p, double max_angle_rad) {
  const double norm = std::hypot(p.gx, p.gy);
  return norm > 0.0 && std::abs(p.gy) >= std::cos(max_angle_rad) * norm;
}

// Median and robust standard deviation (1.4826 MAD) of `values`.
void MedianSpread(std::vector<double> values, double* median, double* spread) {
  *median = Median(values);
  for (double& v : values) v = std::abs(v - *median);
  *spread = 1.4826 * Median(values);
}

// The run's height over the road plane along the rows (rectified x).
struct HeightLine {
  double a = 0.0, b = 0.0, sigma = 0.0;
  bool ok = false;
};

// A line through heights h at rows' abscissae x, without the outliers
// (mismatches: beyond 3 robust spreads, at least 1 cm); a constant when
// they span less than min_span_px.
HeightLine FitHeightLine(const std::vector<double>& x,
                         const std::vector<double>& h, double min_span_px,
                         const MonoplotOptions& options) {
  HeightLine line;
  if (static_cast<int>(h.size()) < options.min_height_points) return line;
  double median = 0.0, spread = 0.0;
  MedianSpread(h, &median, &spread);
  const double limit = std::max(0.01, 3.0 * spread);
  double sx = 0, sh = 0, sxx = 0, sxh = 0;
  int n = 0;
  for (size_t k = 0; k < h.size(); ++k) {
    if (std::abs(h[k] - median) > limit) continue;
    sx += x[k];
    sh += h[k];
    sxx += x[k] * x[k];
    sxh += x[k] * h[k];
    ++n;
  }
  if (n < options.min_height_points) return line;
  const double mx = sx / n, mh = sh / n;
  const double vxx = sxx / n - mx * mx;
  line.b =
      vxx > 0.25 * min_span_px * min_span_px ? (sxh / n - mx * mh) / vxx : 0.0;
  line.a = mh - line.b * mx;
  double r2 = 0.0;
  for (size_t k = 0; k < h.size(); ++k) {
    if (std::abs(h[k] - median) > limit) continue;
    const double r = h[k] - line.a - line.b * x[k];
    r2 += r * r;
  }
  const double rms = std::sqrt(r2 / n);
  if (rms > options.max_height_spread_m) return line;
  // The line's error at the run, and the surface's own departure from it.
  line.sigma = std::max(options.min_height_sigma_m, 2.0 * rms / std::sqrt(n));
  line.ok = true;
  return line;
}

// The triangulated points near the road whose edges cross the rows (a
// match along them is a guess), by 16-pixel cell of the left image; the
// height line of those around a run's two ends (its band's ends).
class EndHeights {
 public:
  EndHeights(
      const std::vector<std::vector<std::pair<int, EdgePoint3d>>>& by_chain,
      const RoadPlane& plane, double keep_distance_m,
      const MonoplotOptions& options, double ground_pixel_m)
      : options_(options),
        radius_px_(options.end_radius_m / ground_pixel_m),
        min_span_px_(options.min_height_span_m / ground_pixel_m) {
    for (const auto& chain : by_chain) {
      for (const auto& [index, p] : chain) {
        const double g = p.gradient.norm();
        if (!(std::abs(p.gradient.y()) <
              std::cos(options.max_row_angle_rad) * g)) {
          continue;
        }
        const double d = plane.SignedDistance(p.p_body);
        if (std::abs(d) > keep_distance_m) continue;
        cells_[Key(Cell(p.xy_left.x()), Cell(p.xy_left.y()))].push_back(
            {p.xy_left.x(), p.xy_left.y(), d});
      }
    }
  }

  HeightLine Around(const EdgePoint& first, const EdgePoint& last) const {
    std::vector<double> x, h;
    const int64_t r = static_cast<int64_t>(std::ceil(radius_px_ / kCell));
    for (const EdgePoint* e : {&first, &last}) {
      for (int64_t i = Cell(e->x) - r; i <= Cell(e->x) + r; ++i) {
        for (int64_t j = Cell(e->y) - r; j <= Cell(e->y) + r; ++j) {
          const auto it = cells_.find(Key(i, j));
          if (it == cells_.end()) continue;
          for (const Known& k : it->second) {
            if (std::hypot(k.x - e->x, k.y - e->y) > radius_px_) continue;
            x.push_back(k.x);
            h.push_back(k.h);
          }
        }
      }
    }
    return FitHeightLine(x, h, min_span_px_, options_);
  }

 private:
  struct Known {
    double x, y, h;
  };
  static constexpr double kCell = 16.0;
  static int64_t Cell(double v) {
    return static_cast<int64_t>(std::floor(v / kCell));
  }
  static int64_t Key(int64_t i, int64_t j) { return i * 1000003 + j; }
  const MonoplotOptions& options_;
  double radius_px_, min_span_px_;
  std::unordered_map<int64_t, std::vector<Known>> cells_;
};

}  // namespace

std::string MonoplotOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, max_row_angle_rad, "(", 0.0, 0.8, ")");
  OPTION_GT(check, min_run_length_m, 0.0);
  OPTION_GE(check, max_run_gap_points, 0);
  OPTION_GT(check, end_radius_m, 0.0);
  OPTION_GT(check, min_height_span_m, 0.0);
  OPTION_GE(check, min_height_points, 3);
  OPTION_GT(check, max_height_spread_m, 0.0);
  OPTION_GT(check, min_height_sigma_m, 0.0);
  OPTION_GT(check, edge_sigma_px, 0.0);
  OPTION_GT(check, height_disparity_sigma_px, 0.0);
  return check.problem();
}

void MonoplotSigmas(const RoadPlane& plane, const Eigen::Vector3d& centre,
                    const Eigen::Vector3d& p,
                    const Eigen::Vector3d& edge_direction, double baseline_m,
                    double pixel_angle_rad, double line_sigma_m,
                    const MonoplotOptions& options, double* across_sigma_m,
                    double* height_sigma_m) {
  const Eigen::Vector3d ray = p - centre;
  const double range = ray.norm();
  const Eigen::Vector3d& n = plane.normal_body;
  // The edge's image line fixes the plane through the camera and the edge
  // (normal m); moving the point by d across the edge on the road (along
  // `across`) moves it d |across . m| off that plane, seen at `range`.
  const Eigen::Vector3d along =
      (edge_direction - edge_direction.dot(n) * n).normalized();
  const Eigen::Vector3d across = n.cross(along);
  const Eigen::Vector3d m = ray.cross(along).normalized();
  const double grazing = std::max(0.05, std::abs(across.dot(m)));
  *across_sigma_m = options.edge_sigma_px * pixel_angle_rad * range / grazing;
  // A triangulated point's height error: its depth error (range^2 / (f B)
  // per pixel of disparity) along a ray that descends height / range.
  const double height = std::abs(plane.SignedDistance(centre));
  *height_sigma_m = std::max(
      line_sigma_m, options.height_disparity_sigma_px * pixel_angle_rad *
                        range * height / std::max(baseline_m, 1e-3));
}

std::vector<EdgeChain3d> MonoplotRowEdges(
    const RoadRectification& rectification, const EdgeMap& left,
    const std::vector<std::vector<std::pair<int, EdgePoint3d>>>& by_chain,
    const RoadPlane& plane, double keep_distance_m, double pixel_angle_rad,
    const MonoplotOptions& options) {
  std::vector<EdgeChain3d> out;
  if (!options.enabled) return out;
  const Eigen::Vector3d centre = rectification.left_centre_body();
  const int min_points = static_cast<int>(
      std::ceil(options.min_run_length_m / rectification.ground_pixel_m()));
  const EndHeights heights(by_chain, plane, keep_distance_m, options,
                           rectification.ground_pixel_m());
  auto monoplot_run = [&](const std::vector<int>& run, const HeightLine& h) {
    if (static_cast<int>(run.size()) < min_points || !h.ok) return;
    EdgeChain3d chain;
    for (int k : run) {
      const EdgePoint& e = left.points[k];
      RoadPlane local = plane;
      local.offset_m += h.a + h.b * e.x;
      EdgePoint3d p;
      if (!local.IntersectRay(centre, rectification.RayBody(0, {e.x, e.y}),
                              &p.p_body)) {
        continue;
      }
      p.p_chain_body = p.p_body;
      p.xy_left = Eigen::Vector2d(e.x, e.y);
      p.gradient = Eigen::Vector2d(e.gx, e.gy);
      p.index_in_chain = e.index_in_chain;
      p.monoplot_height_sigma_m = h.sigma;
      chain.points.push_back(p);
    }
    VLOG(3) << "monoplot run of " << chain.points.size() << " points, height "
            << h.a << " + " << h.b << " x, sigma " << h.sigma;
    if (static_cast<int>(chain.points.size()) < min_points) return;
    const Eigen::Vector3d direction =
        chain.points.back().p_body - chain.points.front().p_body;
    for (EdgePoint3d& p : chain.points) {
      MonoplotSigmas(plane, centre, p.p_body, direction,
                     rectification.baseline_m(), pixel_angle_rad, h.sigma,
                     options, &p.monoplot_across_sigma_m,
                     &p.monoplot_height_sigma_m);
    }
    out.push_back(std::move(chain));
  };
  // A run goes on over up to max_run_gap_points points whose gradient
  // noise turns them off the rows (worn paint, a blurred far edge).
  for (int c = 0; c < static_cast<int>(left.chains.size()); ++c) {
    const std::vector<int>& chain = left.chains[c];
    std::vector<int> run, pending;
    auto flush = [&]() {
      if (static_cast<int>(run.size()) >= min_points) {
        monoplot_run(run, heights.Around(left.points[run.front()],
                                         left.points[run.back()]));
      }
      run.clear();
      pending.clear();
    };
    for (int k : chain) {
      if (AlongRows(left.points[k], options.max_row_angle_rad)) {
        if (!run.empty()) run.insert(run.end(), pending.begin(), pending.end());
        pending.clear();
        run.push_back(k);
        continue;
      }
      pending.push_back(k);
      if (static_cast<int>(pending.size()) > options.max_run_gap_points) {
        flush();
      }
    }
    flush();
  }
  return out;
}

}  // namespace zebrageo
