// Internal to the trajectory adjustment (trajectory_adjuster.h): what the
// solver changes and what its residuals read, shared by the steps of the
// adjustment (control selection, problem building, blunder loop, variance
// components, outputs), in the manner of COLMAP's bundle adjustment.
//
// Frames: ENU (the survey's working frame), body FRD, camera OpenCV; the
// correction's knots are [dtheta, dp] in the track frame of the INS pose
// (trajectory_correction.h). Metres, radians, seconds.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_STATE_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_STATE_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "adjustment/cost_functions.h"
#include "adjustment/line_costs.h"
#include "adjustment/trajectory_adjuster.h"
#include "adjustment/trajectory_correction.h"
#include "adjustment/vehicle_motion.h"
#include "survey/rig.h"
#include "survey/trajectory.h"

namespace zebrageo {
namespace adjustment_internal {

// One image observation of a 3D point, with what the residual needs.
struct ImageObservation {
  double time = 0.0;
  int camera = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Pose ins_pose;             // INS pose interpolated at `time`
  double sigma_scale = 1.0;  // of the observation's sigma (tie pyramid level)
  int exposure = -1;         // index into State::exposure_times, or -1
};

// A control vertex as one exposure's stereo pair reconstructed it
// (cost_functions.h, StereoVertexError).
struct StereoObservation {
  double time = 0.0;
  int exposure = -1;  // index into State::exposure_times, or -1
  Pose ins_pose;
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance_body = Eigen::Matrix3d::Identity();  // m^2
};

struct ControlPoint {
  std::string crossing_id;
  int band = 0;
  int db_vertex = 0;
  int crossing = 0;  // index into the crossing list
  Eigen::Vector3d database_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Zero();  // e, n, u
  std::vector<ImageObservation> observations;  // 2 per stereo observation
  std::vector<StereoObservation> stereo;
  ControlStatus status = ControlStatus::kControl;
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();  // parameter block
  double normalized_residual = 0.0;
  // A check point held out of a first adjustment, then used as control in
  // the final one: its image-only position in the first.
  bool held_out = false;
  bool held_out_triangulated = false;
  Eigen::Vector3d held_out_enu = Eigen::Vector3d::Zero();
  double held_out_rms_px = 0.0;
  double held_out_normalized_residual = 0.0;
};

struct TiePoint {
  std::vector<ImageObservation> observations;
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
  int source = 0;  // index into the input tracks
};

// The GNSS/INS error model: each component of the correction (in the track
// frame: attitude about along, across, up; position along, across, up) is
// a first-order Gauss-Markov process of standard deviation sigma and
// correlation time tau, sampled at the knots:
//   c_0 ~ N(b_0, sigma^2),
//   (c_k - b_k) - phi (c_{k-1} - b_{k-1}) ~ N(0, sigma^2 (1 - phi^2) + x_k),
//   phi = exp(-knot_spacing / tau),
// b_k the jumps taken out of the trajectory before knot k (an outage's
// closure spread over it), x_k what the error gains at a jump or through an
// outage beyond the process (position only; State). A correlated
// error is then counted as what it is: a few independent values per
// correlation time, not one per knot.
struct ErrorModel {
  Eigen::Vector3d attitude_sigma_rad = Eigen::Vector3d::Constant(1e-3);
  Eigen::Vector3d attitude_tau_s = Eigen::Vector3d::Constant(30.0);
  Eigen::Vector3d position_sigma_m = Eigen::Vector3d::Constant(1.0);
  Eigen::Vector3d position_tau_s = Eigen::Vector3d::Constant(30.0);
  // The first knot's position sigma (the error's level at the start): at
  // least position_sigma_m, wider where the control must not be shrunk
  // towards the INS (trajectory_adjuster.cc, PositionSigma).
  Eigen::Vector3d position_level_sigma_m = Eigen::Vector3d::Constant(1.0);
  // The vehicle-motion constraint's spread (lateral, vertical), radians.
  Eigen::Vector2d motion_sigma_rad = Eigen::Vector2d::Constant(1e-3);
  // Tie-point image sigma, pixels (times each observation's scale).
  double tie_sigma_px = 1.0;
  // The fast part of the position error (trajectory_jitter.h), per axis:
  // each exposure's own offset, a Gauss-Markov process over the exposures.
  // Zero sigma: none (a smooth trajectory).
  Eigen::Vector3d jitter_sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d jitter_tau_s = Eigen::Vector3d::Constant(0.5);

  bool HasJitter() const { return jitter_sigma_m.maxCoeff() > 0.0; }

