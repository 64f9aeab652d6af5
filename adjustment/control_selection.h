// Internal to the trajectory adjustment: which matched crossings may serve
// as control. Each crossing's discrepancy (database minus image-only
// position with the INS trajectory: the trajectory's error there plus the
// database's) is tested against what the other crossings and the GNSS/INS
// error model (error_model.h) predict at its time. The worst crossing that
// fails is removed and the test repeated, so that the largest consistent
// set remains: one repainted or wrongly matched crossing costs itself, not
// the control of the whole survey. A crossing that would fit once shifted
// by one band period across the crossing was matched one band off: it is
// named as such.
//
// Frames: discrepancies in the track frame at the crossing (along-track,
// left, up), metres.
#ifndef ZEBRAGEO_ADJUSTMENT_CONTROL_SELECTION_H_
#define ZEBRAGEO_ADJUSTMENT_CONTROL_SELECTION_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_state.h"
#include "adjustment/error_model.h"

namespace zebrageo {
namespace adjustment_internal {

struct CrossingDiscrepancy {
  bool valid = false;  // at least one vertex could be triangulated
  double time_s = 0.0;
  Eigen::Vector3d value_m = Eigen::Vector3d::Zero();      // track frame
  Eigen::Vector3d variance_m2 = Eigen::Vector3d::Zero();  // per axis
  // One band period across the crossing (track frame, horizontal).
  Eigen::Vector3d period_m = Eigen::Vector3d::Zero();
  int vertices = 0;
};

// Per crossing (index of ControlPoint::crossing), from the control and
// check points of `state` triangulated with its current correction (zero:
// the de-jumped INS trajectory; the jumps of knot_prior are added back).
// `period_enu` is each crossing's band period vector in ENU (zero when
// unknown).
std::vector<CrossingDiscrepancy> CrossingDiscrepancies(
    const AdjustmentOptions& options, const State& state,
    const std::vector<Eigen::Vector3d>& period_enu);

struct CrossingVerdict {
  bool consistent = true;
  bool one_period_off = false;
  double chi_square = 0.0;  // of its leave-one-out test when it failed
  std::string reason;
};

// The verdict per crossing. Crossings without a valid discrepancy are left
// consistent (untested). `names` label the reasons. A crossing that no
// other crossing or witness brackets on an axis (the other of two, or one
// beyond all the others) is tested with a horizontal sigma of at least
// two_crossings_sigma_m (AdjustmentOptions::two_crossings_position_sigma_m)
// on that axis.
// `witnesses`: discrepancies of other control (whole dashes,
// DashDiscrepancies; the road lines across the track, LineDiscrepancies)
// that vote in every test, on the axes they measure (variance below
// kUnmeasuredVarianceM2), and are never rejected here. With witnesses
// across the track (road lines) a lone crossing is tested too, against
// those alone: a repainted crossing that is the only one matched is
// otherwise control unchecked, and a whole dash, one mark matched alone,
// is not enough to judge it.
std::vector<CrossingVerdict> SelectConsistentCrossings(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<std::string>& names,
    const GaussMarkovFitOptions& fit_options, double chi_square_threshold,
    double two_crossings_sigma_m = 0.0,
    const std::vector<CrossingDiscrepancy>& witnesses = {});

// The Gauss-Markov fit of each axis (along, cross, up) of the crossings
// flagged in `use`.
std::vector<GaussMarkovFit> FitAxes(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<bool>& use, const GaussMarkovFitOptions& fit_options);

// The same with the witnesses (SelectConsistentCrossings) on the axes they
// measure.
std::vector<GaussMarkovFit> FitAxes(
    const std::vector<CrossingDiscrepancy>& crossings,
    const std::vector<bool>& use,
    const std::vector<CrossingDiscrepancy>& witnesses,
    const GaussMarkovFitOptions& fit_options);

// The other control that votes in the crossings' tests: whole dashes
// (along-track) and the road lines per time bin (across the track only).
std::vector<CrossingDiscrepancy> ControlWitnesses(
    const AdjustmentOptions& options, const State& state);

// The Gauss-Markov fit of the position process from the options' bounds.
GaussMarkovFitOptions PositionFitOptions(const AdjustmentOptions& options);

// Crossings that disagree with the others and the error model
// (SelectConsistentCrossings) are rejected whole, with a warning naming
// each; their points' normalized_residual is the test's sqrt(chi-square).
void RejectInconsistentCrossings(const Context& context,
                                 const CrossingTable& crossings,
                                 const std::vector<CrossingDiscrepancy>& d,
                                 State* state);

// Check crossings: every k-th consistent crossing in time order
// (k = 1 / check_crossing_share), as long as min_control_crossings remain;
// their control points become ControlStatus::kCheck.
void MarkCheckCrossings(const Context& context, const CrossingTable& crossings,
                        State* state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_CONTROL_SELECTION_H_
