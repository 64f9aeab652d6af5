// Edge point matching along conjugate epipolar lines by dynamic programming
// (Soheilian et al., section 3; Baillard and Dissard 2000).
//
// Works on a rectified pair (rows are epipolar lines, road marks have the
// same shape in both images, see road_rectification.h). On each row, the
// left and right edge points are two ordered sequences; a matching is an
// increasing sequence of pairs (ordering constraint) that minimises
//   sum over matches (1 - NCC + continuity) + occlusion_cost * unmatched
// where NCC is the normalised cross-correlation of an 11x11 window (square
// in the road-plane geometry: the "road plane adaptive" window) and the
// continuity term is figural continuity: the disparity of a match is
// compared with the disparities found along the same left edge chain by a
// first pass, so a chain is matched as a whole and not point by point.
//
// The sub-pixel disparity is taken where the sub-pixel epipolar line y =
// y_left crosses the right sub-pixel edge chain.
#ifndef ZEBRAGEO_RECONSTRUCTION_EDGE_MATCHING_H_
#define ZEBRAGEO_RECONSTRUCTION_EDGE_MATCHING_H_

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

struct MatchingOptions {
  // Half size of the correlation window: 5 gives the paper's 11 x 11.
  int window_radius_px = 5;
  // Matches whose window correlation is lower are never made.
  double min_ncc = 0.6;
  // Cost of leaving one edge point unmatched (occlusion). A match costs
  // 1 - NCC (+ continuity), so a pair is matched when its cost is below
  // twice this value.
  double occlusion_cost = 0.35;
  // Largest angle between the left and right gradients of a match.
  double max_gradient_angle_rad = 0.35;
  // Edges closer than this angle to the epipolar lines (image rows) are not
  // matched: their position along the row is ill-defined.
  double min_epipolar_angle_rad = 0.35;
  // Figural continuity: weight of the term and disparity difference (px)
  // at which it saturates, and how many chain points on each side give the
  // chain's local disparity.
  double continuity_weight = 1.0;
  double continuity_tolerance_px = 1.0;
  int continuity_half_window = 40;
  // Chains with fewer matched points are dropped.
  int min_matches_per_chain = 5;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("window_radius_px", window_radius_px);
    v("min_ncc", min_ncc);
    v("occlusion_cost", occlusion_cost);
    v("max_gradient_angle_rad", max_gradient_angle_rad);
    v("min_epipolar_angle_rad", min_epipolar_angle_rad);
    v("continuity_weight", continuity_weight);
    v("continuity_tolerance_px", continuity_tolerance_px);
    v("continuity_half_window", continuity_half_window);
    v("min_matches_per_chain", min_matches_per_chain);
  }
};

struct EdgeMatch {
  int left = -1;   // index into the left EdgeMap's points
  int right = -1;  // index into the right EdgeMap's points
  double x_left = 0.0;
  double y = 0.0;        // the sub-pixel epipolar line (rectified row)
  double x_right = 0.0;  // right chain crossing y
  double ncc = 0.0;
};

// Search volume: for a left edge point at (x, y), the residual disparity
// interval [d_min, d_max] (see RoadRectification); false: do not match it.
using DisparityRange =
    std::function<bool(double x, double y, double* d_min, double* d_max)>;

// Matches the edge points of a rectified pair. Deterministic.
std::vector<EdgeMatch> MatchEdges(const cv::Mat& left_image,
                                  const cv::Mat& right_image,
                                  const EdgeMap& left, const EdgeMap& right,
                                  const DisparityRange& range,
                                  const MatchingOptions& options);

// The abscissa where the right edge chain through point `j` crosses the row
// y (linear interpolation between chain points; the edge tangent at `j`
// when no chain segment straddles y). Exposed for tests.
double ChainCrossing(const EdgeMap& edges, int j, double y);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_EDGE_MATCHING_H_
