#include "reconstruction/crossing_edges.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "reconstruction/bright_lines.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// v = c0 + c1 u by least squares; false with fewer than 2 distinct u.
struct StraightFit {
  double c0 = 0.0, c1 = 0.0, rms = 0.0, max_residual = 0.0;
  int worst = -1;
};
bool FitStraight(const std::vector<Eigen::Vector2d>& uv, StraightFit* fit) {
  const double n = static_cast<double>(uv.size());
  if (uv.size() < 2) return false;
  double su = 0, sv = 0, suu = 0, suv = 0;
  for (const Eigen::Vector2d& p : uv) {
    su += p.x();
    sv += p.y();
    suu += p.x() * p.x();
    suv += p.x() * p.y();
  }
  const double det = n * suu - su * su;
  if (!(det > 1e-9 * n * n)) return false;
  fit->c1 = (n * suv - su * sv) / det;
  fit->c0 = (sv - fit->c1 * su) / n;
  double sum_squares = 0.0;
  fit->max_residual = 0.0;
  for (size_t i = 0; i < uv.size(); ++i) {
    const double r = std::abs(uv[i].y() - fit->c0 - fit->c1 * uv[i].x());
    sum_squares += r * r;
    if (r >= fit->max_residual) {
      fit->max_residual = r;
      fit->worst = static_cast<int>(i);
    }
  }
  fit->rms = std::sqrt(sum_squares / n);
  return true;
}

}  // namespace

cv::Mat BandPaintPixels(const cv::Mat& image, const cv::Mat& valid, double gsd,
                        const CrossingEdgeOptions& options) {
  cv::Mat smooth;
  cv::GaussianBlur(image, smooth, cv::Size(0, 0), 1.0);
  // The ground of a pixel: the darkest valid pixel of its row within
  // box_window_m (a band period: a gap is in it); its paint level: the
  // brightest within half that (not the next band's, in the sun when this
  // one is in a shadow).
  const int half =
      static_cast<int>(std::lround(0.5 * options.box_window_m / gsd));
  const cv::Mat kernel = cv::Mat::ones(1, 2 * half + 1, CV_8U);
  const cv::Mat paint_kernel = cv::Mat::ones(1, half | 1, CV_8U);
  cv::Mat for_ground = smooth.clone(), for_paint = smooth.clone();
  for_ground.setTo(std::numeric_limits<float>::max(), valid == 0);
  for_paint.setTo(std::numeric_limits<float>::lowest(), valid == 0);
  cv::Mat ground, top;
  cv::erode(for_ground, ground, kernel, cv::Point(-1, -1), 1,
            cv::BORDER_REPLICATE);
  cv::dilate(for_paint, top, paint_kernel, cv::Point(-1, -1), 1,
             cv::BORDER_REPLICATE);
  cv::Mat paint(image.size(), CV_8U, cv::Scalar(0));
  const float contrast = static_cast<float>(options.min_contrast);
  for (int y = 0; y < image.rows; ++y) {
    const float* g = smooth.ptr<float>(y);
    const float* lo = ground.ptr<float>(y);
    const float* hi = top.ptr<float>(y);
    const uint8_t* v = valid.ptr<uint8_t>(y);
    uint8_t* out = paint.ptr<uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      // Over the ground by min_contrast, and nearer the paint's level.
      if (v[x] != 0 && g[x] >= lo[x] + contrast &&
          2.0f * g[x] > lo[x] + hi[x]) {
        out[x] = 255;
      }
    }
  }
  KeepRunsByWidth(
      valid, std::max(1, static_cast<int>(options.min_band_width_m / gsd)),
      static_cast<int>(std::ceil(options.max_band_width_m / gsd)), &paint);
  // Sunlit asphalt beside a shadow's edge is over the shadowed ground too,
  // but its two sides differ.
  KeepRunsOnEvenGround(image, options.max_side_difference, &paint);
  return paint;
}

