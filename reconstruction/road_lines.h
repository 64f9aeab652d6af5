// Road lines (lane lines and stop lines) from the stereo pairs of a survey:
// the bright-line extractor of the Ohio State GPS-Van (XVIIth ISPRS
// Congress 1992, part B3, "Extraction of road edges and center-lines",
// sections 3.1 to 3.3; ../shared/seeds/001_*.txt), GitHub issue 9.
//
// It runs on the road-plane rectified pair of reconstruction/ (see
// road_rectification.h): there the images are orthoimages of the road,
// lane lines run along the columns (the seed's "bright linear features
// which run from top to bottom"), stop lines along the rows, and a road
// point has the same pixel in both images. Per stereo pair:
//   1. per scan line, the mean and standard deviation of the gray values
//      (valid pixels only); a pixel is bright when the 5-pixel median around
//      it exceeds the mean by more than 1.5 standard deviations (binary
//      image); in a shadow across the road, where the paint is darker than
//      the sunlit asphalt that sets the mean, a local reference instead
//      (bright_lines.h); runs of bright pixels wider or narrower than a
//      painted line are cleared: zebra bands (0.5 m wide) are recognised
//      here and left to the zebra front-end;
//   2. thinning to one pixel (Zhang-Suen, OpenCV ximgproc);
//   3. line following by chain coding; chains under 10 pixels dropped;
//      chains joined across short breaks (a shadow's edge, worn paint);
//   4. interior points collinear with their neighbours dropped (the
//      polyline keeps a vertex at least every max_vertex_spacing_m, so the
//      3D line keeps its height profile);
//   5. stereo: each chain pixel's sub-pixel run centre on the left row is
//      matched with the one bright run of the same right row inside the
//      search volume (a slab around the road plane); triangulated to the
//      body frame with the covariance of the centres;
//   6. 3D vertices: the triangulated points around each polyline vertex,
//      averaged, with their covariance; the end vertices moved along the
//      line to where the paint ends at half contrast, so a dash's two ends
//      lie alike on its paint whatever the threshold and blur, and its
//      centre, an along-track control point, is unbiased.
// The scan lines of step 1 are image rows for lane lines; the same steps on
// the columns (the transposed image) give stop lines, which lie along the
// epipolar lines and so cannot be matched in stereo: their points are the
// left rays intersected with the road plane, the covariance carrying the
// plane's height uncertainty. The edges of zebra crossings seen in part
// (the seen ends of their bands, crossing_edges.h) are found in the same
// rectified pair (road_lines_edges.cc).
//
// Frames: body (FRD) metres for every 3D output; image coordinates of the
// outputs are pixels of the ORIGINAL (distorted) images, (0, 0) the centre
// of the top-left pixel.
#ifndef ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_H_
#define ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "reconstruction/bright_lines.h"
#include "reconstruction/crossing_edges.h"
#include "reconstruction/road_rectification.h"
#include "survey/cancellation.h"
#include "survey/results_lines.h"
#include "survey/rig.h"
#include "survey/survey.h"

