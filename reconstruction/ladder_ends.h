// Ladder crossings (issue 52): two solid bars along the crossing's edges
// join its band ends, so a band end is no edge of its own. Where a band
// joins a bar, its end is the bar's inner edge between the band's long
// sides; that edge is seen in the gaps beside the band, with the reverse
// of a band end's polarity (band_ends.cc searches it there when
// KnownEnd::ladder is set). This file holds the checks that such an end is
// a bar's: the band runs on into paint, the gaps end on paint, and the
// bar's outer edge lies beyond. The bars themselves are never bands: they
// lie across the bands' direction and are narrower than a band
// (band_pairs.cc), and their edges are no band end's polarity.
//
// Frames: rectified image pixels; body (FRD) metres for 3D.
#ifndef ZEBRAGEO_RECONSTRUCTION_LADDER_ENDS_H_
#define ZEBRAGEO_RECONSTRUCTION_LADDER_ENDS_H_

#include <Eigen/Core>
#include <array>

#include "reconstruction/band_ends.h"
#include "reconstruction/band_vertices.h"
#include "reconstruction/transversal_sides.h"

namespace zebrageo {

// True when every ladder end of band i (known[e].ladder) in `image` is a
// bar's inner edge (BandOptions, ladder_*): the step across its line
// between the band's corners is at most max_ladder_join_step_fraction of
// the long sides' step, in a gap beside the band at least
// min_end_step_fraction of it, and a paint end's edge parallel to it lies
// ladder_min_bar_width_m to ladder_max_bar_width_m beyond, with at least
// that step too. `corner`: the band's vertices in this image, `vertices`
// their 3D points (for the image scale).
bool LadderEndsJoinBars(const BandContext& context, int i,
                        const KnownEnd known[2], const BandImage& image,
                        const ImageLine long_lines[2],
                        const ImageLine transversal_lines[2],
                        const Eigen::Vector2d corner[4],
                        const std::array<Eigen::Vector3d, 4>& vertices);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_LADDER_ENDS_H_
