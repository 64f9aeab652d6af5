// Detection of the long sides of zebra bands among the 3D edge chains
// (Soheilian et al., section 4.3).
//
// The 3D edge points near the road plane are expressed in a 2D frame of
// that plane (metres). Each chain is polygonised (Douglas-Peucker) and each
// polygon side refined by a line regression on its points. The principal
// direction is the most frequent segment direction; segments near it vote,
// in proportion to their length, in an accumulator across that direction.
// Hysteresis on the votes (20 % and 5 % of the minimum band length) gives
// connected components, i.e. lines; a component is kept when another lies
// one band width away. Its segments are grouped in two passes (fine
// closeness and coarse orientation, then fine orientation and coarse
// closeness, which bridges occlusions), and each group becomes a 3D line by
// a regression on its 3D points, kept when longer than L_min.
//
// Frames: body (FRD) for 3D; the plane frame (e1, e2) is the rectified
// images' (x, y) axes projected on the road plane, so rectified image
// gradients are (almost exactly) gradients in the plane frame.
#ifndef ZEBRAGEO_RECONSTRUCTION_LONG_SIDES_H_
#define ZEBRAGEO_RECONSTRUCTION_LONG_SIDES_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "reconstruction/road_plane.h"

namespace zebrageo {

// What a zebra band is (French specification, SURVEY_FORMAT.md: bands about
// 0.5 m wide and 0.5 m apart, 2.5 m to 6 m long).
struct ZebraSpecification {
  double band_width_m = 0.5;
  // Accepted deviation of a band's width from band_width_m (paint wear,
  // other countries' specifications).
  double band_width_tolerance_m = 0.12;
  double min_band_length_m = 2.5;
  double max_band_length_m = 6.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("band_width_m", band_width_m);
    v("band_width_tolerance_m", band_width_tolerance_m);
    v("min_band_length_m", min_band_length_m);
    v("max_band_length_m", max_band_length_m);
  }
};

struct LongSideOptions {
  // Douglas-Peucker tolerance of the chain polygonisation.
  double polygon_tolerance_m = 0.02;
  // Consecutive 3D chain points farther apart break the chain (a gap of
  // unmatched points).
  double max_chain_gap_m = 0.1;
  // Polygon sides shorter than this (or with fewer than 4 points) are noise.
  double min_segment_length_m = 0.08;
  // Segments within this angle of the principal direction vote.
  double direction_tolerance_rad = 0.17;
  // Several crossings at different angles (an intersection): up to this
  // many principal directions are processed in turn.
  int max_directions = 3;
  // Accumulator cell across the principal direction.
  double accumulator_cell_m = 0.02;
  // Hysteresis thresholds, fractions of the minimum band length.
  double high_vote_fraction = 0.2;
  double low_vote_fraction = 0.05;
  // Grouping pass 1: fine closeness, coarse orientation.
  double pass1_max_gap_m = 0.15;
  double pass1_max_offset_m = 0.02;
  double pass1_max_angle_rad = 0.17;
  double pass1_min_length_m = 0.2;  // shorter groups are dropped after it
  // Grouping pass 2: fine orientation, coarse closeness (occlusions).
  double pass2_max_gap_m = 2.0;
  double pass2_max_offset_m = 0.03;
  double pass2_max_angle_rad = 0.035;
  // L_min: shorter long sides are dropped (the paper uses 1 m for accuracy,
  // 0.2 m for completeness).
  double min_long_side_length_m = 1.0;
  // RegulariseChainHeights: half window along a chain, in chain points
  // (about a rectified pixel each: +-25 is +-0.4 m at 1.5 cm); 0 uses the
  // triangulated points as they are.
  int height_smoothing_half_window = 25;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("polygon_tolerance_m", polygon_tolerance_m);
    v("max_chain_gap_m", max_chain_gap_m);
    v("min_segment_length_m", min_segment_length_m);
    v("direction_tolerance_rad", direction_tolerance_rad);
    v("max_directions", max_directions);
    v("accumulator_cell_m", accumulator_cell_m);
    v("high_vote_fraction", high_vote_fraction);
    v("low_vote_fraction", low_vote_fraction);
    v("pass1_max_gap_m", pass1_max_gap_m);
    v("pass1_max_offset_m", pass1_max_offset_m);
    v("pass1_max_angle_rad", pass1_max_angle_rad);
    v("pass1_min_length_m", pass1_min_length_m);
    v("pass2_max_gap_m", pass2_max_gap_m);
    v("pass2_max_offset_m", pass2_max_offset_m);
    v("pass2_max_angle_rad", pass2_max_angle_rad);
    v("min_long_side_length_m", min_long_side_length_m);
    v("height_smoothing_half_window", height_smoothing_half_window);
  }
};

