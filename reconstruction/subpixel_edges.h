// Sub-pixel edge points and edge chains (Canny gradients, Devernay
// re-localisation), as used by Soheilian et al., section 3.
//
// Image coordinates: pixel (0, 0) is the centre of the top-left pixel, x to
// the right, y down. Gradients are in grey levels per pixel.
//
// Gradient: Gaussian smoothing then a 3x3 Sobel derivative (Canny's
// operator; Deriche's recursive filter is an approximation of the same
// optimal edge detector). Non-maximum suppression and sub-pixel position
// follow Devernay (1995) as described by Grompone von Gioi and Randall
// (IPOL 2017, "A sub-pixel edge detector: an implementation of the
// Canny/Devernay algorithm"): a pixel is an edge point when its gradient
// norm is a local maximum along the image axis (x or y) closest to the
// gradient direction, and the edge point is moved to the vertex of the
// parabola through the three norms along that axis. Edge points are then
// chained to their neighbours along the edge, and Canny's hysteresis keeps
// chains holding at least one point above the high threshold.
#ifndef ZEBRAGEO_RECONSTRUCTION_SUBPIXEL_EDGES_H_
#define ZEBRAGEO_RECONSTRUCTION_SUBPIXEL_EDGES_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace zebrageo {

struct EdgeOptions {
  // Standard deviation of the Gaussian smoothing before the derivative,
  // pixels. Larger is more robust to noise and texture but blurs nearby
  // edges together (a zebra band is ~33 px wide at 1.5 cm/px).
  double gaussian_sigma_px = 1.2;
  // Canny hysteresis on the gradient norm (grey levels per pixel, images on
  // a 0..255 scale): chains need one point above `high_threshold`, every
  // point is above `low_threshold`.
  double high_threshold = 8.0;
  double low_threshold = 3.0;
  // Chains with fewer points are dropped (texture, noise).
  int min_chain_points = 6;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("gaussian_sigma_px", gaussian_sigma_px);
    v("high_threshold", high_threshold);
    v("low_threshold", low_threshold);
    v("min_chain_points", min_chain_points);
  }
};

struct EdgePoint {
  float x = 0.0f;  // sub-pixel position
  float y = 0.0f;
  float gx = 0.0f;  // gradient at the edge pixel
  float gy = 0.0f;
  float norm = 0.0f;
  int px = 0;  // the pixel the point was found at
  int py = 0;
  int chain = -1;           // index into EdgeMap::chains
  int index_in_chain = -1;  // position along that chain
};

struct EdgeMap {
  int width = 0;
  int height = 0;
  cv::Mat gx;  // CV_32F gradient images (after smoothing)
  cv::Mat gy;
  // CV_8U, 0 where gradients are artefacts of the invalid area (empty when
  // every pixel is usable).
  cv::Mat usable;
  // Sorted by (py, x).
  std::vector<EdgePoint> points;
  // points[row_begin[r] .. row_begin[r + 1]) lie on pixel row r.
  std::vector<int> row_begin;
  // Point indices of each chain, in order along the edge.
  std::vector<std::vector<int>> chains;

  // Bilinear gradient at (x, y); zero outside the image.
  cv::Vec2f GradientAt(double x, double y) const;
  // True when the gradient at the pixel nearest (x, y) is meaningful.
  bool IsUsable(double x, double y) const;
};

// Detects the sub-pixel edges of a CV_32F image. `valid_mask` (CV_8U, may
// be empty) excludes pixels where it is 0, and pixels next to them.
EdgeMap DetectSubpixelEdges(const cv::Mat& image, const cv::Mat& valid_mask,
                            const EdgeOptions& options);

// The pixels of `valid_mask` (CV_8U, may be empty: then empty) whose
// gradient is usable: those outside the smoothing support of an invalid
// pixel. DetectSubpixelEdges computes it from its valid mask; a caller
// with one mask for many images computes it once (EdgeMap::usable).
cv::Mat UsableMask(const cv::Mat& valid_mask, const EdgeOptions& options);

// The working images of the detection, kept between calls: images of one
// size then reuse their memory instead of having the kernel hand out (and
// zero) fresh pages for every image, which cost more than the filtering.
struct EdgeScratch {
  cv::Mat smooth;
  cv::Mat norm;
  cv::Mat index;  // CV_32S, -1 everywhere between calls
  std::vector<EdgePoint> candidates;
};

// As DetectSubpixelEdges, with `usable` from UsableMask (shared, not
// copied), into `edges` (its images and vectors reused). The same edges.
void DetectSubpixelEdges(const cv::Mat& image, const cv::Mat& usable,
                         const EdgeOptions& options, EdgeScratch* scratch,
                         EdgeMap* edges);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_SUBPIXEL_EDGES_H_