  // sigma and tau of the 6 knot components, attitude first; the first
  // knot's sigma.
  Eigen::Matrix<double, 6, 1> Sigma() const;
  Eigen::Matrix<double, 6, 1> LevelSigma() const;
  Eigen::Matrix<double, 6, 1> Tau() const;
};

// Everything the solver changes.
struct State {
  TrajectoryCorrection correction;
  std::vector<Eigen::Vector3d> crossing_offsets;
  std::vector<std::array<double, kRigCorrectionSize>> rig_corrections;
  std::vector<ControlPoint> points;
  std::vector<TiePoint> ties;
  // Matched road-line points with the INS pose at their time and their
  // exposure (index into exposure_times, or -1).
  struct Line {
    LineControlPoint point;
    Pose ins_pose;
    int exposure = -1;
  };
  std::vector<Line> lines;
  // The exposures' times (increasing) and their fast position offsets
  // (track frame; zero without jitter).
  std::vector<double> exposure_times;
  std::vector<Eigen::Vector3d> exposure_offsets;
  std::vector<Eigen::Matrix3d> exposure_frames;  // R_enu_track there
  // Vehicle-motion constraints and the vehicle block (yaw misalignment,
  // axle offset, pitch misalignment).
  std::vector<VehicleMotionSample> motion;
  std::array<double, kVehicleSize> vehicle{};
  // Centre of the GNSS/INS prior of each knot: 0, or the jumps removed
  // from the trajectory before the knot, an outage's closure spread over
  // it (track frame).
  std::vector<Eigen::Matrix<double, 6, 1>> knot_prior;
  // Variance added to the position innovation into each knot (m^2, per
  // axis): what the error gains there beyond its process, a jump that
  // stays a step or an outage's closure
  // (DejumpedTrajectory::innovation_variance_m2), per axis of the track
  // frame (a sideways switch's on the cross-track axis alone); empty: none.
  std::vector<Eigen::Vector3d> knot_extra_variance_m2;
  ErrorModel model;
  // Attitude components of the correction (0..2 of a knot) held at their
  // prior centre, the input's attitude (attitude_significance.h).
  std::array<bool, 3> attitude_held{};
  // The along-track position correction held at its prior centre (road
  // lines alone: nothing measures it, and a weak prior would let a
  // millimetre of height misfit on a grade move it by decimetres).
  bool along_track_held = false;

  // Index of the exposure at `time` (to a microsecond), or -1.
  int ExposureIndex(double time) const;
  // The position part of knot_prior at the knot nearest `time` (the jumps
  // taken out of the trajectory before it; track frame), zero without.
  Eigen::Vector3d PriorJumpAt(double time) const;
};

// The camera's mounting after its correction.
Eigen::Isometry3d CorrectedBodyFromCamera(
    const Eigen::Isometry3d& T_body_cam,
    const std::array<double, kRigCorrectionSize>& correction);

// Pixel residual (predicted - observed) of `X_enu` in one observation with
// the current state; false when behind the camera.
bool PixelResidual(const Rig& rig, const State& state,
                   const ImageObservation& o, const Eigen::Vector3d& X_enu,
                   Eigen::Vector2d* residual);

// Image-only position of a point seen in `observations`, with the current
// trajectory and rig: Gauss-Newton on the reprojection error from
// `initial`, numeric Jacobian. Returns false when it does not converge;
// `covariance` is sigma_px^2 (J^T J)^-1.
bool TriangulateWithState(const Rig& rig, const State& state,
                          const std::vector<ImageObservation>& observations,
                          const Eigen::Vector3d& initial, double sigma_px,
                          Eigen::Vector3d* X, Eigen::Matrix3d* covariance,
                          double* rms_px);

// The corrected body pose at `time` from the INS pose there: the
// correction, plus the exposure's fast offset.
Pose CorrectedPose(const State& state, double time, const Pose& ins_pose,
                   int exposure);

// The position of a control vertex from its stereo observations alone,
// with the current trajectory: the covariance-weighted mean of each
// exposure's reconstruction placed in ENU, and its covariance. False
// without observations.
bool StereoPosition(const AdjustmentOptions& options, const State& state,
                    const std::vector<StereoObservation>& observations,
                    Eigen::Vector3d* X, Eigen::Matrix3d* covariance);

// The body covariance an observation is weighted with: the
// reconstruction's, scaled and floored (AdjustmentOptions).
Eigen::Matrix3d ObservationCovariance(const AdjustmentOptions& options,
                                      const StereoObservation& o);

// RMS of the pixel residuals of the control (or tie) observations, and of
// the control points' distance to their database position (+ offset).
struct StateRms {
  double control_px = 0.0;
  double tie_px = 0.0;
  double control_m = 0.0;
  int control_images = 0;
  int tie_images = 0;
  int control_points = 0;
};
StateRms MeasureState(const Rig& rig, const State& state);

// Image-only position and normalised residual of every control and check
// vertex. Control vertices are compared with their database position plus
// the crossing's estimated offset (a vertex that disagrees with its own
// crossing is a blunder); check vertices with the database position alone,
// with the offset's prior in the covariance.
void EvaluateControlPoints(const AdjustmentOptions& options, const Rig& rig,
                           State* state);

// Back to the INS and the database, so a removed point leaves no trace.
void ResetState(State* state);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_STATE_H_