namespace {

// Step 3 at one end (outward -1 top, +1 bottom) of a band whose pixels are
// `label` in `labels` inside `box`; the centre line x = a + b y, width w.
bool EndOfBand(const cv::Mat& image, const cv::Mat& valid,
               const cv::Mat& labels, int label, const cv::Rect& box, double a,
               double b, double width, int outward,
               const CrossingEdgeOptions& options, BandEnd* end) {
  constexpr int kInsideRows = 24;        // HalfContrastEndRow's fitting window
  std::vector<Eigen::Vector2d> columns;  // (x, end row)
  for (int x = box.x; x < box.x + box.width; ++x) {
    int row = -1;
    for (int k = 0; k < box.height; ++k) {
      const int y = outward < 0 ? box.y + k : box.y + box.height - 1 - k;
      if (labels.at<int>(y, x) == label) {
        row = y;
        break;
      }
    }
    if (row < 0) continue;
    // Inside the band's width (not a frayed corner) at that row.
    if (std::abs(x - (a + b * row)) > 0.5 * width - 2.0) continue;
    std::vector<cv::Point> chain;
    for (int k = kInsideRows; k >= 0; --k) {
      chain.emplace_back(x, row - outward * k);
    }
    if (outward < 0) std::reverse(chain.begin(), chain.end());
    const double y =
        HalfContrastEndRow(image, valid, chain, outward, options.min_contrast);
    if (std::isfinite(y)) columns.emplace_back(x, y);
  }
  if (static_cast<int>(columns.size()) < options.min_end_columns) return false;
  StraightFit fit;
  if (!FitStraight(columns, &fit) || fit.rms > options.max_end_rms_px ||
      std::abs(fit.c1) > options.max_end_slope) {
    return false;
  }
  // Where the centre line x = a + b y meets the end y = c0 + c1 x.
  const double x = (a + b * fit.c0) / (1.0 - b * fit.c1);
  end->mid_px = Eigen::Vector2d(x, fit.c0 + fit.c1 * x);
  end->end_slope = fit.c1;
  end->axis_slope = b;
  end->outward = outward;
  end->width_px = width;
  return true;
}

}  // namespace

std::string CrossingEdgeOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, box_window_m, 0.5);
  OPTION_GT(check, min_contrast, 0.0);
  OPTION_GT(check, min_band_width_m, 0.0);
  OPTION_REQUIRE(check, max_band_width_m > min_band_width_m, max_band_width_m,
                 "band widths must satisfy 0 < min_band_width_m < "
                 "max_band_width_m");
  OPTION_GT(check, max_side_difference, 0.0);
  OPTION_GT(check, min_band_length_m, 0.0);
  OPTION_GT(check, max_axis_slope, 0.0);
  OPTION_GT(check, max_end_slope, 0.0);
  OPTION_GT(check, max_end_rms_px, 0.0);
  OPTION_GE(check, min_end_columns, 2);
  OPTION_GE(check, min_bands, 2);
  OPTION_GT(check, stereo_length_m, 0.0);
  OPTION_GT(check, max_axis_rms_m, 0.0);
  OPTION_GT(check, max_end_height_difference_m, 0.0);
  OPTION_GT(check, max_end_range_m, 0.0);
  OPTION_GE(check, min_stereo_rows, 3);
  OPTION_GT(check, max_band_gap_m, 0.0);
  OPTION_GT(check, max_edge_residual_m, 0.0);
  OPTION_GT(check, max_end_angle_rad, 0.0);
  OPTION_GT(check, end_sigma_px, 0.0);
  return check.problem();
}

