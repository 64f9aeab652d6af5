// Internal to the trajectory adjustment: the GNSS/INS error the matched road
// lines show, where no zebra crossing is control.
//
// Without control crossings the error model (adjustment_setup.cc) has no
// discrepancy to be fitted on, and its floor (min_position_sigma_m) would
// hold the trajectory within centimetres of the input: lines a metre off
// could not move it. The lines measure the error themselves, across the
// line (cross-track where the line runs with the vehicle) and in height,
// never along it: per time bin, the median of the line points' offsets
// (database minus the point placed with the INS trajectory) is one
// discrepancy in the track frame, its along-track axis without
// information.
#ifndef ZEBRAGEO_ADJUSTMENT_LINE_DISCREPANCIES_H_
#define ZEBRAGEO_ADJUSTMENT_LINE_DISCREPANCIES_H_

#include <vector>

#include "adjustment/adjustment_state.h"
#include "adjustment/control_selection.h"

namespace zebrageo {
namespace adjustment_internal {

// The variance given to an axis the lines do not measure (along-track, or
// cross-track from lines across the road): large enough that the Gauss-
// Markov fit learns nothing from it.
constexpr double kUnmeasuredVarianceM2 = 1e4;

// One discrepancy per `bin_s` seconds holding at least `min_points` line
// points (track frame at the bin: along-track, left, up; metres), in time
// order. The jumps of knot_prior are taken out as CrossingDiscrepancies
// does.
std::vector<CrossingDiscrepancy> LineDiscrepancies(const State& state,
                                                   double bin_s,
                                                   int min_points);

// One along-track discrepancy per whole dash matched to a database dash
// (LineControlPoint::along_track: database centre minus the reconstructed
// centre placed with the INS trajectory, along the dash, in the track
// frame), in time order; the other axes unmeasured. A dash also measures
// the cross-track error times the sine of its angle to the track: that
// part is in the variance (a metre unknown), and dashes more than 10
// degrees off the track are left out. The jumps of knot_prior are taken
// out.
std::vector<CrossingDiscrepancy> DashDiscrepancies(const State& state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_LINE_DISCREPANCIES_H_
