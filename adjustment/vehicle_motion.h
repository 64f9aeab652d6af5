// The vehicle's motion as an observation: a land vehicle moves along its
// heading (the non-holonomic constraints of land-vehicle navigation). At the
// INS, the velocity in the body frame has no vertical component beyond the
// INS's pitch misalignment to the vehicle, and no lateral one beyond
//   crab = misalignment + axle_offset * curvature
// (the yaw misalignment of the INS to the vehicle's axis, and the lateral
// velocity of a point axle_offset ahead of the axle that does not slip,
// curvature = yaw rate / speed), plus the body's roll and yaw oscillations,
// which average out over a second or two. The INS heading drifts, its
// velocity does not in the same way: once the positions are controlled
// (crossings, road lines), the direction of travel holds the heading
// between and beyond the crossings.
//
// The velocity is the chord of the corrected positions over [t - h, t + h]
// (h short: on a turn with braking, the chord's direction is that of the
// tangent at t to a * h^2 / 2 * curvature), the heading is the corrected
// attitude at t:
//   p_j   = p_ins(t_j) + F_j c(t_j)[3:6]            t_j = t - h, t, t + h
//   b     = R_ins(t)^T Exp(-F_1 c(t)[0:3]) (p_2 - p_0)   (body FRD)
//   r     = [(b_y / L - m_yaw - m_axle curvature) / sigma_lateral,
//            (b_z / L - m_pitch) / sigma_vertical]
// L: the INS chord's horizontal length, fixed (small angles; an along-track
// correction stretches the chord, it does not turn it).
// F_j: the correction's frame at t_j (TrajectoryCorrection::Frame); m: the
// vehicle block [yaw misalignment (rad), axle offset (m), pitch
// misalignment (rad)]. The vertical spread is larger (heave, pitching on
// the suspension).
#ifndef ZEBRAGEO_ADJUSTMENT_VEHICLE_MOTION_H_
#define ZEBRAGEO_ADJUSTMENT_VEHICLE_MOTION_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "adjustment/trajectory_correction.h"
#include "survey/trajectory.h"

namespace zebrageo {

// Size of the vehicle block: [yaw misalignment (rad), axle offset (m), pitch
// misalignment (rad)].
constexpr int kVehicleSize = 3;

// One constraint: the INS poses at t - h, t, t + h and what the residual
// needs of the spline there.
struct VehicleMotionSample {
  std::array<double, 3> times{};  // t - h, t, t + h
  std::array<Pose, 3> ins;
  std::array<Eigen::Matrix3d, 3> frame;  // R_enu_correction at each time
  double speed_mps = 0.0;                // INS, over the chord
  double curvature_per_m = 0.0;          // INS yaw rate / speed
  double sigma_lateral_rad = 0.0;
  double sigma_vertical_rad = 0.0;
};

// The unexplained crab angles of a sample (lateral, vertical; radians) with
// a correction and a vehicle block; with a zero correction and vehicle
// block, the INS trajectory's own.
Eigen::Vector2d CrabAngleResidual(const VehicleMotionSample& sample,
                                  const TrajectoryCorrection& correction,
                                  const double* vehicle);

// Constraints about every 1 / rate_hz over the trajectory where the INS
// speed is at least min_speed_mps. The chord joins two trajectory samples
// (interpolating positions between samples would bend it on a turn) at
// least 2 * min_half_chord_s apart, with no gap of the trajectory between
// them; t is their mid-time. `sample_times`
// are the trajectory's, increasing; `ins_pose_at` gives the (jump-free)
// INS pose, false outside the trajectory.
template <typename PoseAt>
std::vector<VehicleMotionSample> MakeVehicleMotionSamples(
    const TrajectoryCorrection& correction,
    const std::vector<double>& sample_times, double rate_hz,
    double min_half_chord_s, double min_speed_mps,
    const Eigen::Vector2d& sigma_rad, PoseAt&& ins_pose_at);

// The high-frequency spread (lateral, vertical; radians) of the crab
// angles of `samples` under `correction` (zero vehicle block): each angle
// minus the median of those within +-window_s, robust RMS of that. A
// trajectory whose positions jitter from sample to sample (an unsmoothed
// GNSS solution) has a direction of travel that departs from its heading
// by degrees over a short chord; no smooth correction removes that, so it
// is the constraint's noise, not the vehicle's sideslip.
Eigen::Vector2d HighFrequencyCrabSpread(
    const std::vector<VehicleMotionSample>& samples,
    const TrajectoryCorrection& correction, double window_s);

// The residual as a function of the corrections c at t - h, t, t + h (6
// each) and the vehicle block.
class VehicleMotionError {
 public:
  explicit VehicleMotionError(const VehicleMotionSample& sample)
      : sample_(sample) {}