std::vector<BandEnd> FindBandEnds(const cv::Mat& image, const cv::Mat& valid,
                                  const cv::Mat& paint, double ground_pixel_m,
                                  const CrossingEdgeOptions& options) {
  std::vector<BandEnd> ends;
  const double gsd = ground_pixel_m;
  cv::Mat labels, stats, centroids;
  const int n =
      cv::connectedComponentsWithStats(paint, labels, stats, centroids, 8);
  const int min_rows = static_cast<int>(options.min_band_length_m / gsd);
  for (int label = 1; label < n; ++label) {
    const cv::Rect box(stats.at<int>(label, cv::CC_STAT_LEFT),
                       stats.at<int>(label, cv::CC_STAT_TOP),
                       stats.at<int>(label, cv::CC_STAT_WIDTH),
                       stats.at<int>(label, cv::CC_STAT_HEIGHT));
    VLOG(3) << "band paint component " << label << ": " << box.width << "x"
            << box.height << " px at " << box.x << "," << box.y;
    if (box.height < min_rows) continue;
    // Step 2: the run centre and width of each row.
    std::vector<Eigen::Vector2d> centres;  // (y, x)
    std::vector<double> widths;
    for (int y = box.y; y < box.y + box.height; ++y) {
      int lo = -1, hi = -1;
      for (int x = box.x; x < box.x + box.width; ++x) {
        if (labels.at<int>(y, x) != label) continue;
        if (lo < 0) lo = x;
        hi = x;
      }
      if (lo < 0) continue;
      centres.emplace_back(y, 0.5 * (lo + hi));
      widths.push_back(hi - lo + 1);
    }
    StraightFit axis;
    if (static_cast<int>(centres.size()) < min_rows ||
        !FitStraight(centres, &axis) ||
        std::abs(axis.c1) > options.max_axis_slope) {
      continue;
    }
    const double width = Median(widths);
    for (int outward : {-1, 1}) {
      BandEnd end;
      if (EndOfBand(image, valid, labels, label, box, axis.c0, axis.c1, width,
                    outward, options, &end)) {
        VLOG(3) << "band end at " << end.mid_px.transpose() << " outward "
                << outward;
        ends.push_back(end);
      }
    }
  }
  return ends;
}

std::vector<std::vector<int>> GroupCrossingEdges(
    const std::vector<BandEnd>& ends, double ground_pixel_m,
    const CrossingEdgeOptions& options) {
  std::vector<std::vector<int>> edges;
  const double gsd = ground_pixel_m;
  for (int outward : {-1, 1}) {
    std::vector<int> order;
    for (int i = 0; i < static_cast<int>(ends.size()); ++i) {
      if (ends[i].outward == outward) order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&ends](int i, int j) {
      return ends[i].mid_px.x() < ends[j].mid_px.x();
    });
    // Runs of neighbours, then the ends of a run on one line.
    size_t begin = 0;
    while (begin < order.size()) {
      size_t end = begin + 1;
      while (end < order.size() &&
             ends[order[end]].mid_px.x() - ends[order[end - 1]].mid_px.x() <=
                 options.max_band_gap_m / gsd) {
        ++end;
      }
      std::vector<int> group(order.begin() + begin, order.begin() + end);
      begin = end;
      while (static_cast<int>(group.size()) >= options.min_bands) {
        std::vector<Eigen::Vector2d> points;
        for (int i : group) points.push_back(ends[i].mid_px);
        StraightFit line;
        if (!FitStraight(points, &line)) break;
        if (line.max_residual > options.max_edge_residual_m / gsd) {
          group.erase(group.begin() + line.worst);
          continue;
        }
        // Each end's own direction is the edge's.
        const double angle = std::atan(line.c1);
        int worst = -1;
        double worst_angle = options.max_end_angle_rad;
        for (size_t k = 0; k < group.size(); ++k) {
          const double d =
              std::abs(std::atan(ends[group[k]].end_slope) - angle);
          if (d > worst_angle) {
            worst_angle = d;
            worst = static_cast<int>(k);
          }
        }
        if (worst >= 0) {
          group.erase(group.begin() + worst);
          continue;
        }
        VLOG(3) << "crossing edge of " << group.size() << " band ends";
        edges.push_back(group);
        break;
      }
    }
  }
  return edges;
}

}  // namespace zebrageo
