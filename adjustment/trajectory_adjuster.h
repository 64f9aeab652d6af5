// The trajectory adjustment (issue 7): a bundle adjustment that corrects the
// drifting GNSS/INS trajectory with matched zebra-band vertices as ground
// control points and image tie points.
//
// Unknowns: the trajectory correction (trajectory_correction.h: cubic
// B-spline of [dtheta, dp] in ENU, knots every knot_spacing_s), one 3D point
// (ENU) per control vertex and per tie track, one systematic offset (ENU)
// per database crossing, and optionally each camera's mounting correction
// (boresight rotation, lever arm).
// Observations (all whitened, see cost_functions.h):
//   - reprojection of control vertices (uv_left/uv_right of
//     reconstructed_bands.csv), sigma vertex_sigma_px, Huber loss;
//   - reprojection of tie points, sigma tie_sigma_px, Huber loss;
//   - the database position of each control vertex (sigma_xy, sigma_z of
//     the database) plus its crossing's offset (crossing_offset_sigma_m),
//     Cauchy loss;
//   - the GNSS/INS solution: the correction is a correlated (Gauss-Markov)
//     process whose sigma and correlation time are estimated from the
//     control for the position and taken from the trajectory's own sd_* for
//     the attitude (see AdjustmentOptions); where the positions jitter from
//     sample to sample, each exposure has its own offset on top
//     (trajectory_jitter.h);
//   - the vehicle's motion: it moves along its heading (vehicle_motion.h),
//     Cauchy loss; road-line points (line_control.h), Cauchy loss.
// The soft constraints' sigmas are checked against their residuals and
// widened where the data show more spread (variance components). Solved
// with Ceres (SPARSE_SCHUR on SuiteSparse: points eliminated, the banded
// knot system factorised), first without robust losses to take out the
// drift, then robustly; then control vertices whose image-only position
// disagrees with the database (normalised residual above
// blunder_threshold) are removed and the adjustment repeated. Before that,
// each crossing is tested against the others and the GNSS/INS error model
// (control_selection.h): the largest consistent set is kept, a crossing one
// band period away from it is named as such. A share of crossings is held
// out as check points: their residuals come from an adjustment without
// them; the final adjustment then uses them as control
// (check_points_in_final). The attitude axes whose correction the control
// does not determine (attitude_significance) are then held at the input's
// and the adjustment solved again. Without any usable control the input
// trajectory is returned unchanged.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "adjustment/control_guard.h"
#include "adjustment/line_control.h"
#include "adjustment/never_worse_options.h"
#include "adjustment/solver_options.h"
#include "adjustment/trajectory_correction.h"
#include "adjustment/trajectory_switches.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/math_util.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/tie_tracks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct AdjustmentOptions {
  // ---------------------------------------------------- trajectory model
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
  // The fast part of the position error (trajectory_jitter.h): when the
  // trajectory's positions depart from a smooth path over
  // +-jitter_window_s by more than min_jitter_m (robust RMS, any axis),
  // each exposure gets its own position offset.
  double jitter_window_s = 1.5;
  double min_jitter_m = 0.005;
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
  // compute_covariance and max_knots_for_covariance).
  double attitude_significance = 2.0;
  // Variance components: after a solve, each soft constraint (vehicle
  // motion, tie points, the attitude prior) is checked against the data and
  // its sigma widened where its residuals show more than it states; the
  // adjustment is then repeated, at most max_variance_iterations times.
  bool estimate_variance_components = true;
  int max_variance_iterations = 3;
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
  // Never worse than the input (issue 43): a GNSS outage's hypotheses
  // tested against the control, and the guard that keeps the input where
  // the adjusted trajectory fits the matched crossings worse.
  NeverWorseOptions never_worse;

  // ---------------------------------------------------- control points
  // Each control vertex is observed as its exposure's stereo pair
  // reconstructed it (body-frame position and covariance of
  // reconstructed_bands.csv), the covariance scaled by
  // stereo_covariance_scale (the reconstruction's is optimistic by about
  // 2 in sigma on the field cases) with min_stereo_sigma_m added per axis.
  // With self_calibrate_rig the image positions are used instead (their
  // reprojection through the corrected mounting), at vertex_sigma_px.
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

  // ---------------------------------------------------- control selection
  // Before the adjustment, each crossing is tested against the others and
  // the GNSS/INS error model (control_selection.h): a leave-one-out
  // chi-square (3 degrees of freedom) above this rejects it, worst first,
  // until the rest agree (16.27: p = 0.001).
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

  // ---------------------------------------------------- blunders
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

  // ---------------------------------------------------- road lines
  // Cauchy loss on the point-to-line residuals (line_control.h), in sigmas.
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
  // ---------------------------------------------------- tie points
  // Per pyramid scale of the feature (tie_points.h: 1.2^octave): a corner
  // found on a coarser ORB level is localised that much less precisely.
  double tie_sigma_px = 1.0;

  // ---------------------------------------------------- vehicle motion
  // The non-holonomic constraint (vehicle_motion.h): the vehicle moves
  // along its heading, so the direction of travel of the corrected
  // positions holds the heading where only they are controlled (between
  // and beyond crossings, along road lines), and their height the pitch.
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

  // ---------------------------------------------------- rig calibration
  // Estimate each camera's boresight rotation and lever arm (shared by all
  // exposures) with these priors around rig.yaml.
  bool self_calibrate_rig = false;
  double boresight_sigma_rad = DegToRad(0.2);
  double lever_arm_sigma_m = 0.02;

  // ---------------------------------------------------- reporting
  // Warnings go to summary.warnings and, when true, to the log as
  // warnings. False for a trial adjustment the user never gets (the road
  // lines alone, on which the second registration pass searches: its
  // warnings would describe a result nobody receives); they are logged at
  // VLOG(1).
  bool log_warnings = true;

  // ---------------------------------------------------- covariance
  // Posterior covariance of the corrected positions (trajectory sd_* of the
  // output) when the problem has at most this many knots.
  bool compute_covariance = true;
  int max_knots_for_covariance = 3000;

  SolverOptions solver;

  // "" when valid, else "field = value: constraint".
  std::string Check() const;
};