// A 2D frame on the road plane.
struct PlaneFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();

  // e1 = x_axis projected on the plane, e2 = normal x e1, origin = the
  // projection of `point` on the plane.
  static PlaneFrame Make(const RoadPlane& plane, const Eigen::Vector3d& x_axis,
                         const Eigen::Vector3d& point);
  Eigen::Vector2d To2d(const Eigen::Vector3d& p_body) const {
    const Eigen::Vector3d d = p_body - origin;
    return Eigen::Vector2d(e1.dot(d), e2.dot(d));
  }
  Eigen::Vector3d To3d(const Eigen::Vector2d& q) const {
    return origin + q.x() * e1 + q.y() * e2;
  }
  Eigen::Vector3d Direction3d(const Eigen::Vector2d& d) const {
    return d.x() * e1 + d.y() * e2;
  }
};

// A 3D edge point: triangulated from a match.
struct EdgePoint3d {
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();
  // The same point on its left image ray at the height over the road plane
  // smoothed along its chain (RegulariseChainHeights; p_body until then):
  // the geometry of the long sides, without the stereo depth noise.
  Eigen::Vector3d p_chain_body = Eigen::Vector3d::Zero();
  Eigen::Vector2d xy_left = Eigen::Vector2d::Zero();   // rectified pixel
  Eigen::Vector2d gradient = Eigen::Vector2d::Zero();  // rectified, left
  int index_in_chain = 0;  // position along the left image chain
  // > 0: the point was not triangulated but monoplotted (monoplot.h): its
  // left image ray cut by the local road surface, whose height has this
  // standard deviation (metres); it moves the point along that ray.
  double monoplot_height_sigma_m = 0.0;
  // ... and the standard deviation of its position across its edge on the
  // road from the edge's localisation in the image alone (the ray's
  // angular error over the grazing angle of the plane through the camera
  // and the edge: 7-10 cm per pixel at 12 m for an edge across the line of
  // sight, a side-street band's long side 6 m aside).
  double monoplot_across_sigma_m = 0.0;
};
// Points in order along a left image edge chain.
struct EdgeChain3d {
  std::vector<EdgePoint3d> points;
};

// Moves each point's p_chain_body along its left image ray (from
// `left_centre_body` through p_body) to the height over `road` given by a
// local linear fit of the chain's heights against the position along the
// chain (index_in_chain within +-half_window), fitted again without the
// points more than 3 robust sigmas (at least 5 mm) off.
//
// Why: a triangulated point's error is along its left ray, of standard
// deviation Z^2 / (f B) times the disparity error; far from the rig and to
// the side it is mostly lateral (x Z / (f B) per pixel of disparity: 1 cm
// for 0.2 px at 14 m and 3 m aside with a 1 m baseline), which breaks the
// far long sides into pieces that do not group. Along a painted edge the
// road's height varies slowly (camber, grade), so smoothing the height and
// keeping the left image position removes that noise without the bias a
// single road plane would leave on a cambered road. half_window <= 0:
// p_chain_body = p_body.
void RegulariseChainHeights(const RoadPlane& road,
                            const Eigen::Vector3d& left_centre_body,
                            int half_window, EdgeChain3d* chain);

