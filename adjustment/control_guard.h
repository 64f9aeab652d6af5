// The guard of "never worse than the input" (issue 43): before anything is
// written, every matched crossing (control, check or rejected alike) is
// placed from its images twice, with the input trajectory and with the
// adjusted one, and compared with the database. Where the adjusted
// trajectory puts a crossing farther from the database than the input does,
// beyond what the database's own error can explain, the adjusted
// trajectory is worse there by the survey's own control, whatever the
// model that made it says: that stretch keeps the input trajectory.
//
// The test: with r_in and r_adj the crossing's database-minus-image
// residuals under the two trajectories (median over its vertices, ENU) and
// e the database's error (common to both, per axis sd sigma), the adjusted
// trajectory is farther from the truth than the input when
//   |r_adj - e|^2 - |r_in - e|^2 = d.(r_adj + r_in) - 2 d.e > 0,
// d = r_adj - r_in (the two trajectories' difference there, known). The
// crossing is worse when z = d.(r_adj + r_in) / (2 |sigma o d|) exceeds
// NeverWorseOptions::guard_sigmas and |d| guard_min_difference_m. A crossing
// the adjustment rejected (repainted, moved in the database: wrong itself, not
// the trajectory) objects only where the input also fits it at least twice as
// well as the adjusted trajectory: a wrong crossing 1.5 m off that the input
// misses by 1 m says nothing of either.
//
// Plain data in and out: this file knows nothing of the adjustment's state.
// Frames: ENU metres; times in the trajectory's seconds.
#ifndef ZEBRAGEO_ADJUSTMENT_CONTROL_GUARD_H_
#define ZEBRAGEO_ADJUSTMENT_CONTROL_GUARD_H_

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "adjustment/never_worse_options.h"

namespace zebrageo {

// One matched crossing: its vertices' database positions and their
// positions from the images with each trajectory (same order).
struct GuardCrossing {
  std::string id;
  double first_time_s = 0.0;  // its first and last observation
  double last_time_s = 0.0;
  bool used = true;  // control or check; false: rejected
  std::vector<Eigen::Vector3d> database_enu;
  std::vector<Eigen::Vector3d> input_enu;
  std::vector<Eigen::Vector3d> adjusted_enu;
  // sd of the database's error of the crossing's median residual, per
  // ENU axis.
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Constant(0.07);
};

struct GuardVerdict {
  std::string id;
  double first_time_s = 0.0;
  double last_time_s = 0.0;
  bool used = true;
  // |median residual| with each trajectory, metres.
  double input_misfit_m = 0.0;
  double adjusted_misfit_m = 0.0;
  // The evidence that the adjusted trajectory is farther from the truth
  // here, in sd of the database's error (negative: nearer).
  double z = 0.0;
  bool worse = false;
};

// A stretch where the input trajectory is kept: whole over
// [begin_s, end_s], blended with the adjusted one towards the crossings
// that do not object over [ramp_begin_s, begin_s] and [end_s, ramp_end_s]
// (infinite where no such crossing lies on that side).
struct KeptStretch {
  double ramp_begin_s = 0.0;
  double begin_s = 0.0;
  double end_s = 0.0;
  double ramp_end_s = 0.0;
  std::vector<std::string> crossings;  // the crossings that objected
  double input_misfit_m = 0.0;         // their largest misfits
  double adjusted_misfit_m = 0.0;
};

struct GuardResult {
  std::vector<GuardVerdict> verdicts;  // in time order
  std::vector<KeptStretch> kept;
  bool Fired() const { return !kept.empty(); }
  // 1 where the adjusted trajectory stands, 0 where the input is kept,
  // linear in time between a crossing that objected and one that did not.
  double AdjustedWeight(double time_s) const;
  // Whether the input is kept (partly) everywhere: no crossing stands by
  // the adjusted trajectory.
  bool KeepsInputEverywhere() const;

  // (time, weight) at each crossing's first and last observation, in time
  // order: AdjustedWeight interpolates them.
  std::vector<std::pair<double, double>> weight_knots;
};

// The verdict per crossing and the stretches that keep the input. Crossings
// without a vertex are ignored. guard_sigmas = 0: never fires.
GuardResult GuardAgainstInput(const std::vector<GuardCrossing>& crossings,
                              const NeverWorseOptions& options);

// The report's sentence for a stretch ("from 12.3 s to 45.6 s the input
// trajectory is kept: ..."), times relative to `time_origin_s`.
std::string KeptStretchText(const KeptStretch& stretch, double time_origin_s);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_CONTROL_GUARD_H_
