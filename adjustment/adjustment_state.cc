#include "adjustment/adjustment_state.h"

#include <algorithm>
#include <cmath>

#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {

Eigen::Matrix<double, 6, 1> ErrorModel::Sigma() const {
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << attitude_sigma_rad, position_sigma_m;
  return sigma;
}

Eigen::Matrix<double, 6, 1> ErrorModel::LevelSigma() const {
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << attitude_sigma_rad,
      position_level_sigma_m.cwiseMax(position_sigma_m);
  return sigma;
}

Eigen::Matrix<double, 6, 1> ErrorModel::Tau() const {
  Eigen::Matrix<double, 6, 1> tau;
  tau << attitude_tau_s, position_tau_s;
  return tau;
}

Eigen::Vector3d State::PriorJumpAt(double time) const {
  if (knot_prior.empty()) return Eigen::Vector3d::Zero();
  const int k =
      std::clamp(static_cast<int>(std::lround((time - correction.KnotTime(0)) /
                                              correction.knot_spacing())),
                 0, static_cast<int>(knot_prior.size()) - 1);
  return knot_prior[k].tail<3>();
}

int State::ExposureIndex(double time) const {
  const auto it = std::lower_bound(exposure_times.begin(), exposure_times.end(),
                                   time - 1e-6);
  if (it == exposure_times.end() || *it > time + 1e-6) return -1;
  return static_cast<int>(it - exposure_times.begin());
}

Eigen::Isometry3d CorrectedBodyFromCamera(
    const Eigen::Isometry3d& T_body_cam,
    const std::array<double, kRigCorrectionSize>& correction) {
  const Eigen::Vector3d dphi(correction[0], correction[1], correction[2]);
  Eigen::Isometry3d T = T_body_cam;
  const double angle = dphi.norm();
  if (angle > 0.0) {
    T.linear() = T_body_cam.linear() *
                 Eigen::AngleAxisd(angle, dphi / angle).toRotationMatrix();
  }
  T.translation() +=
      Eigen::Vector3d(correction[3], correction[4], correction[5]);
  return T;
}

bool PixelResidual(const Rig& rig, const State& state,
                   const ImageObservation& o, const Eigen::Vector3d& X_enu,
                   Eigen::Vector2d* residual) {
  int first = 0;
  double w[4];
  state.correction.Basis(o.time, &first, w);
  const RigCamera& camera = rig.cameras[o.camera];
  const PoseReprojectionError error(
      o.uv, Eigen::Matrix2d::Identity(), o.ins_pose,
      state.correction.Frame(o.ins_pose), camera.T_body_cam,
      camera.camera.intrinsics());
  const auto& knots = state.correction.knots();
  double c[kKnotSize];
  for (int i = 0; i < kKnotSize; ++i) {
    c[i] = w[0] * knots[first][i] + w[1] * knots[first + 1][i] +
           w[2] * knots[first + 2][i] + w[3] * knots[first + 3][i];
  }
  if (o.exposure >= 0 && state.model.HasJitter()) {
    for (int i = 0; i < 3; ++i)
      c[3 + i] += state.exposure_offsets[o.exposure][i];
  }
  return error(c, X_enu.data(), state.rig_corrections[o.camera].data(),
               residual->data());
}

Pose CorrectedPose(const State& state, double time, const Pose& ins_pose,
                   int exposure) {
  Pose pose = state.correction.Apply(time, ins_pose);
  if (exposure >= 0 && state.model.HasJitter()) {
    pose.p_enu +=
        state.correction.Frame(ins_pose) * state.exposure_offsets[exposure];
  }
  return pose;
}

Eigen::Matrix3d ObservationCovariance(const AdjustmentOptions& options,
                                      const StereoObservation& o) {
  Eigen::Matrix3d C =
      options.control.stereo_covariance_scale * o.covariance_body;
  C.diagonal().array() +=
      options.control.min_stereo_sigma_m * options.control.min_stereo_sigma_m;
  return C;
}

bool StereoPosition(const AdjustmentOptions& options, const State& state,
                    const std::vector<StereoObservation>& observations,
                    Eigen::Vector3d* X, Eigen::Matrix3d* covariance) {
  if (observations.empty()) return false;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (const StereoObservation& o : observations) {
    const Pose pose = CorrectedPose(state, o.time, o.ins_pose, o.exposure);
    const Eigen::Matrix3d R = pose.q_enu_body.toRotationMatrix();
    const Eigen::Matrix3d C =
        R * ObservationCovariance(options, o) * R.transpose();
    const Eigen::Matrix3d W = C.inverse();
    information += W;
    weighted += W * (R * o.p_body + pose.p_enu);
  }
  *covariance = information.inverse();
  *X = *covariance * weighted;
  return X->allFinite() && covariance->allFinite();
}

