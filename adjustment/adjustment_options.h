// The options of the trajectory adjustment (trajectory_adjuster.h), in
// groups: the GNSS/INS error model, the input trajectory's faults, the
// control points, their selection and blunders, road lines, tie points,
// the vehicle's motion, the rig, the posterior covariance and the solver.
// Each group is plain data with checked defaults (Check()) and lists its
// fields once (VisitFields, survey/option_json.h): the run's options JSON
// holds them as nested objects, each key a field's name.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OPTIONS_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OPTIONS_H_

#include <string>

#include "adjustment/never_worse_options.h"
#include "adjustment/solver_options.h"
#include "adjustment/trajectory_switches.h"
#include "survey/math_util.h"

namespace zebrageo {

// The correction and the GNSS/INS error model.
struct TrajectoryModelOptions {
  // Spacing of the B-spline knots. Shorter follows faster drift (GNSS
  // jumps) but needs more control per second; 0.5-2 s suits drifts with
  // periods of a minute.
  double knot_spacing_s = 1.0;
  // Express the correction in the track frame (along-track, cross-track,
  // up: dead-reckoning errors turn with the vehicle) or in ENU.
  bool track_frame = true;
  // The GNSS/INS error is modelled as what it is, a correlated process:
  // each component of the correction (attitude about along-track,
  // cross-track and up; position along-track, cross-track and up) is a
  // first-order Gauss-Markov process of standard deviation sigma and
  // correlation time tau (adjustment_state.h). Its innovations, not its
  // values, are independent: a drift is counted a few times per correlation
  // time, never once per knot, so the correction reaches the control where
  // there is control (no shrinkage towards the input), follows a metre-size
  // change over tens of metres where the control shows one, and returns to
  // the input trajectory where no control remains (about tau away).
  //
  // Position: sigma and tau of each axis are estimated from the control
  // (the discrepancies between the matched crossings and the INS
  // trajectory, by maximum likelihood with the database's own error
  // removed; error_model.h), within these bounds. With fewer than
  // min_crossings_for_tau crossings, tau is position_tau_s.
  bool estimate_position_model = true;
  double min_position_sigma_m = 0.03;
  double max_position_sigma_m = 5.0;
  double position_tau_s = 30.0;
  int min_crossings_for_tau = 3;
  // Attitude: sigma from the trajectory's own sd_roll, sd_pitch and
  // sd_heading (their median over the samples), at least
  // min_attitude_sigma_rad; where the data disagree with it beyond their
  // noise, the variance components widen it (up to max_attitude_sigma_rad).
  // Control and tie points measure attitude only to a few hundredths of a
  // degree: a loose attitude prior lets their noise make a good INS worse.
  double min_attitude_sigma_rad = DegToRad(0.003);
  double max_attitude_sigma_rad = DegToRad(0.5);
  double attitude_tau_s = 60.0;
  // Attitude significance: after the adjustment, each axis of the attitude
  // correction (about along-track, cross-track, up) is kept only where it
  // departs from the INS's attitude by at least this many of its posterior
  // standard deviations at some knot. Below that the control does not
  // determine the axis (a crossing seen from a few metres measures heading
  // to about a tenth of a degree, the INS's to a few hundredths): the axis
  // keeps the input attitude and the adjustment is solved again with it
  // held. 0 keeps every axis (needs the posterior covariance:
  // covariance.compute_covariance and max_knots_for_covariance).
  double attitude_significance = 2.0;
  // Variance components: after a solve, each soft constraint (vehicle
  // motion, tie points, the attitude prior) is checked against the data and
  // its sigma widened where its residuals show more than it states; the
  // adjustment is then repeated, at most max_variance_iterations times.
  bool estimate_variance_components = true;
  int max_variance_iterations = 3;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("knot_spacing_s", knot_spacing_s);
    v("track_frame", track_frame);
    v("estimate_position_model", estimate_position_model);
    v("min_position_sigma_m", min_position_sigma_m);
    v("max_position_sigma_m", max_position_sigma_m);
    v("position_tau_s", position_tau_s);
    v("min_crossings_for_tau", min_crossings_for_tau);
    v("min_attitude_sigma_rad", min_attitude_sigma_rad);
    v("max_attitude_sigma_rad", max_attitude_sigma_rad);
    v("attitude_tau_s", attitude_tau_s);
    v("attitude_significance", attitude_significance);
    v("estimate_variance_components", estimate_variance_components);
    v("max_variance_iterations", max_variance_iterations);
  }
};

