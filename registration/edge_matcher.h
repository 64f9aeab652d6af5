// Crossing edges to the database (issue 17): the line through the seen ends
// of a crossing's bands (reconstruction/crossing_edges.h) against the same
// line of a database crossing, the ends of its bands on one side.
//
// An edge runs across the road: matched, it holds the position across
// itself, along the track, where nothing else does when no band is ever
// seen whole (a camera pitched steeply down, exposures far apart). The two
// edges of a crossing are 2.5 to 6 m apart and look alike; they differ in
// which side the paint lies on, which both carry (their points are ordered
// so that, seen from above, the paint lies to the left). A reconstructed
// edge is matched to the database edge when:
//   - they run the same way (paint on the same side) within max_angle_rad;
//   - its points lie across that edge within gate_m, by their median, and
//     within max_spread_m of that median (the same line, not a skewed one);
//   - two thirds of its points lie within the database edge's extent
//     (extent_margin_m): the database may lack an end band;
//   - every other database edge running that way is at least
//     min_separation_ratio times, and gate_m, farther.
//
// Frames: ENU metres of the survey's local frame.
#ifndef ZEBRAGEO_REGISTRATION_EDGE_MATCHER_H_
#define ZEBRAGEO_REGISTRATION_EDGE_MATCHER_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "survey/geodesy.h"
#include "survey/roadmarks.h"

namespace zebrageo {

struct CrossingEdgeMatchOptions {
  double gate_m = 1.5;
  double min_separation_ratio = 2.5;
  double max_angle_rad = 0.15;
  double max_spread_m = 0.15;
  double extent_margin_m = 0.6;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("gate_m", gate_m);
    v("min_separation_ratio", min_separation_ratio);
    v("max_angle_rad", max_angle_rad);
    v("max_spread_m", max_spread_m);
    v("extent_margin_m", extent_margin_m);
  }
};

// One edge of a database crossing: the mid-points of its bands' ends on one
// side, ordered so that, seen from above, the paint lies to their left.
struct DatabaseCrossingEdge {
  std::string crossing_id;
  std::string id;  // crossing_id:edge+ or :edge- (its bands' +u or -u ends)
  std::vector<Eigen::Vector3d> points;
  // The straight line fitted through them (horizontal): a point, the unit
  // direction the points run, and their extent along it from the point.
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
  double from_m = 0.0, to_m = 0.0;
  double sigma_xy_m = 0.0;

  // The unit normal towards the paint (left of the direction).
  Eigen::Vector2d Normal() const { return {-direction.y(), direction.x()}; }
};

// Both edges of every database crossing with at least two bands.
std::vector<DatabaseCrossingEdge> DatabaseCrossingEdges(
    const RoadmarkDatabase& database, const LocalFrame& frame);

struct CrossingEdgeMatch {
  int edge = 0;     // index into the reconstructed edges
  int db_edge = 0;  // index into the database edges
  // Median distance of the points across the database edge, towards its
  // paint (reconstructed minus database).
  double offset_m = 0.0;
};

// `edges`: each reconstructed edge's points in ENU, in their order.
std::vector<CrossingEdgeMatch> MatchCrossingEdges(
    const std::vector<std::vector<Eigen::Vector3d>>& edges,
    const std::vector<DatabaseCrossingEdge>& database,
    const CrossingEdgeMatchOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_EDGE_MATCHER_H_