namespace zebrageo {

struct RoadLineOptions {
  // Rectified road images for lines: coarser than for zebra vertices (a
  // 15 cm lane line is still 5 pixels wide) and shorter (heights from
  // stereo degrade with the square of the range).
  double ground_pixel_m = 0.03;
  double max_range_m = 16.0;
  double max_lateral_m = 8.0;
  // Step 1, the seed's values: median window (odd) and threshold.
  int median_window_px = 5;
  double threshold_sigmas = 1.5;
  // Robustness: the scan line's "mean and standard deviation" are its
  // median and 1.4826 x median absolute deviation; true: the seed's plain
  // mean and deviation, which the paint of zebra bands crossing the scan
  // line raises over a stop line's contrast.
  bool plain_statistics = false;
  // Lane lines in a shadow: the reference is the running median of this
  // much of the scan line around each pixel, with its own deviation
  // (bright_lines.h), where that median lies shadow_sigmas deviations
  // under the scan line's: a shadow across the road hides the paint inside
  // it from a reference set by the sunlit asphalt. Several times a lane
  // line's width, under a zebra band's period. The local deviation is bare
  // asphalt's, smaller than a whole scan line's, hence the higher
  // threshold. 0: the scan line's statistics everywhere, as the seed.
  double background_window_m = 1.2;
  double local_threshold_sigmas = 2.5;
  double shadow_sigmas = 1.5;
  // Widths of the bright runs kept across a lane line (along a row) and
  // across a stop line (along a column), metres on the road. Wider runs are
  // zebra bands or marks across the scan line; narrower ones noise.
  double min_line_width_m = 0.06;
  double max_line_width_m = 0.3;
  double min_stop_line_width_m = 0.18;
  // (A 0.3 m stop line 10 m ahead spans a few original pixels along the
  // road: blurred, its run is 0.5 m wide and more.)
  double max_stop_line_width_m = 0.9;
  // Paint lies on even ground: a run whose two sides differ by more than
  // this share of its contrast is the edge of something else (a kerb
  // between gutter and sidewalk, a sidewalk's tiles).
  double max_side_difference = 0.5;
  // Step 3: shorter chains are dropped (the seed's 10 pixels).
  int min_chain_px = 10;
  // Lane chains joined across breaks this short, when one continues the
  // other within max_break_offset_m (bright_lines.h): a shadow's edge across
  // a dash cuts it by about 0.45 m. Under the 1 m gaps of the shortest
  // dashed patterns. 0: no joining.
  double max_break_m = 0.6;
  double max_break_offset_m = 0.06;
  // A lane line's end vertices at its paint's end, half way in gray value
  // from the paint to the ground beyond (road_lines.cc), when that step is
  // at least min_end_contrast gray levels.
  bool half_contrast_ends = true;
  double min_end_contrast = 8.0;
  // Stop lines shorter than this across the road are dropped (the ends of
  // dashes and band sides cut by the image border look like short stop
  // lines).
  double min_stop_line_length_m = 0.8;
  // Step 4: a point closer than this to the chord of its neighbours is
  // collinear (Douglas-Peucker tolerance).
  double collinear_tolerance_px = 0.7;
  double max_vertex_spacing_m = 2.0;
  // Step 5: the search volume, a slab of this half-thickness around the
  // road plane.
  double max_height_off_road_m = 0.25;
  // Standard deviation of a run centre across the line, pixels; centres of
  // neighbouring rows are correlated over about `correlation_px` rows, which
  // bounds what averaging gains.
  double centre_sigma_px = 0.3;
  double correlation_px = 3.0;
  // Step 6: triangulated points within this many chain pixels of a vertex
  // are averaged into it; fewer than min_vertex_points: no vertex.
  int vertex_half_window_px = 8;
  int min_vertex_points = 4;
  // A lane chain whose both ends are inside the images and which is at
  // most this long is a dash; otherwise a solid line (or a dash seen in
  // part: the database tells them apart).
  double max_dash_length_m = 5.0;
  // Stop lines: height uncertainty of the road plane they are put on.
  double stop_line_height_sigma_m = 0.03;
  // The seen ends of zebra bands, one line per crossing edge
  // (crossing_edges.h), put on the road plane like stop lines.
  CrossingEdgeOptions crossing_edges;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("ground_pixel_m", ground_pixel_m);
    v("max_range_m", max_range_m);
    v("max_lateral_m", max_lateral_m);
    v("median_window_px", median_window_px);
    v("threshold_sigmas", threshold_sigmas);
    v("plain_statistics", plain_statistics);
    v("background_window_m", background_window_m);
    v("local_threshold_sigmas", local_threshold_sigmas);
    v("shadow_sigmas", shadow_sigmas);
    v("min_line_width_m", min_line_width_m);
    v("max_line_width_m", max_line_width_m);
    v("min_stop_line_width_m", min_stop_line_width_m);
    v("max_stop_line_width_m", max_stop_line_width_m);
    v("max_side_difference", max_side_difference);
    v("min_chain_px", min_chain_px);
    v("max_break_m", max_break_m);
    v("max_break_offset_m", max_break_offset_m);
    v("half_contrast_ends", half_contrast_ends);
    v("min_end_contrast", min_end_contrast);
    v("min_stop_line_length_m", min_stop_line_length_m);
    v("collinear_tolerance_px", collinear_tolerance_px);
    v("max_vertex_spacing_m", max_vertex_spacing_m);
    v("max_height_off_road_m", max_height_off_road_m);
    v("centre_sigma_px", centre_sigma_px);
    v("correlation_px", correlation_px);
    v("vertex_half_window_px", vertex_half_window_px);
    v("min_vertex_points", min_vertex_points);
    v("max_dash_length_m", max_dash_length_m);
    v("stop_line_height_sigma_m", stop_line_height_sigma_m);
    v("crossing_edges", crossing_edges);
  }
};