// What the adjustment reads. Pointers to data owned by the caller; the
// vertex and match lists are the reconstruction's and the registration's
// outputs, tie tracks are optional.
struct AdjustmentInput {
  const Rig* rig = nullptr;
  const LocalFrame* frame = nullptr;
  const Trajectory* trajectory = nullptr;
  const ExposureTable* exposures = nullptr;
  const RoadmarkDatabase* roadmarks = nullptr;
  const std::vector<ReconstructedVertex>* vertices = nullptr;
  const std::vector<VertexMatch>* matches = nullptr;
  const std::vector<TieTrack>* tie_tracks = nullptr;
  // Matched road-line points (issue 9), optional.
  const std::vector<LineControlPoint>* line_points = nullptr;
};

enum class ControlStatus {
  kControl,   // used in the adjustment
  kCheck,     // held out, evaluated only
  kRejected,  // blunder: removed from the adjustment
};
const char* ControlStatusName(ControlStatus status);

// One database vertex observed in the images.
struct ControlPointResult {
  std::string crossing_id;
  int band = 0;
  int db_vertex = 0;
  ControlStatus status = ControlStatus::kControl;
  Eigen::Vector3d database_enu = Eigen::Vector3d::Zero();
  // Adjusted position (control), else the image-only position.
  Eigen::Vector3d adjusted_enu = Eigen::Vector3d::Zero();
  // Triangulated from the images with the corrected trajectory alone.
  Eigen::Vector3d image_enu = Eigen::Vector3d::Zero();
  double normalized_residual = 0.0;
  double rms_px = 0.0;
  int n_images = 0;
};

// RMS of one type of observation before (INS trajectory, database points)
// and after the adjustment, in its unit.
struct ObservationRms {
  std::string type;
  std::string unit;
  int count = 0;
  double before = 0.0;
  double after = 0.0;
};

