// Band hypotheses from the long sides (Soheilian et al., section 5): pairs
// of long sides, parallel, one band width apart, overlapping, with inverse
// gradients and the bright paint between them, grouped into crossings
// (bands of one direction side by side). A crossing's regular pattern then
// completes the bands of which one long side is hidden (a parked vehicle)
// or merged with other paint (a lane line across the band's end).
//
// Frames: the plane frame of long_sides.h (metres); body (FRD) for 3D.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_PAIRS_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_PAIRS_H_

#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

// A band hypothesis: two long sides of one direction set.
struct BandCandidate {
  int lo = -1;  // side with the smaller lateral coordinate
  int hi = -1;
  double cost = 0.0;
  // Extent of the band (the overlap of its sides) along the direction of
  // its set: a side may run on along a lane line, the overlap does not.
  double begin = 0.0;
  double end = 0.0;
  // Completed band (see CompleteCrossings): which of lo (0) and hi (1) is
  // inferred from the crossing rather than seen, -1 for none; the standard
  // deviation of that inferred side across the band.
  int inferred = -1;
  double inferred_sigma_m = 0.0;
  // A lone long side runs between its two sides.
  bool edge_between = false;
};

// The band hypotheses of one stereo pair, grouped into crossings.
struct BandPairs {
  // The detected long sides, then the inferred ones (completed bands).
  std::vector<LongSide> sides;
  std::vector<BandCandidate> pairs;
  std::vector<int> crossing_of;  // crossing index of each pair
  int crossings = 0;
  // pairs[0, seen) have both sides seen; the completed bands follow.
  int seen = 0;
};

// Pairs the long sides of `detection` into bands and groups them into
// crossings; with BandOptions::complete_crossings, completes the crossings.
// With BandOptions::cut_at_paint_gaps, a pair is cut at its paint gaps in
// the rectified images' `edges` (paint_gaps.h).
// `debug` (may be null) gets the pairs' sides in the left rectified image.
BandPairs FindBandPairs(const LongSideDetection& detection,
                        const PlaneFrame& frame,
                        const RoadRectification& rectification,
                        const EdgeMap edges[2], const ZebraSpecification& zebra,
                        const BandOptions& options, BandModelingDebug* debug);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_PAIRS_H_