// --- A stereo pair -----------------------------------------------------------

// RoadLineType and RoadLineTypeName: survey/results_lines.h (the contract
// of reconstructed_lines.csv).

struct RoadLine3d {
  RoadLineType type = RoadLineType::kLaneSolid;
  std::vector<Eigen::Vector3d> points_body;
  std::vector<Eigen::Matrix3d> covariances_body;
  std::vector<Eigen::Vector2d> uv_left;   // original image pixels
  std::vector<Eigen::Vector2d> uv_right;  // (NaN-free: projected)
};

struct PairLines {
  std::vector<RoadLine3d> lines;
  int chains = 0;          // after step 3 (lanes and stop lines)
  int wide_runs = 0;       // row runs too wide for a lane line (bands...)
  int matched_pixels = 0;  // lane chain pixels matched in stereo
  double seconds = 0.0;    // CPU time of the calling thread
};

class StereoLineExtractor {
 public:
  // `road`: the road plane in the body frame (the zebra front-end's
  // estimate). Check ok() before use.
  StereoLineExtractor(const RigCamera& left, const RigCamera& right,
                      const RoadPlane& road, const RoadLineOptions& options);
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const RoadRectification& rectification() const { return rectification_; }

  // Runs steps 1 to 6 on two original CV_32F images.
  PairLines Extract(const cv::Mat& left_image,
                    const cv::Mat& right_image) const;

 private:
  void LaneLines(const cv::Mat& left, const cv::Mat& right,
                 PairLines* out) const;
  void StopLines(const cv::Mat& left, PairLines* out) const;
  // The centre of the one bright run of `bright_right` in row y inside the
  // search volume of the left centre x_left (step 5).
  bool RightRunCentre(const cv::Mat& right, const cv::Mat& bright_right,
                      double x_left, int y, int max_px, double* x_right) const;
  void CrossingEdges(const cv::Mat& left, const cv::Mat& right,
                     PairLines* out) const;
  // Keeps the points of `line` whose height over the road plane is within
  // max_difference_m of their median (two: within half of it of their
  // mean).
  void DropEndsOffTheRoad(double max_difference_m, RoadLine3d* line) const;
  // A band end's point in 3D: the band's centre line triangulated over the
  // rows inside its end, extrapolated to the end (crossing_edges.h).
  bool StereoEndPoint(const BandEnd& end, const cv::Mat* images,
                      const cv::Mat* paint, Eigen::Vector3d* p,
                      Eigen::Matrix3d* covariance) const;
  bool Finish(RoadLine3d* line) const;  // uv, false if not projectable

  RigCamera cameras_[2];
  RoadPlane road_;
  RoadLineOptions options_;
  RoadRectification rectification_;
  std::string error_;
};

// --- A survey ----------------------------------------------------------------

// ReconstructedLinePoint, kReconstructedLinesFile and the reader and writer
// of reconstructed_lines.csv: survey/results_lines.h.

struct RoadLineSummary {
  int pairs = 0;
  int lines = 0;
  int lines_of_type[kRoadLineTypes] = {0, 0, 0, 0};
  int points = 0;
  double seconds_per_pair = 0.0;  // CPU
  std::string BriefReport() const;
};

// Extracts the lines of every stereo pair of every exposure (threads: 0 =
// one per hardware thread), in a deterministic order.
RoadLineSummary ExtractSurveyLines(
    const Survey& survey, const RoadPlane& road, const RoadLineOptions& options,
    int threads, std::vector<ReconstructedLinePoint>* points,
    const std::function<void(int, int)>& progress = nullptr,
    const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_ROAD_LINES_H_
