// The regularity of a zebra crossing, used to make its far bands as
// reliable as its near ones: the bands of one crossing are painted
// parallel, with parallel ends (a skewed crossing's bands are
// parallelograms of one shape).
//
// Frames: the 2D plane frame of long_sides.h (metres); directions are
// unit vectors, taken modulo pi (a line has no orientation).
#ifndef ZEBRAGEO_RECONSTRUCTION_CROSSING_REGULARITY_H_
#define ZEBRAGEO_RECONSTRUCTION_CROSSING_REGULARITY_H_

#include <Eigen/Core>
#include <vector>

#include "reconstruction/band.h"

namespace zebrageo {

// One estimate of the direction of a band's end, with its weight (inverse
// variance, up to a common factor).
struct EndDirectionObservation {
  int crossing = 0;
  Eigen::Vector2d direction_2d = Eigen::Vector2d::UnitY();
  double weight = 1.0;
};

// The direction of the ends of crossing `crossing`: the weighted mean of
// its observations' angles within 0.05 rad of their weighted median
// (angles modulo pi, measured from its heaviest observation), so that a few
// wrong ends, a stain's slanted edge, do not pull it. False with fewer than
// `min_count` observations of that crossing.
bool CrossingEndDirection(const std::vector<EndDirectionObservation>& all,
                          int crossing, int min_count,
                          Eigen::Vector2d* direction_2d);

// The bands of `bands` not longer than their crossing's (issue 52): a
// crossing's bands are painted of one length, so a band longer by more
// than BandOptions::max_crossing_length_excess_m than the longest of its
// crossing's other bands that a third one confirms (within
// crossing_length_agreement_m) is dropped. It runs on into paint beside
// the crossing in line with it (a bicycle square beyond its end) that the
// paint gaps (paint_gaps.h) could not tell apart: far away the short
// stretch of road between them is a pixel or two. A band cut short by the
// image's edge or an occluder is never the reference.
std::vector<Band> WithoutOverlongBands(std::vector<Band> bands,
                                       const BandOptions& options);

// The rule of WithoutOverlongBands for bands given by the crossing and the
// length of each: 1 for each band longer than its crossing's others.
std::vector<char> LongerThanTheirCrossings(const std::vector<int>& crossing_of,
                                           const std::vector<double>& length_m,
                                           const BandOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_CROSSING_REGULARITY_H_
