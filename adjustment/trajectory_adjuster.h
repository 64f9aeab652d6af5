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
//   - the GNSS/INS solution: the correction at each knot is 0 +- gnss_*,
//     counted once per prior_correlation_time_s (Cauchy loss: a GNSS jump
//     is an outlier, not a constraint); gnss_* are estimated from the
//     control first (variance components: what the crossings' discrepancies
//     hold beyond the database's own error), so a drift smaller than the
//     database's error is not "corrected" into that error;
//   - the vehicle's motion: it moves along its heading (vehicle_motion.h),
//     sigma sideslip_sigma_deg per constraint, Cauchy loss;
//   - the INS relative motion: the drift rate (first difference of knots,
//     at most what a Gauss-Markov drift of sigma gnss_* and correlation
//     time prior_correlation_time_s allows) and its change (second
//     difference) are small; they set how fast the correction may vary
//     between control points.
// Solved with Ceres (SPARSE_SCHUR on SuiteSparse: points eliminated, the
// banded knot system factorised), first without robust losses to take out
// the drift, then robustly; then control vertices whose image-only position
// disagrees with the database (normalised residual above
// blunder_threshold) are removed and the adjustment repeated. A share of
// crossings is held out as check points: their residuals come from an
// adjustment without them; the final adjustment then uses them as control
// (check_points_in_final).
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "adjustment/line_control.h"
#include "adjustment/solver_options.h"
#include "adjustment/tie_points.h"
#include "adjustment/trajectory_correction.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
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
  // The GNSS/INS absolute position, per knot: realistic, not the file's
  // optimistic sd_* (urban drift reaches metres). Cauchy loss of scale
  // gnss_loss_scale (in sigmas).
  double gnss_sigma_horizontal_m = 1.0;
  double gnss_sigma_vertical_m = 1.0;
  double gnss_loss_scale = 1.0;
  // Variance component estimation of the two sigmas above (upper bounds
  // then): the mean square discrepancy between the control crossings and
  // the INS trajectory, minus the database's own error. A drift the control
  // does not show beyond the database's error is then not "corrected" into
  // that error (an adjustment must not make the trajectory worse).
  bool estimate_gnss_sigma = true;
  double min_gnss_sigma_m = 0.03;
  // The INS absolute attitude, tilt and heading apart: they drift
  // differently. Tilt (roll, pitch) is held by gravity; its prior holds per
  // knot (0.2 deg per knot bounds the mean tilt correction over the
  // correlation time to about 0.04 deg, a tactical-grade INS's tilt drift),
  // and the data hold tilt only weakly (a crossing's database heights give
  // its tilt to about 0.2 deg). Heading drifts like the position (a few
  // hundredths of a degree to a tenth), once per prior_correlation_time_s:
  // counting it per knot would hold the heading to the INS's where only
  // the vehicle's motion and road lines control it. A better INS: lower
  // ins_tilt_sigma_deg.
  double ins_tilt_sigma_deg = 0.2;
  double ins_heading_sigma_deg = 0.2;
  // Correlation time of the GNSS/INS error (its drift): the two priors
  // above hold once per this time, so each knot's prior is widened by
  // sqrt(prior_correlation_time_s / knot_spacing_s).
  double prior_correlation_time_s = 30.0;
  // Drift rate: how fast the position/attitude error may change (first
  // difference of knots / spacing), per knot interval.
  double drift_rate_sigma_mps = 0.2;
  double drift_rate_sigma_deg_per_s = 0.02;
  // Change of the drift rate (second difference / spacing^2): the smoothness
  // of the correction between control points. A drift of peak A and period
  // T has an acceleration of A (2 pi / T)^2: 2 m over 60 s gives 0.02.
  double drift_acceleration_sigma_mps2 = 0.01;
  double drift_angular_acceleration_sigma_deg_per_s2 = 0.001;
  // Jumps of the GNSS/INS solution (GNSS coming back after an outage): a
  // sample-to-sample step of the position (attitude) that departs from the
  // motion of the neighbouring samples by more than this. The adjustment
  // works on the trajectory with its jumps removed (the INS relative motion
  // is continuous) and the GNSS prior follows the jumps, so the correction
  // stays smooth; 0 disables the detection.
  double jump_threshold_m = 0.05;
  double jump_threshold_deg = 0.05;

  // ---------------------------------------------------- control points
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
  // ---------------------------------------------------- tie points
  // Per pyramid scale of the feature (tie_points.h: 1.2^octave): a corner
  // found on a coarser ORB level is localised that much less precisely.
  double tie_sigma_px = 1.0;

  // ---------------------------------------------------- vehicle motion
  // The non-holonomic constraint (vehicle_motion.h): the vehicle moves
  // along its heading, so the direction of travel of the corrected
  // positions holds the heading where only they are controlled (between
  // and beyond crossings, along road lines), and their height the pitch.
  // sideslip_sigma_deg, vertical_slip_sigma_deg: the spread of the angle
  // between the velocity and the body's x axis (lateral, vertical) from the
  // body's oscillations, per constraint (they average out over a second or
  // two); sideslip_sigma_deg = 0 disables both.
  double sideslip_sigma_deg = 0.1;
  double vertical_slip_sigma_deg = 0.35;
  double vehicle_motion_rate_hz = 10.0;
  // Half-length of the chord giving the velocity (at least; the chord
  // joins trajectory samples).
  double vehicle_motion_half_chord_s = 0.05;
  // Below this speed the direction of travel is not used.
  double vehicle_motion_min_speed_mps = 2.0;
  // Priors of the vehicle block: the INS's yaw and pitch misalignment to
  // the vehicle's axis, and its distance ahead of the axle that does not
  // slip.
  double vehicle_misalignment_sigma_deg = 1.0;
  double axle_offset_sigma_m = 3.0;
  // Cauchy loss on the constraint, in sigmas (a skid, a wrong sample).
  double vehicle_motion_loss_scale = 3.0;

  // ---------------------------------------------------- rig calibration
  // Estimate each camera's boresight rotation and lever arm (shared by all
  // exposures) with these priors around rig.yaml.
  bool self_calibrate_rig = false;
  double boresight_sigma_deg = 0.2;
  double lever_arm_sigma_m = 0.02;

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
  // Size of the correction applied to the trajectory samples.
  // GNSS/INS position sigma of the prior (estimated or as configured).
  double gnss_sigma_horizontal_m = 0.0;
  double gnss_sigma_vertical_m = 0.0;
  double max_correction_horizontal_m = 0.0;
  double max_correction_vertical_m = 0.0;
  double rms_correction_horizontal_m = 0.0;
  // Vehicle-motion constraint: number of constraints, the estimated INS
  // yaw and pitch misalignment and axle offset.
  int num_vehicle_motion = 0;
  double vehicle_yaw_misalignment_deg = 0.0;
  double vehicle_pitch_misalignment_deg = 0.0;
  double vehicle_axle_offset_m = 0.0;
  // Jumps found in the input trajectory (GNSS returns).
  int num_jumps = 0;
  // Posterior sd of the corrected positions (median over the samples, 0
  // when not computed).
  double median_posterior_sd_horizontal_m = 0.0;
  double median_posterior_sd_vertical_m = 0.0;
  bool covariance_computed = false;

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
