// A zebra band as band modelling (band_modeling.h) outputs it, and the
// options of every step of band modelling (Soheilian et al., section 5).
//
// Frames: body (FRD) for 3D, metres; rectified image pixels for 2D (see
// road_rectification.h). A band's vertices are in order around it: 0 and 1
// on its "begin" transversal side, 2 and 3 on its "end" side, 0 and 3 on one
// long side, 1 and 2 on the other.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "reconstruction/road_plane.h"

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
  // ... at this range and beyond; nearer, in proportion to the range, down
  // to end_angle_min_share of it (rendered seed 29: a stain's edge on the
  // paint, 0.147 rad from the crossing's ends in both images at 6.4 m, cut
  // a band 1.9 m short; on 1153 ends of 10 surveys 95 % are within 0.02
  // rad up to 8 m).
  double end_angle_full_range_m = 12.0;
  double end_angle_min_share = 0.4;
  // The two images see an end in one direction: they agree within this
  // many radians per metre of the band's range (a far end's angle is
  // noisier). Rendered seed 21: a dark stain's edge, 0.157 rad from the
  // crossing's ends in the left image and 0.010 in the right, at 6.4 m, cut
  // a band 1.9 m short (a "false band" to the scorer). On 10 surveys (two
  // field cases, 8 rendered), 1153 ends: 99 % within 0.08 rad up to 10 m,
  // 0.19 at 12-16 m; the largest 0.32 at 15 m.
  double max_end_disagreement_rad_per_m = 0.02;
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
  // Ladder crossings (issue 52): two solid bars along the crossing's edges
  // join the band ends, so a band end has no edge of its own; the bar's
  // inner edge, seen in the gaps beside the band (the road brightening into
  // the bar, the reverse of a band end's polarity), is the end. A band
  // whose ends are not found as paint ends is modelled again with each end
  // taken on that edge, searched within ladder_gap_reach_m of its long
  // sides, when: the edge's step in the gaps is at least
  // min_end_step_fraction of the long sides' (a bar's paint), the step
  // across it between the band's corners is at most
  // max_ladder_join_step_fraction of it (the band runs on into the bar),
  // and a paint end's polarity (the bar's outer edge) lies
  // ladder_min_bar_width_m to ladder_max_bar_width_m beyond it. Such an
  // end's standard deviation along the band adds ladder_end_sigma_m to its
  // line fit's: the edge is measured beside the band and carried across it.
  bool ladder_ends = true;
  double ladder_gap_reach_m = 0.7;
  double max_ladder_join_step_fraction = 0.3;
  double ladder_min_bar_width_m = 0.1;
  double ladder_max_bar_width_m = 0.5;
  double ladder_end_sigma_m = 0.008;
  // Paint gaps (issue 52): a band candidate is cut where both its long
  // sides stop for at least min_paint_gap_m and, in both images, the
  // band's middle there is darker than the paint on either side by at
  // least min_paint_gap_drop_fraction of the paint's step to the road
  // beside the band (paint_gaps.h); it keeps its longest piece, which must
  // be at least min_piece_widths band widths long (a bicycle square is as
  // long as wide). The paint beside a crossing in line with its bands, 0.2
  // m and more beyond their ends, otherwise joins them.
  bool cut_at_paint_gaps = true;
  double min_paint_gap_m = 0.1;
  double min_paint_gap_drop_fraction = 0.5;
  double min_piece_widths = 2.0;
  // A band longer than its crossing's others (crossing_regularity.h).
  bool drop_overlong_bands = true;
  double max_crossing_length_excess_m = 0.3;
  double crossing_length_agreement_m = 0.1;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_side_angle_rad", max_side_angle_rad);
    v("min_side_overlap_fraction", min_side_overlap_fraction);
    v("max_length_excess_m", max_length_excess_m);
    v("extremity_length_fraction", extremity_length_fraction);
    v("transversal_search_m", transversal_search_m);
    v("side_margin_m", side_margin_m);
    v("transversal_max_angle_rad", transversal_max_angle_rad);
    v("point_angle_tolerance_rad", point_angle_tolerance_rad);
    v("hough_angle_step_rad", hough_angle_step_rad);
    v("hough_rho_step_px", hough_rho_step_px);
    v("hough_score_fraction", hough_score_fraction);
    v("pair_score_fraction", pair_score_fraction);
    v("hough_min_gradient", hough_min_gradient);
    v("refine_distance_px", refine_distance_px);
    v("min_transversal_points", min_transversal_points);
    v("max_transversal_run_on", max_transversal_run_on);
    v("min_end_step_fraction", min_end_step_fraction);
    v("end_step_profile_px", end_step_profile_px);
    v("max_end_angle_rad", max_end_angle_rad);
    v("end_angle_full_range_m", end_angle_full_range_m);
    v("end_angle_min_share", end_angle_min_share);
    v("max_end_disagreement_rad_per_m", max_end_disagreement_rad_per_m);
    v("max_stereo_disagreement_m", max_stereo_disagreement_m);
    v("max_crossing_gap_m", max_crossing_gap_m);
    v("max_band_range_m", max_band_range_m);
    v("min_line_sigma_px", min_line_sigma_px);
    v("min_sigma_m", min_sigma_m);
    v("complete_crossings", complete_crossings);
    v("completion_min_bands", completion_min_bands);
    v("completion_tolerance_m", completion_tolerance_m);
    v("completion_min_sigma_m", completion_min_sigma_m);
    v("inferred_score_factor", inferred_score_factor);
    v("max_inferred_range_m", max_inferred_range_m);
    v("infer_hidden_ends", infer_hidden_ends);
    v("hidden_end_max_rms_m", hidden_end_max_rms_m);
    v("hidden_end_max_offset_m", hidden_end_max_offset_m);
    v("crossing_end_direction", crossing_end_direction);
    v("min_end_direction_observations", min_end_direction_observations);
    v("ladder_ends", ladder_ends);
    v("ladder_gap_reach_m", ladder_gap_reach_m);
    v("max_ladder_join_step_fraction", max_ladder_join_step_fraction);
    v("ladder_min_bar_width_m", ladder_min_bar_width_m);
    v("ladder_max_bar_width_m", ladder_max_bar_width_m);
    v("ladder_end_sigma_m", ladder_end_sigma_m);
    v("cut_at_paint_gaps", cut_at_paint_gaps);
    v("min_paint_gap_m", min_paint_gap_m);
    v("min_paint_gap_drop_fraction", min_paint_gap_drop_fraction);
    v("min_piece_widths", min_piece_widths);
    v("drop_overlong_bands", drop_overlong_bands);
    v("max_crossing_length_excess_m", max_crossing_length_excess_m);
    v("crossing_length_agreement_m", crossing_length_agreement_m);
  }
};

// What placed a band end: its own paint end (an edge across the band),
// the inner edge of a ladder crossing's bar, or the line of its crossing's
// other bands' ends (a hidden end).
enum class EndEvidence { kPaintEnd, kLadderBar, kCrossingLine };
const char* EndEvidenceName(EndEvidence evidence);

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
  // What placed each end, begin [0] and end [1] (issue 52).
  std::array<EndEvidence, 2> end_evidence = {EndEvidence::kPaintEnd,
                                             EndEvidence::kPaintEnd};
};

// What band modelling tried, for debug images (left rectified pixels).
struct BandModelingDebug {
  std::vector<std::array<Eigen::Vector2d, 4>> search_areas;
  std::vector<std::array<Eigen::Vector2d, 2>> candidate_lines;
  std::vector<std::array<Eigen::Vector2d, 2>> band_pairs;  // long side pairs
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_H_
