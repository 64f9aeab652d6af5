// Transversal sides of a band in the rectified images (Soheilian et al.,
// section 5.1): Hough candidates inside a search area around the
// approximate transversal side (transversal_search.h), the pair with the
// most opposite gradients (equations 1 to 3), sub-pixel refinement, and the
// checks that a seen end is the paint's end.
//
// Frames: rectified image pixels (see road_rectification.h).
#ifndef ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SIDES_H_
#define ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SIDES_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

// A line of a rectified image: normal . x = rho, |normal| = 1.
struct ImageLine {
  Eigen::Vector2d normal = Eigen::Vector2d::UnitY();
  double rho = 0.0;
  double votes = 0.0;
  // The paper's Gamma: sum of the image gradient along the line inside the
  // search area.
  Eigen::Vector2d gamma = Eigen::Vector2d::Zero();
  int support = 0;      // edge points of the least-squares refinement
  double rms_px = 0.0;  // their residuals
  double Distance(const Eigen::Vector2d& x) const {
    return normal.dot(x) - rho;
  }
};

// z component of the cross product of two image vectors.
inline double Cross2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Image line through two points.
ImageLine LineThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Intersection of two image lines; false when they are parallel.
bool Intersect(const ImageLine& a, const ImageLine& b, Eigen::Vector2d* x);

// Hough candidates for a transversal side among the pixels inside the
// convex `area` (4 corners, rectified pixels): lines whose normal is within
// transversal_max_angle_rad of `expected_normal` (oriented: the expected
// polarity, the image brightening into the band). Each pixel votes with its
// gradient norm for the lines through it whose normal is within
// point_angle_tolerance_rad of its gradient. Local maxima above
// hough_score_fraction of the best, strongest first, each with its gamma.
std::vector<ImageLine> HoughTransversalCandidates(
    const EdgeMap& edges, const std::array<Eigen::Vector2d, 4>& area,
    const Eigen::Vector2d& expected_normal, const BandOptions& options);

// The paper's equations 2 and 3: among the pairs (begin candidate t, end
// candidate l) whose score |gamma_t| + |gamma_l| is above
// pair_score_fraction of the best, the one whose gammas are the most
// opposite (smallest dot product). Begin candidates must have gamma along
// +band_direction (the image brightens into the band) and end candidates
// along -band_direction. False when no pair qualifies.
bool ChooseTransversalPair(const std::vector<ImageLine>& begin,
                           const std::vector<ImageLine>& end,
                           const Eigen::Vector2d& band_direction,
                           const BandOptions& options, int* t, int* l);

// Sub-pixel refinement of `line` inside `area`: centroids of the gradient
// profiles across it (polarity of its gamma) fitted by weighted least
// squares. False with fewer than min_transversal_points profiles.
// `fixed_normal` (unit, may be null): the line keeps that normal and only
// its offset is fitted (the crossing's direction of the band ends).
bool RefineImageLine(const EdgeMap& edges,
                     const std::array<Eigen::Vector2d, 4>& area,
                     const BandOptions& options, ImageLine* line,
                     const Eigen::Vector2d* fixed_normal = nullptr);

// How far a transversal side runs on beyond its band: the mean gradient
// across `line` (with the polarity of its gamma) beyond the band's long
// sides, from 10 % to 50 % of the band width outside `ends` (the band's
// image vertices on that line; `check[k]` says whether to look beyond
// ends[k]), over the mean along the middle of the band's end. About 0 for
// a painted end, about 1 for a shadow boundary crossing the road. 0 when
// nothing can be sampled.
double TransversalRunOn(const EdgeMap& edges, const ImageLine& line,
                        const Eigen::Vector2d ends[2], const bool check[2]);

// Grey-level step across `line` between the points a and b (inset by a
// fifth of their distance at each end): at each pixel along the line the
// gradient along its normal summed over +-half_width_px (or the largest
// symmetric part of it the image holds, at least +-3 px), of which the
// upper quartile is returned. The step, not the sharpness: a far side
// blurred by the resampling keeps its value, and an end worn or stained
// over part of its length keeps it. NaN when too little is usable.
double EdgeStep(const EdgeMap& edges, const ImageLine& line,
                const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                double half_width_px);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SIDES_H_
