// A zebra band is one piece of paint (issue 52): the long sides of a band
// and of the paint beside its end in line with it (a row of bicycle squares
// in phase with the bands, 0.2-0.5 m beyond their ends; a column of squares
// along the bands) group into one long side across the short stretch of
// road between them (LongSideOptions::pass2_max_gap_m bridges occluders),
// and the pair then spans band, road and square: a band too long whose
// ends are searched at the square's far edge. Here a band candidate is cut
// where both its long sides stop at once and the images show road between
// them there (the paint ends, then starts again), and keeps its longest
// piece.
//
// Frames: the plane frame of long_sides.h (metres); rectified image pixels.
#ifndef ZEBRAGEO_RECONSTRUCTION_PAINT_GAPS_H_
#define ZEBRAGEO_RECONSTRUCTION_PAINT_GAPS_H_

#include "reconstruction/band.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

// The brightness step between two plane-frame points of the road plane in
// one rectified image: the gradient along the straight path between their
// pixels, summed pixel by pixel (grey levels, > 0 when `b` is brighter).
// False when part of the path is not usable.
bool PlaneBrightnessStep(const PlaneFrame& frame,
                         const RoadRectification& rectification, int side,
                         const EdgeMap& edges, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b, double* step);

// The longest piece of the band candidate of long sides `lo` (smaller
// lateral) and `hi` over [*begin, *end] (along lo.direction_2d) once cut at
// its paint gaps: stretches of at least BandOptions::min_paint_gap_m where
// neither long side has a point (`points_2d`: LongSideDetection's) and
// where, in both rectified images, the band's middle is darker than the
// paint on either side of the stretch by at least min_paint_gap_drop_fraction
// of the step from the paint to the road beside the band. Returns the
// number of cuts.
int CutAtPaintGaps(const std::vector<Eigen::Vector2d>& points_2d,
                   const PlaneFrame& frame,
                   const RoadRectification& rectification,
                   const EdgeMap edges[2], const LongSide& lo,
                   const LongSide& hi, const BandOptions& options,
                   double* begin, double* end);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_PAINT_GAPS_H_
