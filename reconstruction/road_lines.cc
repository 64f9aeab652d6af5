#include "reconstruction/road_lines.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <ctime>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "survey/image_io.h"
#include "survey/option_check.h"
#include "survey/threads.h"

namespace zebrageo {
namespace {

// True when every pixel within `radius` of p is valid: the end of a chain
// there is the end of the painted line, not of the image.
bool InsideValid(const cv::Mat& valid, const cv::Point& p, int radius) {
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      if (!IsSet(valid, p.x + dx, p.y + dy)) return false;
    }
  }
  return true;
}

// Rows of paint beyond a chain's end pixel `end`, away from `inner` (a
// chain pixel a few steps in), in the bright mask: what the thinning took
// off that end. Zhang-Suen's thinning is not symmetric (its first
// sub-iteration takes the south and east boundary pixels), so a dash came
// out about a pixel shorter at one end than at the other: on rendered
// surveys its near end lay 0.21 m inside the paint and its far end
// 0.18 m, which put the dash's centre, an along-track control point
// (registration/dash_matcher.h), 1.5 cm forward.
int ThinnedAwayRows(const cv::Mat& bright, const cv::Point& end,
                    const cv::Point& inner) {
  constexpr int kMaxRows = 10;
  const int dy = end.y > inner.y ? 1 : (end.y < inner.y ? -1 : 0);
  if (dy == 0) return 0;
  int x = end.x;
  int rows = 0;
  for (int y = end.y + dy; rows < kMaxRows; y += dy) {
    int next = -1;
    for (int dx : {0, -1, 1}) {
      if (IsSet(bright, x + dx, y)) {
        next = x + dx;
        break;
      }
    }
    if (next < 0) break;
    x = next;
    ++rows;
  }
  return rows;
}

// A triangulated chain pixel.
struct ChainPoint {
  int index = 0;  // in the chain
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// Step 6: the points within half_window chain pixels of each kept index,
// averaged. Centres of neighbouring pixels are correlated over
// correlation_px pixels, so n points count as n / correlation_px.
void AverageVertices(const std::vector<ChainPoint>& points,
                     const std::vector<int>& kept,
                     const RoadLineOptions& options, RoadLine3d* line) {
  size_t begin = 0;
  for (int k : kept) {
    while (begin < points.size() &&
           points[begin].index < k - options.vertex_half_window_px) {
      ++begin;
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    int n = 0;
    for (size_t j = begin; j < points.size() &&
                           points[j].index <= k + options.vertex_half_window_px;
         ++j) {
      sum += points[j].p;
      covariance += points[j].covariance;
      ++n;
    }
    if (n < options.min_vertex_points) continue;
    const double effective = std::max(1.0, n / options.correlation_px);
    line->points_body.push_back(sum / n);
    line->covariances_body.push_back(covariance / n / effective);
  }
}

// Moves the end vertices of a lane line outwards by the rows the thinning
// took off each end of its chain (ThinnedAwayRows; gsd metres per row, the
// line running along the columns), so both ends lie alike inside the
// paint (by the vertex averaging's one-sided window).
void RestoreThinnedEnds(const cv::Mat& bright,
                        const std::vector<cv::Point>& chain, double gsd,
                        RoadLine3d* line) {
  std::vector<Eigen::Vector3d>& p = line->points_body;
  if (p.size() < 2 || chain.size() < 4) return;
  const size_t k = 3;
  const int front = ThinnedAwayRows(bright, chain.front(), chain[k]);
  const int back =
      ThinnedAwayRows(bright, chain.back(), chain[chain.size() - 1 - k]);
  const Eigen::Vector3d out_front = (p.front() - p[1]).normalized();
  const Eigen::Vector3d out_back = (p.back() - p[p.size() - 2]).normalized();
  p.front() += front * gsd * out_front;
  p.back() += back * gsd * out_back;
}

// Moves each end vertex of a lane line along the line to where its paint
// ends at half contrast (HalfContrastEndRow), when the profile shows it;
// otherwise leaves it (RestoreThinnedEnds put it there).
void EndsAtHalfContrast(const cv::Mat& image, const cv::Mat& valid,
                        const std::vector<cv::Point>& chain,
                        const RoadRectification& rect, double min_contrast,
                        RoadLine3d* line) {
  std::vector<Eigen::Vector3d>& p = line->points_body;
  if (p.size() < 2) return;
  for (int outward : {-1, 1}) {
    // Chains run top to bottom or bottom to top: which end is which row.
    const bool front_is_top = chain.front().y <= chain.back().y;
    const bool at_front = (outward < 0) == front_is_top;
    Eigen::Vector3d& vertex = at_front ? p.front() : p.back();
    const Eigen::Vector3d& inner = at_front ? p[1] : p[p.size() - 2];
    const double end_row =
        HalfContrastEndRow(image, valid, chain, outward, min_contrast);
    Eigen::Vector2d xy_vertex, xy_inner;
    if (!std::isfinite(end_row) ||
        !rect.ProjectToRectified(0, vertex, &xy_vertex) ||
        !rect.ProjectToRectified(0, inner, &xy_inner) ||
        std::abs(xy_vertex.y() - xy_inner.y()) < 1.0) {
      continue;
    }
    // The vertex slides along the line to the row of the paint's end.
    const double t = (end_row - xy_vertex.y()) / (xy_vertex.y() - xy_inner.y());
    if (std::abs(t * (xy_vertex.y() - xy_inner.y())) > 15.0) continue;
    vertex += t * (vertex - inner);
  }
}

double PolylineLength(const std::vector<Eigen::Vector3d>& points) {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) {
    length += (points[i] - points[i - 1]).norm();
  }
  return length;
}

}  // namespace