// Faults of the input trajectory the adjustment takes out before it
// corrects the rest.
struct TrajectoryFaultOptions {
  // The fast part of the position error (trajectory_jitter.h): when the
  // trajectory's positions depart from a smooth path over
  // +-jitter_window_s by more than min_jitter_m (robust RMS, any axis),
  // each exposure gets its own position offset.
  double jitter_window_s = 1.5;
  double min_jitter_m = 0.005;
  // Jumps of the GNSS/INS solution (GNSS coming back after an outage): a
  // sample-to-sample step of the position (attitude) that departs from the
  // motion of the neighbouring samples by more than this. The adjustment
  // works on the trajectory with its jumps removed (the INS relative motion
  // is continuous) and the GNSS prior follows the jumps, so the correction
  // stays smooth; 0 disables the detection.
  double jump_threshold_m = 0.05;
  double jump_threshold_rad = DegToRad(0.05);
  // Switches of the GNSS error across the track spread over seconds
  // (multipath; trajectory_switches.h): taken out as jumps, so that a
  // correction measured on one side is not carried across with the error
  // the switch added.
  SidewaysSwitchOptions sideways_switches;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("jitter_window_s", jitter_window_s);
    v("min_jitter_m", min_jitter_m);
    v("jump_threshold_m", jump_threshold_m);
    v("jump_threshold_rad", jump_threshold_rad);
    v("sideways_switches", sideways_switches);
  }
};

// The matched band vertices as control and check points.
struct ControlPointOptions {
  // Each control vertex is observed as its exposure's stereo pair
  // reconstructed it (body-frame position and covariance of
  // reconstructed_bands.csv), the covariance scaled by
  // stereo_covariance_scale (the reconstruction's is optimistic by about
  // 2 in sigma on the field cases) with min_stereo_sigma_m added per axis.
  // With rig_calibration.self_calibrate_rig the image positions are used
  // instead (their reprojection through the corrected mounting), at
  // vertex_sigma_px.
  double stereo_covariance_scale = 4.0;
  double min_stereo_sigma_m = 0.005;
  // Sub-pixel band vertices in the images.
  double vertex_sigma_px = 0.5;
  // Huber loss on image residuals, in sigmas.
  double image_loss_scale = 3.0;
  // Floor on the database's own sigma_xy/sigma_z (a database that claims
  // millimetres is not believed).
  double min_database_sigma_m = 0.01;
  // Systematic offset of a whole database crossing (SURVEY_FORMAT.md: 5 to
  // 15 cm), per axis; 0 disables the offset unknowns.
  double crossing_offset_sigma_m = 0.07;
  // Cauchy loss on the database prior of a vertex, in sigmas.
  double control_loss_scale = 3.0;
  // Share of matched crossings held out as check points (every k-th
  // crossing in time order), as long as min_control_crossings remain.
  double check_crossing_share = 0.2;
  int min_control_crossings = 3;
  // Check crossings are held out of a first adjustment, which gives their
  // residuals (the honest accuracy), then the final adjustment uses every
  // crossing as control (the result is not weakened by the check). False:
  // check crossings stay out of the result.
  bool check_points_in_final = true;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("stereo_covariance_scale", stereo_covariance_scale);
    v("min_stereo_sigma_m", min_stereo_sigma_m);
    v("vertex_sigma_px", vertex_sigma_px);
    v("image_loss_scale", image_loss_scale);
    v("min_database_sigma_m", min_database_sigma_m);
    v("crossing_offset_sigma_m", crossing_offset_sigma_m);
    v("control_loss_scale", control_loss_scale);
    v("check_crossing_share", check_crossing_share);
    v("min_control_crossings", min_control_crossings);
    v("check_points_in_final", check_points_in_final);
  }
};

// Before the adjustment, each crossing is tested against the others and
// the GNSS/INS error model (control_selection.h).
struct ControlSelectionOptions {
  // A leave-one-out chi-square (3 degrees of freedom) above this rejects
  // a crossing, worst first, until the rest agree (16.27: p = 0.001).
  double crossing_consistency_chi_square = 16.27;
  // A crossing tested against others all on one side of it (the other of
  // two, or a cluster 150 m away: seed 428) meets an error model fitted
  // there, which says nothing of how the error changes on the way: one
  // near the INS trajectory would make a metre-size drift over tens of
  // metres (multipath, issue 17) look like a blunder, and with two which
  // is dropped is a toss. The horizontal sigma of that test is at least
  // this (a GNSS/INS error in a city: decimetres to metres) on each axis
  // that no other crossing or whole dash measures on both sides of it;
  // only a jump it cannot explain rejects one.
  double two_crossings_position_sigma_m = 1.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("crossing_consistency_chi_square", crossing_consistency_chi_square);
    v("two_crossings_position_sigma_m", two_crossings_position_sigma_m);
  }
};

