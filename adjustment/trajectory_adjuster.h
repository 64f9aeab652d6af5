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
//     Cauchy loss; road-line points (line_costs.h), Cauchy loss.
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

#include "adjustment/adjustment_options.h"
#include "adjustment/control_guard.h"
#include "adjustment/line_costs.h"
#include "adjustment/trajectory_correction.h"
#include "adjustment/weak_control.h"
#include "survey/cancellation.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/math_util.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/tie_tracks.h"
#include "survey/trajectory.h"

namespace zebrageo {

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
  // Stretches where an axis' posterior sd exceeds its threshold
  // (CovarianceOptions::weak_sd_*; empty without the covariance).
  std::vector<WeakStretch> weak_stretches;
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

// Runs the adjustment. Never throws on bad data and never returns NaN
// poses: a failed solve gives summary.usable = false and the reason in
// summary.message. Without any usable control the input trajectory is
// returned unchanged with a warning (usable). `progress(done, total)` is
// called after each solve when set. Throws CancelledError when `cancel` is
// cancelled (checked between solves and between the solver's iterations).
AdjustmentResult AdjustTrajectory(
    const AdjustmentOptions& options, const AdjustmentInput& input,
    const std::function<void(int, int)>& progress = nullptr,
    const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_ADJUSTER_H_