std::string RoadLineOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, ground_pixel_m, "(", 0.002, 0.2, ")");
  OPTION_GT(check, max_range_m, 1.0);
  OPTION_GT(check, max_lateral_m, 0.5);
  OPTION_GE(check, median_window_px, 1);
  OPTION_REQUIRE(check, median_window_px % 2 == 1, median_window_px,
                 "must be odd");
  OPTION_REQUIRE(check,
                 background_window_m == 0.0 ||
                     (background_window_m >= 2.0 * max_line_width_m &&
                      background_window_m <= 10.0),
                 background_window_m,
                 "must be 0 or in [2 x max_line_width_m, 10]");
  OPTION_IN(check, max_break_m, "[", 0.0, 2.0, "]");
  OPTION_IN(check, max_break_offset_m, "(", 0.0, 0.5, "]");
  OPTION_GE(check, min_end_contrast, 0.0);
  OPTION_GT(check, local_threshold_sigmas, 0.0);
  OPTION_GT(check, shadow_sigmas, 0.0);
  OPTION_GT(check, threshold_sigmas, 0.0);
  OPTION_GT(check, min_line_width_m, 0.0);
  OPTION_GT(check, max_line_width_m, min_line_width_m);
  OPTION_GT(check, min_stop_line_width_m, 0.0);
  OPTION_GT(check, max_stop_line_width_m, min_stop_line_width_m);
  OPTION_GT(check, max_side_difference, 0.0);
  OPTION_GE(check, min_chain_px, 2);
  OPTION_GE(check, min_stop_line_length_m, 0.0);
  OPTION_GT(check, collinear_tolerance_px, 0.0);
  OPTION_GT(check, max_vertex_spacing_m, ground_pixel_m);
  OPTION_GT(check, max_height_off_road_m, 0.0);
  OPTION_GT(check, centre_sigma_px, 0.0);
  OPTION_GE(check, correlation_px, 1.0);
  OPTION_GE(check, vertex_half_window_px, 0);
  OPTION_GE(check, min_vertex_points, 1);
  OPTION_GT(check, max_dash_length_m, 0.0);
  OPTION_GT(check, stop_line_height_sigma_m, 0.0);
  if (crossing_edges.enabled) OPTION_NESTED(check, crossing_edges);
  return check.problem();
}

StereoLineExtractor::StereoLineExtractor(const RigCamera& left,
                                         const RigCamera& right,
                                         const RoadPlane& road,
                                         const RoadLineOptions& options)
    : cameras_{left, right}, road_(road), options_(options) {
  error_ = options.Check();
  if (!error_.empty()) return;
  RectificationOptions rectification;
  rectification.ground_pixel_m = options.ground_pixel_m;
  rectification.max_range_m = options.max_range_m;
  rectification.max_lateral_m = options.max_lateral_m;
  rectification_.Build(left, right, road, rectification, &error_);
}

PairLines StereoLineExtractor::Extract(const cv::Mat& left_image,
                                       const cv::Mat& right_image) const {
  const double start = ThreadCpuSeconds();
  PairLines out;
  cv::Mat left, right;
  rectification_.Rectify(left_image, right_image, &left, &right);
  LaneLines(left, right, &out);
  StopLines(left, &out);
  if (options_.crossing_edges.enabled) CrossingEdges(left, right, &out);
  out.seconds = ThreadCpuSeconds() - start;
  return out;
}

