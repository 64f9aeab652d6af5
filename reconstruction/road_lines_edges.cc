// The crossing edges of a stereo pair (crossing_edges.h): the band ends
// found in the left rectified image, each put in 3D by the band's centre
// line triangulated inside it, and ordered with the paint on their left.
// StereoLineExtractor's methods for them (road_lines.h).
#include <glog/logging.h>

#include <algorithm>
#include <cmath>

#include "reconstruction/road_lines.h"
#include "survey/math_util.h"

namespace zebrageo {

bool StereoLineExtractor::StereoEndPoint(const BandEnd& end,
                                         const cv::Mat* images,
                                         const cv::Mat* paint,
                                         Eigen::Vector3d* p,
                                         Eigen::Matrix3d* covariance) const {
  const RoadRectification& rect = rectification_;
  const double gsd = rect.ground_pixel_m();
  const CrossingEdgeOptions& options = options_.crossing_edges;
  const int max_px =
      static_cast<int>(std::ceil(options.max_band_width_m / gsd));
  // Rows whole across the band: past the corner of a slanted end.
  const int first = static_cast<int>(std::ceil(0.5 * std::abs(end.end_slope) *
                                               end.width_px)) +
                    3;
  const int last = first + static_cast<int>(options.stereo_length_m / gsd);
  std::vector<double> rows;
  std::vector<Eigen::Vector3d> points;
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (int k = first; k <= last; ++k) {
    const int y =
        static_cast<int>(std::lround(end.mid_px.y())) - end.outward * k;
    if (y < 0 || y >= images[0].rows) break;
    const double x_axis =
        end.mid_px.x() + end.axis_slope * (y - end.mid_px.y());
    double x_left = 0.0, x_right = 0.0;
    Eigen::Vector3d q;
    if (!RunCentre(images[0], paint[0], y,
                   static_cast<int>(std::lround(x_axis)), &x_left) ||
        std::abs(x_left - x_axis) > 0.25 * end.width_px ||
        !RightRunCentre(images[1], paint[1], x_left, y, max_px, &x_right) ||
        !rect.Triangulate(x_left, x_right, y, &q)) {
      continue;
    }
    if (rows.empty()) J = rect.TriangulationJacobian(x_left, x_right, y);
    rows.push_back(y - end.mid_px.y());
    points.push_back(q);
  }
  const int n = static_cast<int>(rows.size());
  if (n < options.min_stereo_rows) return false;
  // p(row) = p0 + v row, each coordinate by least squares: p0 at the end.
  double sr = 0, srr = 0;
  Eigen::Vector3d sp = Eigen::Vector3d::Zero(), srp = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    sr += rows[i];
    srr += rows[i] * rows[i];
    sp += points[i];
    srp += rows[i] * points[i];
  }
  const double det = n * srr - sr * sr;
  if (!(det > 1e-9)) return false;
  const Eigen::Vector3d v = (n * srp - sr * sp) / det;
  const Eigen::Vector3d p0 = (sp - v * sr) / n;
  double sum_squares = 0.0;
  for (int i = 0; i < n; ++i) {
    sum_squares += (points[i] - p0 - v * rows[i]).squaredNorm();
  }
  if (std::sqrt(sum_squares / n) > options.max_axis_rms_m) return false;
  *p = p0;
  // The centres' triangulation error, averaged over the rows (correlated
  // over correlation_px) and extrapolated to the end (the mean row is
  // about half the span in), plus the end's own error in the image plane.
  const double s2 = options_.centre_sigma_px * options_.centre_sigma_px;
  const double effective = std::max(1.0, n / options_.correlation_px);
  const double mean_row = sr / n;
  const double leverage = 1.0 + mean_row * mean_row * n / (srr - sr * mean_row);
  const Eigen::Vector3d across = rect.R_body_virt().col(1);
  const Eigen::Vector3d along = rect.R_body_virt().col(0);
  const double se = gsd * options.end_sigma_px;
  *covariance =
      J * (s2 * Eigen::Matrix3d::Identity()) * J.transpose() *
          (leverage / effective) +
      se * se * (across * across.transpose() + along * along.transpose());
  return true;
}

void StereoLineExtractor::DropEndsOffTheRoad(double max_difference_m,
                                             RoadLine3d* line) const {
  std::vector<double> heights;
  for (const Eigen::Vector3d& p : line->points_body) {
    heights.push_back(road_.SignedDistance(p));
  }
  if (heights.empty()) return;
  // Two ends: both go when they differ (neither is known right).
  const double median =
      heights.size() == 2 ? 0.5 * (heights[0] + heights[1]) : Median(heights);
  const double tolerance =
      heights.size() == 2 ? 0.5 * max_difference_m : max_difference_m;
  RoadLine3d kept;
  kept.type = line->type;
  for (size_t k = 0; k < heights.size(); ++k) {
    if (std::abs(heights[k] - median) <= tolerance) {
      kept.points_body.push_back(line->points_body[k]);
      kept.covariances_body.push_back(line->covariances_body[k]);
    }
  }
  *line = std::move(kept);
}

void StereoLineExtractor::CrossingEdges(const cv::Mat& left,
                                        const cv::Mat& right,
                                        PairLines* out) const {
  const RoadRectification& rect = rectification_;
  const double gsd = rect.ground_pixel_m();
  const CrossingEdgeOptions& options = options_.crossing_edges;
  const cv::Mat images[2] = {left, right};
  const cv::Mat paint[2] = {
      BandPaintPixels(left, rect.valid_mask(), gsd, options),
      BandPaintPixels(right, rect.valid_mask(), gsd, options)};
  const std::vector<BandEnd> ends =
      FindBandEnds(left, rect.valid_mask(), paint[0], gsd, options);
  for (const std::vector<int>& edge : GroupCrossingEdges(ends, gsd, options)) {
    RoadLine3d line;
    line.type = RoadLineType::kCrossingEdge;
    for (int i : edge) {
      Eigen::Vector3d p;
      Eigen::Matrix3d covariance;
      if (!StereoEndPoint(ends[i], images, paint, &p, &covariance)) {
        VLOG(3) << "crossing edge: band end at " << ends[i].mid_px.transpose()
                << " not seen in stereo";
        continue;
      }
      const Eigen::Vector3d from_camera = p - rect.left_centre_body();
      if (from_camera.head<2>().norm() > options.max_end_range_m) continue;
      line.points_body.push_back(p);
      line.covariances_body.push_back(covariance);
    }
    // A right run mismatched puts an end off the road's surface, and so
    // along the road: the ends agree in height above the road plane.
    DropEndsOffTheRoad(options.max_end_height_difference_m, &line);
    // The ends were found on one line in the left image; two seen in
    // stereo place it (the right camera may not see the others).
    if (line.points_body.size() < 2) continue;
    // Order the points so that, seen from above, the paint lies to their
    // left (results_lines.h). In FRD seen from above, left of (dx, dy) is
    // (dy, -dx). The paint lies inwards of the ends, which the rectified
    // image's rows give (y grows towards the vehicle, along -x of the body
    // when the rig looks forward; the rectification's axes say exactly).
    const Eigen::Vector3d paint_direction =
        -ends[edge.front()].outward * rect.R_body_virt().col(1);
    const Eigen::Vector3d d =
        line.points_body.back() - line.points_body.front();
    if (d.y() * paint_direction.x() - d.x() * paint_direction.y() < 0.0) {
      std::reverse(line.points_body.begin(), line.points_body.end());
      std::reverse(line.covariances_body.begin(), line.covariances_body.end());
    }
    if (Finish(&line)) out->lines.push_back(std::move(line));
  }
}

}  // namespace zebrageo