// Control vertices the images and the database disagree on.
struct BlunderOptions {
  // A control vertex is rejected when its normalised residual (image-only
  // position minus database, Mahalanobis with the database sigma, the
  // crossing offset, the triangulation and blunder_sigma_floor_m) exceeds
  // this. 5 is far in the tail of chi(3) (p < 1e-4).
  double blunder_threshold = 5.0;
  double blunder_sigma_floor_m = 0.03;
  int max_blunder_iterations = 6;
  // A crossing with more than this share of its vertices rejected is
  // rejected whole (repainted, wrongly matched).
  double reject_crossing_share = 0.5;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("blunder_threshold", blunder_threshold);
    v("blunder_sigma_floor_m", blunder_sigma_floor_m);
    v("max_blunder_iterations", max_blunder_iterations);
    v("reject_crossing_share", reject_crossing_share);
  }
};

// Matched road lines as control (line_costs.h).
struct LineControlOptions {
  // Cauchy loss on the point-to-line residuals, in sigmas.
  double line_loss_scale = 3.0;
  // Without a control crossing, matched road lines are the control: the
  // GNSS/INS error model is then fitted on their offsets, pooled per
  // line_discrepancy_bin_s seconds holding at least
  // line_discrepancy_min_points points (line_discrepancies.h); the
  // along-track position keeps the input's. line_control_without_crossings
  // = false keeps the input trajectory instead.
  bool line_control_without_crossings = true;
  double line_discrepancy_bin_s = 2.0;
  int line_discrepancy_min_points = 5;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("line_loss_scale", line_loss_scale);
    v("line_control_without_crossings", line_control_without_crossings);
    v("line_discrepancy_bin_s", line_discrepancy_bin_s);
    v("line_discrepancy_min_points", line_discrepancy_min_points);
  }
};

// Image tie points between exposures (tiepoints/).
struct TiePointWeightOptions {
  // Per pyramid scale of the feature (tie_points.h: 1.2^octave): a corner
  // found on a coarser ORB level is localised that much less precisely.
  double tie_sigma_px = 1.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("tie_sigma_px", tie_sigma_px);
  }
};

// The non-holonomic constraint (vehicle_motion.h): the vehicle moves along
// its heading, so the direction of travel of the corrected positions holds
// the heading where only they are controlled (between and beyond
// crossings, along road lines), and their height the pitch.
struct VehicleMotionOptions {
  // sideslip_sigma_rad, vertical_slip_sigma_rad: the spread of the angle
  // between the velocity and the body's x axis (lateral, vertical) from the
  // body's oscillations, per constraint (they average out over a second or
  // two); sideslip_sigma_rad = 0 disables both. (The CLI's
  // --sideslip-sigma is in degrees.)
  double sideslip_sigma_rad = DegToRad(0.1);
  double vertical_slip_sigma_rad = DegToRad(0.35);
  double vehicle_motion_rate_hz = 10.0;
  // The sideslip's departures are correlated over about this time (the
  // body rolling and yawing on its suspension, the driver's steering):
  // constraints closer than that are not counted as independent.
  double vehicle_motion_correlation_s = 1.0;
  // Half-length of the chord giving the velocity (at least; the chord
  // joins trajectory samples).
  double vehicle_motion_half_chord_s = 0.05;
  // Below this speed the direction of travel is not used.
  double vehicle_motion_min_speed_mps = 2.0;
  // Priors of the vehicle block: the INS's yaw and pitch misalignment to
  // the vehicle's axis, and its distance ahead of the axle that does not
  // slip.
  double vehicle_misalignment_sigma_rad = DegToRad(1.0);
  // With road lines alone as control the yaw misalignment is not separable
  // from a cross-track ramp: lines seen over a few seconds across a
  // multipath switch were fitted by a 2.4 degree misalignment and a ramp
  // that the vehicle-motion constraint then carried 58 m beyond them, to
  // 2.6 m across the track where the input was 0.74 m off (geometry seed
  // 360). There the INS's heading is trusted to this (geometry sweep 1-500:
  // seeds 360, 452, 471 H 135 -> 115, 18 -> 12, 33 -> 14 cm, one crossing
  // more matched; 501-1000 unchanged but seed 943 52 -> 49 cm).
  double lines_only_misalignment_sigma_rad = DegToRad(0.1);
  double axle_offset_sigma_m = 3.0;
  // Cauchy loss on the constraint, in sigmas (a skid, a wrong sample).
  double vehicle_motion_loss_scale = 3.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("sideslip_sigma_rad", sideslip_sigma_rad);
    v("vertical_slip_sigma_rad", vertical_slip_sigma_rad);
    v("vehicle_motion_rate_hz", vehicle_motion_rate_hz);
    v("vehicle_motion_correlation_s", vehicle_motion_correlation_s);
    v("vehicle_motion_half_chord_s", vehicle_motion_half_chord_s);
    v("vehicle_motion_min_speed_mps", vehicle_motion_min_speed_mps);
    v("vehicle_misalignment_sigma_rad", vehicle_misalignment_sigma_rad);
    v("lines_only_misalignment_sigma_rad", lines_only_misalignment_sigma_rad);
    v("axle_offset_sigma_m", axle_offset_sigma_m);
    v("vehicle_motion_loss_scale", vehicle_motion_loss_scale);
  }
};

