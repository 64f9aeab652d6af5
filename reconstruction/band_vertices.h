// A band from its two long sides (Soheilian et al., sections 5 and 5.1):
// its own plane, its transversal sides searched in both rectified images,
// its vertices as the image intersections of long and transversal sides
// projected onto its plane, the checks a painted band passes, and the
// vertices' covariances and the band's score.
//
// Frames: body (FRD) for 3D, metres; the plane frame of long_sides.h;
// rectified image pixels for 2D.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_VERTICES_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_VERTICES_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/band_pairs.h"
#include "reconstruction/crossing_regularity.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"
#include "reconstruction/transversal_search.h"
#include "reconstruction/transversal_sides.h"

namespace zebrageo {

// The transversal side of a band end taken from its crossing (hidden end).
struct KnownEnd {
  const PlaneLine* line = nullptr;
  double sigma_m = 0.0;
  // For the seen end of such a band: the crossing's line there, to choose
  // among the candidates (what hides the other end may have edges too).
  const PlaneLine* expected = nullptr;
  // The crossing's direction of the transversal sides (plane frame): a seen
  // end is fitted with it (only its offset), once its own direction is
  // found within max_end_angle_rad of it.
  const Eigen::Vector2d* direction = nullptr;
  // The end is a ladder bar's inner edge (BandOptions::ladder_ends),
  // searched beside the band with the reverse polarity.
  bool ladder = false;
};

// kNoTransversal: no transversal side at an end; kDisagreement: the two
// images disagree (a vehicle hides an end in one of them).
enum class BandOutcome { kBand, kRejected, kNoTransversal, kDisagreement };

// What every band of one stereo pair is modelled from.
struct BandContext {
  const LongSideDetection& detection;
  const PlaneFrame& frame;
  const RoadRectification& rectification;
  const EdgeMap* edges;  // left and right rectified edge maps
  const ZebraSpecification& zebra;
  const BandOptions& options;
  const BandPairs& bands;
  const TransversalSearch& search;
  BandModelingDebug* debug;  // may be null
};

// Models the band of pair i of context.bands. `known[e]`: how end e
// (0 begin, 1 end) is taken or constrained by its crossing (default: searched
// freely). `end_directions` (may be null): receives the directions of the
// band's ends in each image when the band is seen entirely (not
// extrapolated), for CrossingEndDirection.
BandOutcome ModelBand(const BandContext& context, int i,
                      const KnownEnd known[2],
                      std::vector<EndDirectionObservation>* end_directions,
                      Band* out);

// The mean grey-level step of band i's measured long sides near its end e
// (0 begin, 1 end), over 40 % of the band from that end in the image of
// `edges`; `corner`: the band's vertices there. NaN when neither side can
// be measured. A paint end steps like the long sides; a ladder bar's edge
// or plain paint does not.
double LongSideStep(const BandContext& context, int i, const EdgeMap& edges,
                    const ImageLine long_lines[2],
                    const Eigen::Vector2d corner[4], int e);

// Angle (radians, 0..pi/2) between a band's two ends, v0-v1 and v3-v2
// (vertices in order around the band): 0 for a parallelogram.
double EndAngleRad(const std::array<Eigen::Vector3d, 4>& vertices);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_VERTICES_H_
