// Zebra band modelling (Soheilian et al., section 5): pairs of long sides
// become bands (band_pairs.h), each band gets its own 3D plane
// (band_plane.h), its transversal sides are found by a Hough transform in
// the rectified images around the crossing's approximate transversal sides
// (transversal_search.h, transversal_sides.h, band_ends.h), and its
// vertices are the image intersections of long and transversal sides
// projected onto the band's plane (band_vertices.h). A crossing's regular
// pattern then gives the ends its vehicles hide (hidden_ends.h).
//
// Frames: body (FRD) for 3D, metres; rectified image pixels for 2D (see
// road_rectification.h). Band vertices are ordered as band.h says.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_MODELING_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_MODELING_H_

#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/band_vertices.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"
#include "reconstruction/transversal_sides.h"

namespace zebrageo {

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