void StereoLineExtractor::LaneLines(const cv::Mat& left, const cv::Mat& right,
                                    PairLines* out) const {
  const RoadRectification& rect = rectification_;
  const cv::Mat& valid = rect.valid_mask();
  const double gsd = rect.ground_pixel_m();
  const int min_px = std::max(
      1, static_cast<int>(std::floor(options_.min_line_width_m / gsd)));
  const int max_px =
      static_cast<int>(std::ceil(options_.max_line_width_m / gsd));
  const int background_px =
      static_cast<int>(std::lround(options_.background_window_m / gsd));
  cv::Mat bright[2];
  const cv::Mat* images[2] = {&left, &right};
  for (int side = 0; side < 2; ++side) {
    bright[side] = BrightLinePixels(
        *images[side], valid, options_.median_window_px,
        options_.threshold_sigmas, options_.plain_statistics, background_px,
        options_.local_threshold_sigmas, options_.shadow_sigmas);
    const int wide = KeepRunsByWidth(valid, min_px, max_px, &bright[side]);
    KeepRunsOnEvenGround(*images[side], options_.max_side_difference,
                         &bright[side]);
    if (side == 0) out->wide_runs = wide;
  }
  std::vector<std::vector<cv::Point>> chains =
      FollowChains(ThinLines(bright[0]), options_.min_chain_px);
  out->chains += static_cast<int>(chains.size());
  if (options_.max_break_m > 0.0) {
    chains = JoinChainsAcrossBreaks(
        std::move(chains),
        static_cast<int>(std::lround(options_.max_break_m / gsd)),
        options_.max_break_offset_m / gsd);
  }
  const double sigma2 = options_.centre_sigma_px * options_.centre_sigma_px;
  const Eigen::Vector3d pixel_variance(sigma2, sigma2, sigma2);
  const int spacing_px = static_cast<int>(options_.max_vertex_spacing_m / gsd);
  for (const std::vector<cv::Point>& chain : chains) {
    if (!RunsAcrossRows(chain)) continue;
    std::vector<ChainPoint> points;
    for (int i = 0; i < static_cast<int>(chain.size()); ++i) {
      const int y = chain[i].y;
      double x_left = 0.0, x_right = 0.0;
      if (!RunCentre(left, bright[0], y, chain[i].x, &x_left) ||
          !RightRunCentre(right, bright[1], x_left, y, max_px, &x_right)) {
        continue;
      }
      ChainPoint point;
      point.index = i;
      if (!rect.Triangulate(x_left, x_right, y, &point.p)) continue;
      const Eigen::Matrix3d J = rect.TriangulationJacobian(x_left, x_right, y);
      point.covariance = J * pixel_variance.asDiagonal() * J.transpose();
      points.push_back(point);
    }
    out->matched_pixels += static_cast<int>(points.size());
    RoadLine3d line;
    AverageVertices(
        points,
        DropCollinearPoints(chain, options_.collinear_tolerance_px, spacing_px),
        options_, &line);
    if (line.points_body.size() < 2) continue;
    RestoreThinnedEnds(bright[0], chain, gsd, &line);
    if (options_.half_contrast_ends) {
      EndsAtHalfContrast(left, valid, chain, rect, options_.min_end_contrast,
                         &line);
    }
    const int margin = options_.median_window_px;
    const bool ends_seen = InsideValid(valid, chain.front(), margin) &&
                           InsideValid(valid, chain.back(), margin);
    line.type = ends_seen && PolylineLength(line.points_body) <=
                                 options_.max_dash_length_m
                    ? RoadLineType::kLaneDashed
                    : RoadLineType::kLaneSolid;
    if (Finish(&line)) out->lines.push_back(std::move(line));
  }
}