// Each camera's boresight rotation and lever arm, estimated (shared by
// all exposures) with these priors around rig.yaml.
struct RigCalibrationOptions {
  bool self_calibrate_rig = false;
  double boresight_sigma_rad = DegToRad(0.2);
  double lever_arm_sigma_m = 0.02;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("self_calibrate_rig", self_calibrate_rig);
    v("boresight_sigma_rad", boresight_sigma_rad);
    v("lever_arm_sigma_m", lever_arm_sigma_m);
  }
};

// Posterior covariance of the corrected positions (trajectory sd_* of the
// output) when the problem has at most max_knots_for_covariance knots.
// From it, the stretches where one axis (along-track, cross-track, up) is
// weakly held (issue 51): its posterior sd above weak_sd_database_factor
// times the database's stated sd of that axis (the median sigma_xy of the
// zebra bands for along and cross, sigma_z for up), and never below
// weak_sd_floor_m, or no control holding it within weak_control_radius_m
// (zebra control vertices hold every axis; road-line points hold
// cross-track and height, along-track only those across the track or on a
// dash's ends), over at least weak_min_length_m of trajectory. The sd alone
// is not enough: the error model estimated from a few crossings can be
// tighter than the drift between them.
struct CovarianceOptions {
  bool compute_covariance = true;
  int max_knots_for_covariance = 3000;
  double weak_sd_database_factor = 2.0;
  double weak_sd_floor_m = 0.1;
  double weak_control_radius_m = 30.0;
  double weak_min_length_m = 30.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("compute_covariance", compute_covariance);
    v("max_knots_for_covariance", max_knots_for_covariance);
    v("weak_sd_database_factor", weak_sd_database_factor);
    v("weak_sd_floor_m", weak_sd_floor_m);
    v("weak_control_radius_m", weak_control_radius_m);
    v("weak_min_length_m", weak_min_length_m);
  }
};

struct AdjustmentOptions {
  TrajectoryModelOptions model;
  TrajectoryFaultOptions trajectory_faults;
  ControlPointOptions control;
  ControlSelectionOptions selection;
  BlunderOptions blunders;
  LineControlOptions road_lines;
  TiePointWeightOptions tie_points;
  VehicleMotionOptions vehicle_motion;
  RigCalibrationOptions rig_calibration;
  CovarianceOptions covariance;
  // Never worse than the input (issue 43): a GNSS outage's hypotheses
  // tested against the control, and the guard that keeps the input where
  // the adjusted trajectory fits the matched crossings worse.
  NeverWorseOptions never_worse;
  SolverOptions solver;
  // Warnings go to summary.warnings and, when true, to the log as
  // warnings. False for a trial adjustment the user never gets (the road
  // lines alone, on which the second registration pass searches: its
  // warnings would describe a result nobody receives); they are logged at
  // VLOG(1).
  bool log_warnings = true;

  // "" when valid, else "group.field = value: constraint".
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("model", model);
    v("trajectory_faults", trajectory_faults);
    v("control", control);
    v("selection", selection);
    v("blunders", blunders);
    v("road_lines", road_lines);
    v("tie_points", tie_points);
    v("vehicle_motion", vehicle_motion);
    v("rig_calibration", rig_calibration);
    v("covariance", covariance);
    v("never_worse", never_worse);
    v("solver", solver);
    v("log_warnings", log_warnings);
  }
};

// Logs `warning` as log_warnings says (a warning, or VLOG(1)).
void LogAdjustmentWarning(const AdjustmentOptions& options,
                          const std::string& warning);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_OPTIONS_H_
