// Zebra band modelling (Soheilian et al., section 5): pairs of long sides
// become bands, each band gets its own 3D plane, its transversal sides are
// found by a Hough transform in the rectified images, and its vertices are
// the image intersections of long and transversal sides projected onto the
// band's plane.
//
// Frames: body (FRD) for 3D, metres; rectified image pixels for 2D (see
// road_rectification.h). A band's vertices are in order around it: 0 and 1
// on its "begin" transversal side, 2 and 3 on its "end" side, 0 and 3 on one
// long side, 1 and 2 on the other.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_MODELING_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_MODELING_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "reconstruction/long_sides.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

struct BandOptions {
  // Long sides of one band are parallel within this angle.
  double max_side_angle_rad = 0.05;
  // They overlap (along the band) over at least this share of the shorter,
  // and over at most ZebraSpecification::max_band_length_m plus this: a
  // longer pair is no band (a lane line's edge and the kerb beside a
  // crossing).
  double min_side_overlap_fraction = 0.5;
  double max_length_excess_m = 0.5;
  // The approximate transversal sides of a crossing come from the ends of
  // its long sides at least this share of the longest (the paper's 80 %).
  double extremity_length_fraction = 0.8;
  // Search area: this far on each side of the approximate transversal side
  // (the paper's 40 cm), inset from the long sides by side_margin_m so the
  // long edges and the corners do not vote.
  double transversal_search_m = 0.4;
  double side_margin_m = 0.04;
  // Hough: lines within this angle of the crossing's mean transversal
  // direction (the paper's 20 degrees); an edge point votes for angles
  // within point_angle_tolerance_rad of its own edge direction.
  double transversal_max_angle_rad = 0.35;
  double point_angle_tolerance_rad = 0.17;
  double hough_angle_step_rad = 0.0087;
  double hough_rho_step_px = 1.0;
  // Local Hough maxima above this share of the highest are candidates, and
  // pairs whose gradient score is above this share of the best are
  // compared by their gradient directions (the paper's 80 % twice).
  double hough_score_fraction = 0.8;
  double pair_score_fraction = 0.8;
  // Pixels whose gradient norm is below this do not vote (grey levels per
  // pixel; a far transversal side is blurred along the road, so its
  // gradient is weak but wide).
  double hough_min_gradient = 2.0;
  // Sub-pixel refinement of a Hough line: gradient profiles across it
  // within this distance, at least this many along it.
  double refine_distance_px = 6.0;
  int min_transversal_points = 8;
  // The gradient across a seen transversal side beyond the long sides must
  // stay below this share of the one along the band's end: a shadow
  // boundary across a lane line runs on over the road, a painted end does
  // not. On the 1380 transversal sides of demo and outage (seed 1), 99 %
  // run on less than 0.13; the only ones above 0.25 were one band's end
  // taken on an edge running on past it (a 66 cm vertex error).
  double max_transversal_run_on = 0.25;
  // A seen transversal side's grey-level step (the gradient across it
  // summed over +-end_step_profile_px) must be at least this share of the
  // long sides': the paint ends there. A weak Hough maximum inside plain
  // paint, where a band runs on out of view under the vehicle, is not.
  // On demo, a 14 m/s variant and a 1920x1080 one (961 ends) every true
  // end is above 0.62; the two below, 0.22 and 0.28, were in plain paint.
  double min_end_step_fraction = 0.35;
  double end_step_profile_px = 8.0;
  // A band is painted as a parallelogram: its two ends (averaged over the
  // two images) are parallel within this angle. A dark stain on the paint
  // cuts a band with a slanted "end" (ambiguity seed 2: 0.50 rad). On 9
  // surveys (demo, urban seeds 1-3, outage, ambiguity seed 2 and three
  // contract variants) the good bands' ends are within 0.125 rad, the
  // farthest (13-15 m) the least parallel; above 0.2 were that stain and
  // two far bands with vertices 10 cm off.
  double max_end_angle_rad = 0.2;
  // The left and right images give two estimates of each vertex; a band
  // whose estimates differ by more is dropped.
  double max_stereo_disagreement_m = 0.05;
  // Bands of one direction whose long sides are closer (across) than this
  // and overlap along the band belong to one crossing.
  double max_crossing_gap_m = 2.2;
  // Bands whose centre is farther than this from the left camera are not
  // reported: their along-track precision degrades with the square of the
  // range, and a closer exposure sees them better.
  double max_band_range_m = 15.05;
  // Floor of the image line position's standard deviation in the
  // covariance (resampling and model errors).
  double min_line_sigma_px = 0.1;
  // Floor of the long side and band plane standard deviations.
  double min_sigma_m = 0.002;
  // Crossing completion: a long side that no band took, where the regular
  // pattern of a crossing of at least completion_min_bands bands expects
  // the side of a missing band (within completion_tolerance_m), makes a
  // band with its other side one median band width away: the other side is
  // hidden by a vehicle or merged with a lane line. That inferred side's
  // standard deviation is the spread of the crossing's widths, at least
  // completion_min_sigma_m, and the band's score is multiplied by
  // inferred_score_factor.
  bool complete_crossings = true;
  int completion_min_bands = 3;
  double completion_tolerance_m = 0.04;
  double completion_min_sigma_m = 0.01;
  double inferred_score_factor = 0.5;
  // Bands with an inferred side or end (below) farther than this from the
  // left camera are not reported: the extrapolation error grows with range.
  double max_inferred_range_m = 13.0;
  // Hidden band ends: when no transversal side is found at one end of a
  // band, the line through that end's vertices of the crossing's fully
  // seen bands (at least completion_min_bands, residual rms at most
  // hidden_end_max_rms_m) gives it; the band's seen end must then lie
  // within hidden_end_max_offset_m (or 3 rms) of the crossing's other line.
  // The
  // inferred end's standard deviation along the band is twice that rms, at
  // least completion_min_sigma_m.
  bool infer_hidden_ends = true;
  double hidden_end_max_rms_m = 0.01;
  double hidden_end_max_offset_m = 0.03;
  // The ends of a crossing's bands are parallel: their direction is taken
  // as the weighted median (weights 1 / range^4) of the ends of its bands
  // seen in both images, when there are at least
  // min_end_direction_observations of them (two per band and image), and
  // every seen end is then fitted along it (only its offset), once its own
  // direction is within max_end_angle_rad of it. At 15 m a band's end
  // spans a few original pixels and its angle is noisy: its two vertices
  // move apart along the band, one forward, one back.
  bool crossing_end_direction = true;
  int min_end_direction_observations = 4;

