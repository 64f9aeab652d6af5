// The edges of a zebra crossing from the seen ends of its bands, in the
// road-plane rectified left image (road_rectification.h), issue 17.
//
// A camera pitched steeply down with exposures far apart may never see a
// band whole: each image holds the crossing's far (or near) end, its bands
// cut by the image border at the other. The zebra front-end models whole
// bands only (a band's vertices need both ends, hidden_ends.h needs a
// fully seen band of the same crossing), so such a crossing gave no
// control at all, and the along-track error stayed unobservable. The ends
// that are seen lie on one line across the bands, the crossing's edge, and
// the road-mark database holds that line too (the ends of its bands): a
// line across the road, which holds the position across it, that is along
// the track. Steps:
//   1. paint: pixels brighter than the darkest of their row within
//      box_window_m (about a band period: the ground, sunlit or in a
//      shadow) by min_contrast and nearer the brightest than the darkest,
//      in runs of a band's width on even ground;
//   2. bands: connected runs at least min_band_length_m long, their centre
//      line x = a + b y fitted;
//   3. ends: in each column of a band near its top and bottom rows, the row
//      where the paint falls to half contrast (HalfContrastEndRow), so the
//      ground beyond must be in view: a band cut by the image border has
//      no end there; a straight line fitted through them;
//   4. edges: ends of the same orientation, side by side, on one straight
//      line (max_edge_residual_m) whose direction each end's own line
//      shares: at least min_bands of them.
// What is returned is in rectified pixels; road_lines.cc puts the ends on
// the road plane.
//
// Frames: rectified image pixels (x along the baseline, y increasing
// towards the vehicle).
#ifndef ZEBRAGEO_RECONSTRUCTION_CROSSING_EDGES_H_
#define ZEBRAGEO_RECONSTRUCTION_CROSSING_EDGES_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace zebrageo {

struct CrossingEdgeOptions {
  bool enabled = true;
  // Step 1. A band's run across a row: its width (0.4-0.6 m), wider when
  // the crossing is skewed by up to 30 degrees.
  double box_window_m = 1.2;
  double min_contrast = 20.0;  // gray levels
  double min_band_width_m = 0.3;
  double max_band_width_m = 0.9;
  // A run whose ground on its two sides differs by more than this share of
  // its contrast is not paint (KeepRunsOnEvenGround): the sunlit side of a
  // shadow's edge.
  double max_side_difference = 0.5;
  // Step 2.
  double min_band_length_m = 0.6;
  // Bands run along the road: their centre line's dx/dy in the image.
  double max_axis_slope = 0.6;
  // Step 3: an end across its band, up to 40 degrees off square (skewed
  // crossings), straight within max_end_rms_px, over min_end_columns.
  double max_end_slope = 0.85;
  double max_end_rms_px = 1.5;
  int min_end_columns = 5;
  // Step 4.
  int min_bands = 3;
  double max_band_gap_m = 2.2;  // between neighbouring bands' centres
  double max_edge_residual_m = 0.05;
  double max_end_angle_rad = 0.2;
  // Standard deviation of an end's position across the edge, pixels.
  double end_sigma_px = 0.5;
  // 3D: the band's centre line triangulated over this much of the band
  // inside its end (at least min_stereo_rows rows matched in stereo, within
  // max_axis_rms_m of a straight line), extrapolated to the end. One road
  // plane for the whole image would not do: 2 cm of crown or camber under
  // an end 7 m ahead of a camera 1.8 m up moves it 8 cm along the road.
  double stereo_length_m = 1.0;
  int min_stereo_rows = 10;
  double max_axis_rms_m = 0.03;
  // The ends of one edge lie on the road: their heights over the road
  // plane within this of their median (a crowned road moves them by a
  // centimetre or two over a crossing's width; a mismatched right run by
  // decimetres).
  double max_end_height_difference_m = 0.04;
  // Ends farther than this from the left camera (horizontally) are left
  // out: a stereo height's error grows with the square of the range, and
  // moves the end along the road by range / camera height times as much.
  double max_end_range_m = 11.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("enabled", enabled);
    v("box_window_m", box_window_m);
    v("min_contrast", min_contrast);
    v("min_band_width_m", min_band_width_m);
    v("max_band_width_m", max_band_width_m);
    v("max_side_difference", max_side_difference);
    v("min_band_length_m", min_band_length_m);
    v("max_axis_slope", max_axis_slope);
    v("max_end_slope", max_end_slope);
    v("max_end_rms_px", max_end_rms_px);
    v("min_end_columns", min_end_columns);
    v("min_bands", min_bands);
    v("max_band_gap_m", max_band_gap_m);
    v("max_edge_residual_m", max_edge_residual_m);
    v("max_end_angle_rad", max_end_angle_rad);
    v("end_sigma_px", end_sigma_px);
    v("stereo_length_m", stereo_length_m);
    v("min_stereo_rows", min_stereo_rows);
    v("max_axis_rms_m", max_axis_rms_m);
    v("max_end_height_difference_m", max_end_height_difference_m);
    v("max_end_range_m", max_end_range_m);
  }
};

// A band end found in the rectified image.
struct BandEnd {
  Eigen::Vector2d mid_px = Eigen::Vector2d::Zero();  // on the band's axis
  double end_slope = 0.0;                            // dy/dx of the end's line
  double axis_slope = 0.0;  // dx/dy of the band's centre line
  // -1: the band's top end (the paint lies below it, towards the vehicle);
  // +1: its bottom end (the paint lies above it).
  int outward = 0;
  double width_px = 0.0;  // the band's run across a row (median)
};

// Step 1 on a CV_32F rectified image: its band paint (CV_8U 0/255).
cv::Mat BandPaintPixels(const cv::Mat& image, const cv::Mat& valid,
                        double ground_pixel_m,
                        const CrossingEdgeOptions& options);

// Steps 2 and 3 on a CV_32F rectified image, its valid mask (CV_8U) and
// BandPaintPixels, ground_pixel_m metres per pixel.
std::vector<BandEnd> FindBandEnds(const cv::Mat& image, const cv::Mat& valid,
                                  const cv::Mat& paint, double ground_pixel_m,
                                  const CrossingEdgeOptions& options);

// Step 4: indices into `ends` of each edge, left to right in the image.
std::vector<std::vector<int>> GroupCrossingEdges(
    const std::vector<BandEnd>& ends, double ground_pixel_m,
    const CrossingEdgeOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_CROSSING_EDGES_H_
