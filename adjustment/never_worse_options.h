// Options of "never worse than the input" (issue 43): the hypotheses about a
// GNSS outage that the adjustment tests against the control
// (outage_model.h), and the guard that compares the adjusted trajectory with
// the input at every matched crossing before anything is written
// (control_guard.h). AdjustmentOptions::never_worse.
#ifndef ZEBRAGEO_ADJUSTMENT_NEVER_WORSE_OPTIONS_H_
#define ZEBRAGEO_ADJUSTMENT_NEVER_WORSE_OPTIONS_H_

#include <string>

namespace zebrageo {

struct NeverWorseOptions {
  // ------------------------------------------------------ outage model
  // A jump of the GNSS/INS position of at least this size (metres) where
  // GNSS may return after an outage is explained by each hypothesis of
  // outage_model.h (the INS drifted through an outage before it, the GNSS
  // came back wrong after it, or both), tested against the crossings; the
  // one that keeps the most control wins. 0 disables the hypotheses (the
  // jump is then a step, or the closure the stated sd spread).
  double outage_min_jump_m = 0.3;
  // The outage's start is unknown when the stated sd do not grow: its
  // length is tried from these seconds before the jump (up to the previous
  // jump or the trajectory's start).
  double outage_min_length_s = 10.0;
  double outage_max_length_s = 120.0;
  // GNSS part: after the return the GNSS error decays to the usual level
  // with this time constant.
  double gnss_return_decay_s = 30.0;

  // ------------------------------------------------------------ guard
  // Before the results are written, each matched crossing (control, check
  // or rejected) is placed with the input trajectory and with the adjusted
  // one: where the adjusted trajectory is farther from the database than
  // the input by more than guard_sigmas standard deviations of the
  // database's own error (its crossing offset and vertex sigma; 3: one
  // chance in 700 where both are as good), the input is kept over that
  // stretch. 0 disables the guard.
  double guard_sigmas = 3.0;
  // ... and only where the two trajectories place it at least this far
  // apart (metres): closer, nothing the user would see changes.
  double guard_min_difference_m = 0.05;
  // The database's error per crossing the test assumes at least (per axis,
  // metres): its stated vertex sigma averaged over the vertices plus the
  // crossing's systematic offset (SURVEY_FORMAT.md: 5-15 cm).
  double guard_crossing_sigma_m = 0.07;

  // "" when valid, else "field = value: constraint".
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("outage_min_jump_m", outage_min_jump_m);
    v("outage_min_length_s", outage_min_length_s);
    v("outage_max_length_s", outage_max_length_s);
    v("gnss_return_decay_s", gnss_return_decay_s);
    v("guard_sigmas", guard_sigmas);
    v("guard_min_difference_m", guard_min_difference_m);
    v("guard_crossing_sigma_m", guard_crossing_sigma_m);
  }
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_NEVER_WORSE_OPTIONS_H_