bool StereoLineExtractor::RightRunCentre(const cv::Mat& right,
                                         const cv::Mat& bright_right,
                                         double x_left, int y, int max_px,
                                         double* x_right) const {
  const RoadRectification& rect = rectification_;
  const double h = options_.max_height_off_road_m;
  // The search volume: the residual disparities of the slab.
  Eigen::Vector3d on_road;
  if (!road_.IntersectRay(rect.left_centre_body(),
                          rect.RayBody(0, Eigen::Vector2d(x_left, y)),
                          &on_road)) {
    return false;
  }
  const double d1 = rect.DisparityOf(on_road - h * road_.normal_body);
  const double d2 = rect.DisparityOf(on_road + h * road_.normal_body);
  if (!std::isfinite(d1) || !std::isfinite(d2)) return false;
  const double lo = x_left - std::max(d1, d2);
  const double hi = x_left - std::min(d1, d2);
  // The one right run whose centre is in [lo, hi].
  const uint8_t* b = bright_right.ptr<uint8_t>(y);
  int found = 0;
  const int from = std::max(0, static_cast<int>(std::floor(lo)) - max_px);
  const int to =
      std::min(right.cols - 1, static_cast<int>(std::ceil(hi)) + max_px);
  for (int x = from; x <= to; ++x) {
    if (b[x] == 0 || (x > from && b[x - 1] != 0)) continue;
    double centre = 0.0;
    if (RunCentre(right, bright_right, y, x, &centre) && centre >= lo &&
        centre <= hi) {
      ++found;
      *x_right = centre;
    }
  }
  return found == 1;
}

void StereoLineExtractor::StopLines(const cv::Mat& left, PairLines* out) const {
  const RoadRectification& rect = rectification_;
  const double gsd = rect.ground_pixel_m();
  // Stop lines run along the rows: the scan lines are the columns.
  cv::Mat image, valid;
  cv::transpose(left, image);
  cv::transpose(rect.valid_mask(), valid);
  cv::Mat bright =
      BrightLinePixels(image, valid, options_.median_window_px,
                       options_.threshold_sigmas, options_.plain_statistics);
  KeepRunsByWidth(
      valid,
      std::max(1, static_cast<int>(
                      std::floor(options_.min_stop_line_width_m / gsd))),
      static_cast<int>(std::ceil(options_.max_stop_line_width_m / gsd)),
      &bright);
  KeepRunsOnEvenGround(image, options_.max_side_difference, &bright);
  const int min_length_px =
      std::max(options_.min_chain_px,
               static_cast<int>(options_.min_stop_line_length_m / gsd));
  const std::vector<std::vector<cv::Point>> chains =
      FollowChains(ThinLines(bright), min_length_px);
  out->chains += static_cast<int>(chains.size());
  // On the road plane one rectified pixel is gsd metres; across the line
  // (rectified y) the centre's error, along the normal the plane's.
  const Eigen::Vector3d across = rect.R_body_virt().col(1);
  const Eigen::Vector3d along = rect.R_body_virt().col(0);
  const double s = gsd * options_.centre_sigma_px;
  const Eigen::Matrix3d image_covariance =
      s * s * (across * across.transpose() + along * along.transpose());
  const double sh = options_.stop_line_height_sigma_m;
  const Eigen::Matrix3d height_covariance =
      sh * sh * road_.normal_body * road_.normal_body.transpose();
  const int spacing_px = static_cast<int>(options_.max_vertex_spacing_m / gsd);
  for (const std::vector<cv::Point>& chain : chains) {
    if (!RunsAcrossRows(chain)) continue;
    std::vector<ChainPoint> points;
    for (int i = 0; i < static_cast<int>(chain.size()); ++i) {
      // Transposed: the chain's row is the rectified column.
      double y = 0.0;
      if (!RunCentre(image, bright, chain[i].y, chain[i].x, &y)) continue;
      ChainPoint point;
      point.index = i;
      if (!road_.IntersectRay(rect.left_centre_body(),
                              rect.RayBody(0, Eigen::Vector2d(chain[i].y, y)),
                              &point.p)) {
        continue;
      }
      point.covariance = image_covariance;
      points.push_back(point);
    }
    RoadLine3d line;
    line.type = RoadLineType::kStopLine;
    AverageVertices(
        points,
        DropCollinearPoints(chain, options_.collinear_tolerance_px, spacing_px),
        options_, &line);
    if (line.points_body.size() < 2 ||
        PolylineLength(line.points_body) < options_.min_stop_line_length_m) {
      continue;
    }
    // The plane's height error is common to all points: not averaged.
    for (Eigen::Matrix3d& c : line.covariances_body) c += height_covariance;
    if (Finish(&line)) out->lines.push_back(std::move(line));
  }
}