  template <typename T>
  bool operator()(const T* const c0, const T* const c1, const T* const c2,
                  const T* const vehicle, T* residual) const {
    const T* c[3] = {c0, c1, c2};
    T p[2][3];
    for (int j = 0; j < 2; ++j) {
      const int k = 2 * j;  // t - h, t + h
      const Eigen::Matrix3d& F = sample_.frame[k];
      const Eigen::Vector3d& p_ins = sample_.ins[k].p_enu;
      for (int i = 0; i < 3; ++i) {
        p[j][i] = p_ins[i] + F(i, 0) * c[k][3] + F(i, 1) * c[k][4] +
                  F(i, 2) * c[k][5];
      }
    }
    const T chord[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1],
                        p[1][2] - p[0][2]};
    const Eigen::Matrix3d& F = sample_.frame[1];
    T minus_dtheta[3];
    for (int i = 0; i < 3; ++i) {
      minus_dtheta[i] = -(F(i, 0) * c1[0] + F(i, 1) * c1[1] + F(i, 2) * c1[2]);
    }
    T v[3];
    ceres::AngleAxisRotatePoint(minus_dtheta, chord, v);
    const Eigen::Matrix3d R = sample_.ins[1].q_enu_body.toRotationMatrix();
    const T b_y = R(0, 1) * v[0] + R(1, 1) * v[1] + R(2, 1) * v[2];
    const T b_z = R(0, 2) * v[0] + R(1, 2) * v[1] + R(2, 2) * v[2];
    // Over the INS chord's length, not atan2(b_y, b_x): an along-track
    // correction changes the chord's length, not its direction, and must
    // not buy a smaller crab angle by stretching the chord (through a GNSS
    // outage the fit otherwise moved the trajectory metres along-track to
    // shrink a crab the INS's lateral drift made).
    const double length =
        sample_.speed_mps * (sample_.times[2] - sample_.times[0]);
    residual[0] =
        (b_y / length - vehicle[0] - vehicle[1] * sample_.curvature_per_m) /
        sample_.sigma_lateral_rad;
    residual[1] = (b_z / length - vehicle[2]) / sample_.sigma_vertical_rad;
    return true;
  }

 private:
  VehicleMotionSample sample_;
};

// VehicleMotionError chained to the knots the three times fall on: the
// contiguous knots first_knot() .. first_knot() + num_knots() - 1, then the
// vehicle block.
class VehicleMotionCost : public ceres::CostFunction {
 public:
  // Owned by the caller (Ceres' problem takes ownership when added).
  static VehicleMotionCost* Create(const VehicleMotionSample& sample,
                                   const TrajectoryCorrection& correction);

  int first_knot() const { return first_knot_; }
  int num_knots() const { return num_knots_; }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  VehicleMotionCost(const VehicleMotionSample& sample,
                    const TrajectoryCorrection& correction);

  std::unique_ptr<ceres::CostFunction> error_;
  int first_knot_ = 0;
  int num_knots_ = 0;
  // Per time: its first knot relative to first_knot_, and its weights.
  std::array<int, 3> offset_{};
  std::array<std::array<double, 4>, 3> weights_{};
};

// ------------------------------------------------------------ template
template <typename PoseAt>
std::vector<VehicleMotionSample> MakeVehicleMotionSamples(
    const TrajectoryCorrection& correction,
    const std::vector<double>& sample_times, double rate_hz,
    double min_half_chord_s, double min_speed_mps,
    const Eigen::Vector2d& sigma_rad, PoseAt&& ins_pose_at) {
  std::vector<VehicleMotionSample> samples;
  const int n = static_cast<int>(sample_times.size());
  if (!(rate_hz > 0.0) || n < 3) return samples;
  // Times are compared to a microsecond (sample times in a file are rounded).
  constexpr double kTolerance = 1e-6;
  // gaps_up_to[k]: gaps of the trajectory (survey/trajectory.h) among the
  // intervals before sample k. A chord across a gap is not the vehicle's
  // direction of travel (on a turn it cuts the corner).
  std::vector<int> gaps_up_to(n, 0);
  for (const TrajectoryGap& gap : FindTrajectoryGaps(sample_times)) {
    ++gaps_up_to[gap.before + 1];
  }
  for (int k = 1; k < n; ++k) gaps_up_to[k] += gaps_up_to[k - 1];
  double next = sample_times.front();
  for (int i = 0; i < n; ++i) {
    if (sample_times[i] < next - kTolerance) continue;
    // The first sample at least 2 h after sample i.
    const auto j =
        std::lower_bound(sample_times.begin() + i, sample_times.end(),
                         sample_times[i] + 2.0 * min_half_chord_s - kTolerance);
    if (j == sample_times.end()) break;
    if (gaps_up_to[j - sample_times.begin()] > gaps_up_to[i]) continue;
    VehicleMotionSample s;
    s.times = {sample_times[i], 0.5 * (sample_times[i] + *j), *j};
    s.sigma_lateral_rad = sigma_rad.x();
    s.sigma_vertical_rad = sigma_rad.y();
    bool ok = true;
    for (int k = 0; k < 3 && ok; ++k) {
      ok = ins_pose_at(s.times[k], &s.ins[k]);
      if (ok) s.frame[k] = correction.Frame(s.ins[k]);
    }
    if (!ok) continue;
    next = s.times[1] + 1.0 / rate_hz - 0.5 * (s.times[2] - s.times[0]);
    const double duration = s.times[2] - s.times[0];
    const Eigen::Vector3d chord = s.ins[2].p_enu - s.ins[0].p_enu;
    s.speed_mps = chord.head<2>().norm() / duration;
    if (!(s.speed_mps >= min_speed_mps)) continue;
    // Yaw rate: the change of the body's forward axis on the horizontal.
    const Eigen::Vector3d x0 = s.ins[0].q_enu_body * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d x2 = s.ins[2].q_enu_body * Eigen::Vector3d::UnitX();
    const double yaw_change = std::atan2(x0.x() * x2.y() - x0.y() * x2.x(),
                                         x0.x() * x2.x() + x0.y() * x2.y());
    // ENU counter-clockwise; FRD y is to the right: on a left turn a point
    // ahead of the axle moves to the left (negative crab).
    s.curvature_per_m = -yaw_change / (duration * s.speed_mps);
    samples.push_back(s);
  }
  return samples;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_VEHICLE_MOTION_H_