struct Segment2d {
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  std::vector<int> support;  // indices into the flattened points
  double Length() const { return (b - a).norm(); }
};

// Indices of the vertices Douglas-Peucker keeps (first and last included).
std::vector<int> DouglasPeucker(const std::vector<Eigen::Vector2d>& polyline,
                                double tolerance);

// Direction (unit, angle in [0, pi)) of the highest peak of the
// length-weighted histogram of segment directions (1 degree bins).
// `weight`: the length of segments within `tolerance_rad` of it.
Eigen::Vector2d PrincipalDirection(const std::vector<Segment2d>& segments,
                                   double tolerance_rad, double* weight);

// A line of the accumulator: a run of cells above the low threshold that
// holds one above the high threshold.
struct AccumulatorComponent {
  double lateral_m = 0.0;  // vote-weighted centre, across the direction
  double low_m = 0.0;      // extent of the run
  double high_m = 0.0;
  double peak_votes_m = 0.0;
  bool paired = false;  // another component lies one band width away
};

// Votes the segments (length along `direction`, shared between the cells
// each spans across it), extracts the hysteresis components and marks
// those with a partner one band width away.
std::vector<AccumulatorComponent> ParallelLineComponents(
    const std::vector<Segment2d>& segments, const Eigen::Vector2d& direction,
    const ZebraSpecification& zebra, const LongSideOptions& options);

struct LongSide {
  int direction_set = 0;
  Eigen::Vector2d direction_2d = Eigen::Vector2d::UnitX();  // of the set
  Eigen::Vector3d point_body = Eigen::Vector3d::Zero();     // support centre
  Eigen::Vector3d direction_body = Eigen::Vector3d::UnitX();
  double t_begin = 0.0;  // support extent along direction_body (metres)
  double t_end = 0.0;
  double lateral_m = 0.0;  // across direction_2d, plane frame
  // Mean gradient across the line towards +normal_2d (grey levels / px):
  // > 0 when the image gets brighter towards +normal_2d.
  double contrast = 0.0;
  double lateral_rms_m = 0.0;  // residuals of the line regression
  double height_rms_m = 0.0;
  std::vector<int> support;  // indices into the flattened points

  Eigen::Vector2d Normal2d() const {
    return Eigen::Vector2d(-direction_2d.y(), direction_2d.x());
  }
  Eigen::Vector3d Begin() const {
    return point_body + t_begin * direction_body;
  }
  Eigen::Vector3d End() const { return point_body + t_end * direction_body; }
  double Length() const { return t_end - t_begin; }
};

struct LongSideDetection {
  // The edge points of every chain, flattened (support indices refer here).
  std::vector<EdgePoint3d> points;
  std::vector<Eigen::Vector2d> points_2d;
  std::vector<Segment2d> segments;  // all polygon sides (debugging)
  std::vector<Eigen::Vector2d> directions;
  std::vector<LongSide> sides;
};

// The 3D line (total least squares) of the points `support` (indices into
// `points`, their p_chain_body), oriented along `direction_2d` of the plane
// frame, with its extent, residuals and contrast across direction_2d.
LongSide FitLongSide(const std::vector<EdgePoint3d>& points,
                     std::vector<int> support, const PlaneFrame& frame,
                     const Eigen::Vector2d& direction_2d, int direction_set);

// Extent [low, high] of `side` along the plane-frame direction `along`.
void SideExtent(const PlaneFrame& frame, const LongSide& side,
                const Eigen::Vector2d& along, double* low, double* high);

LongSideDetection DetectLongSides(const std::vector<EdgeChain3d>& chains,
                                  const PlaneFrame& frame,
                                  const ZebraSpecification& zebra,
                                  const LongSideOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_LONG_SIDES_H_