  std::string Check() const;
};

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

// Angle (radians, 0..pi/2) between a band's two ends, v0-v1 and v3-v2
// (vertices in order around the band): 0 for a parallelogram.
double EndAngleRad(const std::array<Eigen::Vector3d, 4>& vertices);

struct Band {
  std::array<Eigen::Vector3d, 4> vertices_body;
  std::array<Eigen::Matrix3d, 4> covariances_body;
  RoadPlane plane;          // the band's own plane
  double score = 0.0;       // 0..1
  int crossing = 0;         // index of the crossing within the stereo pair
  int sides[2] = {-1, -1};  // LongSideDetection::sides
  double width_m = 0.0;
  double length_m = 0.0;
  double stereo_disagreement_m = 0.0;
  // 0 or 1: that long side (sides[k]) was inferred from the crossing, not
  // seen (BandOptions::complete_crossings); -1: both seen.
  int inferred_side = -1;
  // 0 (begin) or 1 (end): that transversal side was inferred from the
  // crossing (BandOptions::infer_hidden_ends); -1: both seen.
  int inferred_end = -1;
};

// What band modelling tried, for debug images (left rectified pixels).
struct BandModelingDebug {
  std::vector<std::array<Eigen::Vector2d, 4>> search_areas;
  std::vector<std::array<Eigen::Vector2d, 2>> candidate_lines;
  std::vector<std::array<Eigen::Vector2d, 2>> band_pairs;  // long side pairs
};

// Builds the bands of one stereo pair. `edges[0]`, `edges[1]`: the left and
// right rectified edge maps. Deterministic.
std::vector<Band> ModelBands(const LongSideDetection& detection,
                             const PlaneFrame& frame,
                             const RoadRectification& rectification,
                             const EdgeMap edges[2],
                             const ZebraSpecification& zebra,
                             const BandOptions& options,
                             BandModelingDebug* debug);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_MODELING_H_