bool TriangulateWithState(const Rig& rig, const State& state,
                          const std::vector<ImageObservation>& observations,
                          const Eigen::Vector3d& initial, double sigma_px,
                          Eigen::Vector3d* X, Eigen::Matrix3d* covariance,
                          double* rms_px) {
  if (observations.size() < 2) return false;
  Eigen::Vector3d x = initial;
  Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
  for (int iteration = 0; iteration < 10; ++iteration) {
    JtJ.setZero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (const ImageObservation& o : observations) {
      Eigen::Vector2d r;
      if (!PixelResidual(rig, state, o, x, &r)) return false;
      Eigen::Matrix<double, 2, 3> J;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d plus = x, minus = x;
        plus[k] += 1e-5;
        minus[k] -= 1e-5;
        Eigen::Vector2d rp, rm;
        if (!PixelResidual(rig, state, o, plus, &rp) ||
            !PixelResidual(rig, state, o, minus, &rm)) {
          return false;
        }
        J.col(k) = (rp - rm) / 2e-5;
      }
      JtJ += J.transpose() * J;
      Jtr += J.transpose() * r;
    }
    const Eigen::Vector3d step = -JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) return false;
    x += step;
    if (step.norm() < 1e-7) break;
  }
  std::vector<double> errors;
  for (const ImageObservation& o : observations) {
    Eigen::Vector2d r;
    if (!PixelResidual(rig, state, o, x, &r)) return false;
    errors.push_back(r.norm());
  }
  const Eigen::Matrix3d inverse = JtJ.inverse();
  if (!inverse.allFinite() || !x.allFinite()) return false;
  *X = x;
  *covariance = sigma_px * sigma_px * inverse;
  *rms_px = Rms(errors);
  return true;
}

StateRms MeasureState(const Rig& rig, const State& state) {
  StateRms rms;
  std::vector<double> control_px, tie_px, control_m;
  for (const ControlPoint& p : state.points) {
    if (p.status != ControlStatus::kControl) continue;
    control_m.push_back(
        (p.estimate - p.database_enu - state.crossing_offsets[p.crossing])
            .norm());
    for (const ImageObservation& o : p.observations) {
      Eigen::Vector2d r;
      if (PixelResidual(rig, state, o, p.estimate, &r)) {
        control_px.push_back(r.norm());
      }
    }
  }
  for (const TiePoint& t : state.ties) {
    for (const ImageObservation& o : t.observations) {
      Eigen::Vector2d r;
      if (PixelResidual(rig, state, o, t.estimate, &r)) {
        tie_px.push_back(r.norm());
      }
    }
  }
  // Per-axis RMS of 2D pixel errors: norm / sqrt(2).
  rms.control_px = Rms(control_px) / std::sqrt(2.0);
  rms.tie_px = Rms(tie_px) / std::sqrt(2.0);
  rms.control_m = Rms(control_m);
  rms.control_images = static_cast<int>(control_px.size());
  rms.tie_images = static_cast<int>(tie_px.size());
  rms.control_points = static_cast<int>(control_m.size());
  return rms;
}

void EvaluateControlPoints(const AdjustmentOptions& options, const Rig& rig,
                           State* state) {
  (void)rig;
  const double floor2 = options.blunders.blunder_sigma_floor_m *
                        options.blunders.blunder_sigma_floor_m;
  for (ControlPoint& p : state->points) {
    Eigen::Matrix3d covariance;
    Eigen::Vector3d X;
    if (!StereoPosition(options, *state, p.stereo, &X, &covariance)) {
      p.normalized_residual = 0.0;
      continue;
    }
    Eigen::Vector3d reference = p.database_enu;
    Eigen::Matrix3d sigma = covariance;
    sigma.diagonal() +=
        p.sigma_m.cwiseAbs2() + Eigen::Vector3d::Constant(floor2);
    if (p.status == ControlStatus::kControl) {
      reference += state->crossing_offsets[p.crossing];
    } else {
      sigma.diagonal().array() += options.control.crossing_offset_sigma_m *
                                  options.control.crossing_offset_sigma_m;
    }
    const Eigen::Vector3d d = X - reference;
    const double w2 = d.dot(sigma.ldlt().solve(d));
    p.normalized_residual = std::sqrt(std::max(0.0, w2));
  }
}

void ResetState(State* state) {
  for (Knot& k : state->correction.knots()) k.fill(0.0);
  for (Eigen::Vector3d& o : state->crossing_offsets) o.setZero();
  for (ControlPoint& p : state->points) p.estimate = p.database_enu;
  state->vehicle.fill(0.0);
  for (Eigen::Vector3d& offset : state->exposure_offsets) offset.setZero();
}

}  // namespace adjustment_internal
}  // namespace zebrageo
