// The correction of the GNSS/INS trajectory: a smooth function of time, a
// uniform cubic B-spline of 6-vectors
//   c(t) = [dtheta(t) (rad, rotation vector), dp(t) (m)]
// expressed in the TRACK frame of the INS pose at t (by default; or in ENU) (x
// along the horizontal direction of travel, y to its left, z up: dead-reckoning
// errors are along-track and cross-track, and they turn with the vehicle),
// applied as
//   R_enu_body(t) = Exp(R_enu_track dtheta(t)) * R_enu_body_ins(t)
//   p_enu(t)      = p_enu_ins(t) + R_enu_track dp(t)
// R_enu_track is a function of the INS pose only (a constant per time).
// so the corrected trajectory exists at every input sample, not only at the
// exposures. The INS relative motion is kept where the data do not say
// otherwise: the priors act on differences of the knots (drift rate and its
// change), see cost_functions.h.
//
// Knots: c_k, k = 0..N-1, spaced `knot_spacing_s`; on the segment
// [t0 + i dt, t0 + (i+1) dt) with u = (t - t0)/dt - i in [0, 1) the spline is
//   c(t) = B0(u) c_i + B1(u) c_{i+1} + B2(u) c_{i+2} + B3(u) c_{i+3}
// with the uniform cubic B-spline basis (de Boor), and knot c_k has its peak
// weight at t0 + (k - 1) dt.
#ifndef ZEBRAGEO_ADJUSTMENT_TRAJECTORY_CORRECTION_H_
#define ZEBRAGEO_ADJUSTMENT_TRAJECTORY_CORRECTION_H_

#include <Eigen/Core>
#include <array>
#include <vector>

#include "survey/trajectory.h"

namespace zebrageo {

constexpr int kKnotSize = 6;  // [dtheta (3), dp (3)]
using Knot = std::array<double, kKnotSize>;

class TrajectoryCorrection {
 public:
  TrajectoryCorrection() = default;
  // A zero correction covering [start_time, end_time]. CHECKs
  // end_time > start_time and knot_spacing_s > 0.
  TrajectoryCorrection(double start_time, double end_time,
                       double knot_spacing_s, bool track_frame = true);

  int num_knots() const { return static_cast<int>(knots_.size()); }
  double knot_spacing() const { return spacing_; }
  // Time at which knot k has its largest weight.
  double KnotTime(int k) const { return start_ + (k - 1) * spacing_; }
  std::vector<Knot>& knots() { return knots_; }
  const std::vector<Knot>& knots() const { return knots_; }

  // First knot of the segment holding `time` (clamped to the span) and the
  // four basis weights; the weights sum to 1.
  void Basis(double time, int* first_knot, double weights[4]) const;
  // c(time).
  Eigen::Matrix<double, 6, 1> Evaluate(double time) const;
  // The corrected pose at `time` from the INS pose at that time.
  Pose Apply(double time, const Pose& ins_pose) const;
  // R_enu_correction of the frame the correction is expressed in at an INS
  // pose: its track frame, or the identity (ENU) when built with
  // track_frame = false.
  Eigen::Matrix3d Frame(const Pose& ins_pose) const;

 private:
  double start_ = 0.0;
  double spacing_ = 1.0;
  bool track_frame_ = true;
  int num_segments_ = 0;
  std::vector<Knot> knots_;
};

// R_enu_track of an INS pose: x = the body's forward axis projected on the
// horizontal, z = up. (Body x vertical: the east axis is used instead.)
Eigen::Matrix3d TrackFrame(const Pose& ins_pose);

// Uniform cubic B-spline basis at u in [0, 1].
void CubicBSplineBasis(double u, double weights[4]);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_TRAJECTORY_CORRECTION_H_
