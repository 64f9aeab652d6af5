// Steps 1 to 5 of the bright-line extractor of road_lines.h (the Ohio
// State GPS-Van, ../shared/seeds/001_*.txt, sections 3.1 to 3.3) on the
// road-plane rectified images: bright pixels per scan line, runs of a
// painted line's width, thinning, line following, polyline vertices and
// sub-pixel run centres.
//
// Frames: rectified image pixels (see road_rectification.h); scan lines are
// image rows.
#ifndef ZEBRAGEO_RECONSTRUCTION_BRIGHT_LINES_H_
#define ZEBRAGEO_RECONSTRUCTION_BRIGHT_LINES_H_

#include <opencv2/core.hpp>
#include <vector>

namespace zebrageo {

// True when (x, y) lies in the CV_8U `mask` and is not 0.
bool IsSet(const cv::Mat& mask, int x, int y);

// Step 1 on the rows of a CV_32F image: CV_8U, 255 where the median of the
// `median_window_px` valid pixels around a pixel (on its row) exceeds the
// row's mean by more than threshold_sigmas standard deviations (robust
// ones unless plain_statistics, see RoadLineOptions). `valid` (CV_8U, or
// empty for all valid) limits the statistics and the result.
//
// With background_window_px > 0, pixels in a shadow have a local threshold
// instead: where the running median of the valid pixels within
// background_window_px / 2 lies more than shadow_sigmas deviations under
// the row's reference, the threshold is that median plus
// local_threshold_sigmas times the robust deviation about it within the
// same window. The paint inside a shadow across the road is darker than
// the sunlit asphalt that sets the row's reference, so the seed's test
// loses it; a running median keeps the shadow's edge a step, not a bright
// run. Outside shadows the seed's test holds unchanged: a local deviation
// is that of bare asphalt, and the texture of sunlit ground and sidewalks
// would pass a threshold set by it.
cv::Mat BrightLinePixels(const cv::Mat& image, const cv::Mat& valid,
                         int median_window_px, double threshold_sigmas,
                         bool plain_statistics = false,
                         int background_window_px = 0,
                         double local_threshold_sigmas = 2.5,
                         double shadow_sigmas = 1.5);

// Step 1, end: clears the runs of a row that are narrower than min_px or
// wider than max_px, and those touching an invalid pixel or the image side
// (their width is unknown). Returns how many runs were wider than max_px.
int KeepRunsByWidth(const cv::Mat& valid, int min_px, int max_px,
                    cv::Mat* binary);

// Step 1, end: clears the runs of a row whose ground two and three pixels
// outside differ, left to right, by more than max_side_difference times the
// run's contrast (peak over the darker side). Returns how many were cleared.
int KeepRunsOnEvenGround(const cv::Mat& image, double max_side_difference,
                         cv::Mat* binary);

// Step 2: one-pixel-wide skeleton of a CV_8U 0/255 image.
cv::Mat ThinLines(const cv::Mat& binary);

// Step 3: chains of 8-connected skeleton pixels, from an end to the other
// (closed loops from any pixel), each pixel in exactly one chain; chains
// with fewer than min_length_px pixels are dropped. Deterministic (raster
// order).
std::vector<std::vector<cv::Point>> FollowChains(const cv::Mat& skeleton,
                                                 int min_length_px);

// Step 1 finds marks running across the scan lines (the rows): a chain
// must too, its ends at least twice as far apart across the rows as along
// them. Noise elongated along the rows (far away, one original pixel
// covers several rectified ones along the road) is dropped.
bool RunsAcrossRows(const std::vector<cv::Point>& chain);

// x = x0 + slope * y fitted to a chain's pixels by least squares (the
// thinned end pixels may hook along a shadow's edge: the fit does not).
struct ColumnFit {
  double x0 = 0.0;
  double slope = 0.0;
  double At(double y) const { return x0 + slope * y; }
};
ColumnFit FitColumns(const std::vector<cv::Point>& chain);

// Step 3, end: chains of marks running across the rows (lane lines), joined
// across short breaks: a shadow's edge crossing a line in the rectified
// image leaves a gap where neither side's reference finds the paint, and
// worn paint does too, which cut a dash in two and so hid it as a whole
// dash. The lower end of one chain and the upper end of another join when
// they are at most max_gap_rows apart along the rows, the straight lines
// fitted to the two chains meet within max_offset_px in the middle of the
// gap and part by at most that over direction_rows rows, and neither end
// has another such partner. Joined chains run top to bottom; others are
// returned unchanged.
std::vector<std::vector<cv::Point>> JoinChainsAcrossBreaks(
    std::vector<std::vector<cv::Point>> chains, int max_gap_rows,
    double max_offset_px, int direction_rows = 15);

// Step 4: indices into `chain` of the points kept: both ends, the points
// farther than tolerance_px from the chord of their neighbours (Douglas-
// Peucker), and enough in between that consecutive kept points are at most
// max_spacing_px apart along the chain.
std::vector<int> DropCollinearPoints(const std::vector<cv::Point>& chain,
                                     double tolerance_px, int max_spacing_px);

// Step 5: sub-pixel centre of the bright run of row `y` containing x (or
// starting within one pixel of it): the centroid of gray value above the
// row's background. False when no run is there.
bool RunCentre(const cv::Mat& image, const cv::Mat& binary, int y, int x,
               double* centre);

// Step 6, end: the row, sub-pixel, where the paint ends beyond the end of
// a lane `chain` (`outward` +1: its lower end, downwards; -1: its upper
// end, upwards): where the gray value along the line's centre (the
// chain's fitted column near the end, 3 pixels wide) first falls half way
// from the paint's level (median of the 8 rows inside the end) to the
// ground's (median of 6 rows from 6 rows out). Half contrast is the edge
// of a blurred step whatever the detection threshold and the blur, so both
// ends of a dash lie alike on its paint and its centre is unbiased. NaN
// when the profile shows no clear end (contrast under min_contrast, or
// the ground beyond not valid in `valid`).
double HalfContrastEndRow(const cv::Mat& image, const cv::Mat& valid,
                          const std::vector<cv::Point>& chain, int outward,
                          double min_contrast);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BRIGHT_LINES_H_
