// Hidden band ends (Soheilian et al., section 5.1, extended): a vehicle
// parked before a crossing hides the end of its outer bands. The
// transversal sides of a crossing are one line at each end; fitted on the
// vertices of its fully seen bands, that line gives the hidden end when it
// is reliable: enough bands, small residuals, a band next to them. The
// band's seen end must lie on the other line. (An end hidden in one image
// only makes the two images disagree.)
//
// Frames: the plane frame of long_sides.h (metres); body (FRD) for 3D.
#ifndef ZEBRAGEO_RECONSTRUCTION_HIDDEN_ENDS_H_
#define ZEBRAGEO_RECONSTRUCTION_HIDDEN_ENDS_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/band_vertices.h"
#include "reconstruction/transversal_search.h"

namespace zebrageo {

// The lines of one crossing's band ends, begin [0] and end [1], fitted on
// the vertices of its fully seen bands.
struct CrossingEndLines {
  std::array<PlaneLine, 2> lines;
  // Standard deviation of a hidden end taken from the line; -1 when the
  // line is not reliable (residual rms above hidden_end_max_rms_m).
  std::array<double, 2> sigma = {-1.0, -1.0};
  // Residual rms of the line; -1 when too few bands were seen.
  std::array<double, 2> rms = {-1.0, -1.0};
  // Lateral extent of the seen bands (across the bands).
  std::array<double, 2> lateral_range = {1e30, -1e30};
};

// The end lines of each of `crossings` crossings from `bands`.
std::vector<CrossingEndLines> FitCrossingEndLines(
    const std::vector<Band>& bands, const std::vector<LongSide>& sides,
    const PlaneFrame& frame, int crossings, const BandOptions& options);

// Models again the bands of `without_transversal` (indices of
// context.bands.pairs whose transversal side was not found, or whose
// images disagreed) with one end taken from its crossing's line, and
// appends those that pass to `bands`. `crossing_direction[c]`, when
// `has_direction[c]`: the direction of crossing c's ends.
void InferHiddenEnds(const BandContext& context,
                     const std::vector<int>& without_transversal,
                     const std::vector<Eigen::Vector2d>& crossing_direction,
                     const std::vector<char>& has_direction,
                     std::vector<Band>* bands);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_HIDDEN_ENDS_H_
