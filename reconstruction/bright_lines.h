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
cv::Mat BrightLinePixels(const cv::Mat& image, const cv::Mat& valid,
                         int median_window_px, double threshold_sigmas,
                         bool plain_statistics = false);

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

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BRIGHT_LINES_H_
