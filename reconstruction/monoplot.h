// Monoplotting of the edges that run along the epipolar lines (issue 51).
//
// A crossing across a side street has its bands' long sides across the
// track, nearly parallel to the stereo baseline, i.e. along the rectified
// images' rows, where edge matching by disparity has nothing to measure:
// those edges are never triangulated, and the long sides of such bands are
// never found. Their ends run along the track and match well: the
// triangulated points around a run's two ends (its band's ends) give the
// height of its paint. Each run of left image edge points along the rows
// is cut with that surface (its left image ray intersected with the road
// plane moved to the height interpolated along the row between the ends),
// and goes to long side detection like a triangulated chain. The local
// surface's height error moves such a point along its ray
// (EdgePoint3d::monoplot_height_sigma_m), and its edge's localisation in
// the image moves it across the edge on the road by the angular error over
// the grazing angle of the plane through camera and edge
// (monoplot_across_sigma_m): both go to the vertex covariance.
//
// Frames: body (FRD), metres; rectified image pixels.
#ifndef ZEBRAGEO_RECONSTRUCTION_MONOPLOT_H_
#define ZEBRAGEO_RECONSTRUCTION_MONOPLOT_H_

#include <string>
#include <utility>
#include <vector>

#include "reconstruction/long_sides.h"
#include "reconstruction/road_plane.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

struct MonoplotOptions {
  // On: with side-street crossings in view (the junction sweep,
  // docs/results.md, issue 51) it gives a few more of their bands and
  // pairs, with 0 false bands and 0 wrong matches measured.
  bool enabled = true;
  // Edge points whose edge runs within this angle of the rows.
  double max_row_angle_rad = 0.4;
  // Runs of consecutive such points along a chain at least this long
  // (metres on the road): longer than a band is wide, so the ends of the
  // bands along the track are not monoplotted.
  double min_run_length_m = 0.8;
  // A run bridges this many consecutive points off the rows.
  int max_run_gap_points = 6;
  // The local road height: a line (along the rows) through the heights
  // over the road plane of the triangulated points (edges across the rows)
  // within end_radius_m of the run's two ends (its band's ends and its
  // neighbours', along the track, matched in stereo), at least
  // min_height_points of them, with an
  // rms of at most max_height_spread_m; a constant when they span less
  // than min_height_span_m along the rows.
  // 3 m: the triangulated ends of the crossing's neighbouring bands too
  // (0.3 m, its own band's ends only, left 1.4 cm height rms at 10-14 m,
  // 7 cm along the ray; 3 m: 0.4 cm; issue 51, docs/results.md).
  double end_radius_m = 3.0;
  double min_height_span_m = 0.5;
  int min_height_points = 10;
  double max_height_spread_m = 0.03;
  // Floor of the local height's standard deviation (the surface is not
  // exactly planar over the radius).
  double min_height_sigma_m = 0.003;
  // The honest covariance of a monoplotted point (issue 51, fourth part;
  // docs/results.md): its edge's localisation in the original image
  // (pixels; a side-street band's long side across the line of sight at
  // 10-14 m, 7-10 cm on the road per pixel: measured
  // 0.45 px rms at the vertices, systematic along a band, so not divided
  // by the number of points), and the disparity error of the triangulated
  // band ends its height comes from (pixels, their errors shared by the
  // points of an edge; measured 0.4 cm height rms at 12 m).
  double edge_sigma_px = 0.4;
  double height_disparity_sigma_px = 0.1;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("enabled", enabled);
    v("max_row_angle_rad", max_row_angle_rad);
    v("min_run_length_m", min_run_length_m);
    v("max_run_gap_points", max_run_gap_points);
    v("end_radius_m", end_radius_m);
    v("min_height_span_m", min_height_span_m);
    v("min_height_points", min_height_points);
    v("max_height_spread_m", max_height_spread_m);
    v("min_height_sigma_m", min_height_sigma_m);
    v("edge_sigma_px", edge_sigma_px);
    v("height_disparity_sigma_px", height_disparity_sigma_px);
  }
};

// The monoplotted chains of the left edge map `left`: runs of its chains'
// points along the rows, cut with the local road surface given by the
// triangulated points around its ends (`by_chain`, those within
// keep_distance_m of `plane`, the pair's fitted road plane). Each run is
// one chain, its points in order along the left chain. `pixel_angle_rad`:
// the angle one pixel of the original left image subtends (1 / focal).
std::vector<EdgeChain3d> MonoplotRowEdges(
    const RoadRectification& rectification, const EdgeMap& left,
    const std::vector<std::vector<std::pair<int, EdgePoint3d>>>& by_chain,
    const RoadPlane& plane, double keep_distance_m, double pixel_angle_rad,
    const MonoplotOptions& options);

// The standard deviations of a point monoplotted from `centre` (the left
// camera) onto `plane` at `p`, on an edge of direction `edge_direction`:
// across the edge on the road from the edge's localisation, and of the
// height from the triangulated ends (at least `line_sigma_m`, the height
// line's own). Both grow with the range.
void MonoplotSigmas(const RoadPlane& plane, const Eigen::Vector3d& centre,
                    const Eigen::Vector3d& p,
                    const Eigen::Vector3d& edge_direction, double baseline_m,
                    double pixel_angle_rad, double line_sigma_m,
                    const MonoplotOptions& options, double* across_sigma_m,
                    double* height_sigma_m);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_MONOPLOT_H_