bool StereoLineExtractor::Finish(RoadLine3d* line) const {
  for (const Eigen::Vector3d& p : line->points_body) {
    Eigen::Vector2d uv[2];
    for (int side = 0; side < 2; ++side) {
      if (!cameras_[side].camera.Project(
              cameras_[side].T_body_cam.inverse() * p, &uv[side])) {
        return false;
      }
    }
    line->uv_left.push_back(uv[0]);
    line->uv_right.push_back(uv[1]);
  }
  return true;
}

std::string RoadLineSummary::BriefReport() const {
  std::ostringstream out;
  out << lines << " road lines (" << lines_of_type[0] << " solid, "
      << lines_of_type[1] << " dashed, " << lines_of_type[2] << " stop lines, "
      << lines_of_type[3] << " crossing edges), " << points << " points from "
      << pairs << " stereo pairs, " << 1e3 * seconds_per_pair
      << " ms CPU per pair";
  return out.str();
}

RoadLineSummary ExtractSurveyLines(
    const Survey& survey, const RoadPlane& road, const RoadLineOptions& options,
    int threads, std::vector<ReconstructedLinePoint>* points,
    const std::function<void(int, int)>& progress,
    const CancellationToken& cancel) {
  RoadLineSummary summary;
  const Rig& rig = survey.rig;
  std::vector<std::unique_ptr<StereoLineExtractor>> extractors;
  for (const auto& pair : rig.stereo_pairs) {
    auto extractor = std::make_unique<StereoLineExtractor>(
        rig.cameras[pair[0]], rig.cameras[pair[1]], road, options);
    if (!extractor->ok()) {
      LOG(WARNING) << "road lines: a stereo pair cannot be rectified: "
                   << extractor->error();
      extractor.reset();
    }
    extractors.push_back(std::move(extractor));
  }
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  const int total = static_cast<int>(exposures.size());
  // results[e][p]: the lines of pair p of exposure e (empty when the
  // images are missing: the zebra stage already warned).
  std::vector<std::vector<PairLines>> results(total);
  std::vector<std::vector<bool>> ran(total);
  std::mutex progress_mutex;
  int done = 0;
  if (threads <= 0) {
    threads =
        std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  }
  PrepareImageCodecs();  // before the worker threads read images
  ParallelFor(total, threads, [&](int e) {
    cancel.ThrowIfCancelled();  // between exposures
    const Exposure& exposure = exposures[e];
    results[e].resize(extractors.size());
    ran[e].assign(extractors.size(), false);
    for (size_t p = 0; p < extractors.size(); ++p) {
      if (!extractors[p]) continue;
      cv::Mat images[2];
      bool read = true;
      for (int side = 0; side < 2 && read; ++side) {
        const int camera = rig.stereo_pairs[p][side];
        const int index = exposure.image_of_camera[camera];
        if (index < 0) {
          read = false;
          break;
        }
        const ExposureImage& image = survey.exposures.images[index];
        try {
          images[side] = ReadGrayImage(survey.PathOf(image.image), image.image,
                                       rig.cameras[camera].camera.width(),
                                       rig.cameras[camera].camera.height());
        } catch (const std::exception&) {
          read = false;
        }
      }
      if (!read) continue;
      VLOG(3) << "road lines: exposure " << exposure.exposure_id << " pair "
              << p;
      results[e][p] = extractors[p]->Extract(images[0], images[1]);
      ran[e][p] = true;
    }
    if (progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress(++done, total);
    }
  });
  double seconds = 0.0;
  int64_t line_id = 0;
  for (int e = 0; e < total; ++e) {
    for (size_t p = 0; p < results[e].size(); ++p) {
      if (!ran[e][p]) continue;
      ++summary.pairs;
      seconds += results[e][p].seconds;
      for (const RoadLine3d& line : results[e][p].lines) {
        ++line_id;
        ++summary.lines;
        ++summary.lines_of_type[static_cast<int>(line.type)];
        for (size_t k = 0; k < line.points_body.size(); ++k) {
          ReconstructedLinePoint point;
          point.exposure_id = exposures[e].exposure_id;
          point.pair = static_cast<int>(p);
          point.line_id = line_id;
          point.type = line.type;
          point.point = static_cast<int>(k);
          point.p_body = line.points_body[k];
          point.covariance_body = line.covariances_body[k];
          point.uv_left = line.uv_left[k];
          point.uv_right = line.uv_right[k];
          points->push_back(point);
          ++summary.points;
        }
      }
    }
  }
  summary.seconds_per_pair = seconds / std::max(1, summary.pairs);
  return summary;
}

}  // namespace zebrageo