struct AdjustmentSummary {
  bool usable = false;
  std::string message;  // why not usable, or a one-line result
  std::vector<std::string> warnings;
  double sigma0 = 0.0;  // a-posteriori standard deviation of unit weight
  int iterations = 0;   // Ceres iterations, all solves
  int solves = 0;
  double time_in_seconds = 0.0;
  int num_exposures = 0;
  int num_knots = 0;
  int num_control_points = 0;
  int num_check_points = 0;
  int num_rejected_points = 0;
  int num_control_crossings = 0;
  int num_check_crossings = 0;
  // The check points were held out of a first adjustment only (their
  // residuals are from it) and are control in the final one.
  bool check_points_in_final = false;
  int num_tie_tracks = 0;
  int num_residuals = 0;
  std::vector<ObservationRms> rms;
  // Adjusted (control) or image-only (check) minus database, metres.
  double control_rmse_horizontal_m = 0.0;
  double control_rmse_vertical_m = 0.0;
  // Over the check points that could be triangulated (their count): 0
  // when there are none, which the reports write as null, not as 0.
  double check_rmse_horizontal_m = 0.0;
  double check_rmse_vertical_m = 0.0;
  int num_check_points_evaluated = 0;
  // A check residual holds the database's error too (per the adjustment's
  // model of it: the stated vertex sigma and crossing_offset_sigma_m): its
  // expected RMS, and the trajectory error the check RMSE implies once it
  // is removed, sqrt(max(0, rmse^2 - database^2)). The check points measure
  // the adjustment made without them (fewer control crossings), so this is
  // a pessimistic figure for the final trajectory.
  double check_database_rms_horizontal_m = 0.0;
  double check_database_rms_vertical_m = 0.0;
  double check_implied_trajectory_horizontal_m = 0.0;
  double check_implied_trajectory_vertical_m = 0.0;
  // The GNSS/INS error model of the final adjustment (estimated or as
  // configured): per axis along-track, cross-track, up (attitude: about
  // them), and the vehicle-motion and tie sigmas after variance components.
  Eigen::Vector3d position_sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_tau_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d attitude_sigma_rad = Eigen::Vector3d::Zero();
  Eigen::Vector2d motion_sigma_rad = Eigen::Vector2d::Zero();
  double tie_sigma_px = 0.0;
  // Size of the correction applied to the trajectory samples.
  double max_correction_horizontal_m = 0.0;
  double max_correction_vertical_m = 0.0;
  double rms_correction_horizontal_m = 0.0;
  // Vehicle-motion constraint: number of constraints, the estimated INS
  // yaw and pitch misalignment and axle offset.
  int num_vehicle_motion = 0;
  double vehicle_yaw_misalignment_deg = 0.0;
  double vehicle_pitch_misalignment_deg = 0.0;
  double vehicle_axle_offset_m = 0.0;
  // Attitude axes (along-track, cross-track, up) held at the input's for
  // lack of significance (attitude_significance), and each axis' largest
  // correction over its posterior sd.
  Eigen::Vector3i attitude_held = Eigen::Vector3i::Zero();
  Eigen::Vector3d attitude_significance = Eigen::Vector3d::Zero();
  // Jumps found in the input trajectory (GNSS returns).
  int num_jumps = 0;
  // The guard (control_guard.h): each matched crossing placed with the
  // input and the adjusted trajectory, and the stretches where the input
  // was kept because the adjusted trajectory fitted them worse.
  std::vector<GuardVerdict> guard_verdicts;
  std::vector<KeptStretch> kept_input;
  // Posterior sd of the corrected positions (median over the samples, 0
  // when not computed).
  double median_posterior_sd_horizontal_m = 0.0;
  double median_posterior_sd_vertical_m = 0.0;
  bool covariance_computed = false;
  // Whether the trajectory was corrected (else the poses are the input's),
  // and whether road lines were its only control (no zebra crossing: the
  // along-track position is the input's unless crossing edges hold it).
  bool corrected = false;
  bool line_control_only = false;

  bool IsUsable() const { return usable; }
  std::string BriefReport() const;
};

struct AdjustmentResult {
  AdjustmentSummary summary;
  TrajectoryCorrection correction;
  // One per input sample, same times; sd_* are the posterior ones when
  // computed, else the input's.
  std::vector<TrajectorySample> corrected_samples;
  std::vector<Pose> corrected_poses;  // ENU, per sample
  // One per row of exposures.csv (camera projection centre, camera-to-ENU).
  std::vector<CameraPose> camera_poses;
  std::vector<ControlPointResult> control_points;
  // Each reconstructed band placed with the corrected trajectory.
  std::vector<AdjustedBand> bands;
  // Adjusted rig mounting (rig.yaml's when not self-calibrating).
  std::vector<Eigen::Isometry3d> T_body_cam;
  // Tie points after adjustment (ENU), with their tracks.
  std::vector<TieTrack> tie_tracks;
};

// Logs `warning` as log_warnings says (a warning, or VLOG(1)).
void LogAdjustmentWarning(const AdjustmentOptions& options,
                          const std::string& warning);

// Runs the adjustment. Never throws on bad data and never returns NaN
// poses: a failed solve gives summary.usable = false and the reason in
// summary.message. Without any usable control the input trajectory is
// returned unchanged with a warning (usable). `progress(done, total)` is
// called after each solve when set.
AdjustmentResult AdjustTrajectory(
    const AdjustmentOptions& options, const AdjustmentInput& input,
    const std::function<void(int, int)>& progress = nullptr);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_
