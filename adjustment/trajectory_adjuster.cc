#include "adjustment/trajectory_adjuster.h"

#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "adjustment/cost_functions.h"
#include "adjustment/vehicle_motion.h"

namespace zebrageo {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;

template <typename T>
std::string Violation(const char* field, T value, const char* constraint) {
  std::ostringstream message;
  message << field << " = " << value << ": " << constraint;
  return message.str();
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / values.size());
}

// One image observation of a 3D point, with what the residual needs.
struct ImageObservation {
  double time = 0.0;
  int camera = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Pose ins_pose;             // INS pose interpolated at `time`
  double sigma_scale = 1.0;  // of the observation's sigma (tie pyramid level)
};

struct ControlPoint {
  std::string crossing_id;
  int band = 0;
  int db_vertex = 0;
  int crossing = 0;  // index into the crossing list
  Eigen::Vector3d database_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_m = Eigen::Vector3d::Zero();  // e, n, u
  std::vector<ImageObservation> observations;
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

// Everything the solver changes.
struct State {
  TrajectoryCorrection correction;
  std::vector<Eigen::Vector3d> crossing_offsets;
  std::vector<std::array<double, kRigCorrectionSize>> rig_corrections;
  std::vector<ControlPoint> points;
  std::vector<TiePoint> ties;
  // Matched road-line points with the INS pose at their time.
  std::vector<std::pair<LineControlPoint, Pose>> lines;
  // Vehicle-motion constraints and the vehicle block (yaw misalignment,
  // axle offset).
  std::vector<VehicleMotionSample> motion;
  std::array<double, kVehicleSize> vehicle{};
  // Centre of the GNSS/INS prior of each knot: 0, or the jumps removed
  // from the trajectory before the knot (track frame).
  std::vector<Eigen::Matrix<double, 6, 1>> knot_prior;
  // GNSS/INS position sigma (horizontal, vertical) of the prior.
  Eigen::Vector2d gnss_sigma_m = Eigen::Vector2d::Ones();
};

// The camera's mounting after its correction.
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

// Pixel residual (predicted - observed) of `X_enu` in one observation with
// the current state; false when behind the camera.
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
  return error(c, X_enu.data(), state.rig_corrections[o.camera].data(),
               residual->data());
}

// The GNSS/INS trajectory with its jumps removed: sample-to-sample steps
// that depart from the motion of the neighbouring samples (a robust median
// of their steps) by more than the thresholds are taken out, so what
// remains is the INS relative motion, continuous. `offset_enu` and
// `rotation_offset` give, per sample, what was taken out (original =
// offset * dejumped for rotations, original = dejumped + offset for
// positions).
struct DejumpedTrajectory {
  std::vector<Pose> poses;
  std::vector<Eigen::Vector3d> position_offset;
  std::vector<Eigen::Quaterniond> rotation_offset;
  int num_jumps = 0;
};

DejumpedTrajectory RemoveJumps(const Trajectory& trajectory, double threshold_m,
                               double threshold_rad) {
  const std::vector<Pose>& poses = trajectory.poses();
  const int n = static_cast<int>(poses.size());
  DejumpedTrajectory out;
  out.poses = poses;
  out.position_offset.assign(n, Eigen::Vector3d::Zero());
  out.rotation_offset.assign(n, Eigen::Quaterniond::Identity());
  if (n < 8 || (threshold_m <= 0.0 && threshold_rad <= 0.0)) return out;
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  // Steps per second (velocity, angular rate in the body frame).
  std::vector<Eigen::Vector3d> velocity(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> rate(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    const double dt = samples[i].time - samples[i - 1].time;
    velocity[i] = (poses[i].p_enu - poses[i - 1].p_enu) / dt;
    const Eigen::AngleAxisd step(poses[i - 1].q_enu_body.inverse() *
                                 poses[i].q_enu_body);
    rate[i] = step.angle() * step.axis() / dt;
  }
  auto median_of_neighbours = [&](const std::vector<Eigen::Vector3d>& v,
                                  int i) {
    Eigen::Vector3d m;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> values;
      for (int k = std::max(1, i - 3); k <= std::min(n - 1, i + 3); ++k) {
        if (k != i) values.push_back(v[k][axis]);
      }
      std::nth_element(values.begin(), values.begin() + values.size() / 2,
                       values.end());
      m[axis] = values[values.size() / 2];
    }
    return m;
  };
  // Departure of each step from its neighbours' motion. A step across a
  // gap of the trajectory (survey/trajectory.h) is not one: the vehicle's
  // motion during the gap is unknown, so it is never taken for a jump.
  std::vector<bool> across_gap(n, false);
  for (const TrajectoryGap& gap : FindTrajectoryGaps(SampleTimes(samples))) {
    across_gap[gap.before + 1] = true;
  }
  std::vector<Eigen::Vector3d> position_step(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> rotation_step(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    if (across_gap[i]) continue;
    const double dt = samples[i].time - samples[i - 1].time;
    position_step[i] = (velocity[i] - median_of_neighbours(velocity, i)) * dt;
    rotation_step[i] = (rate[i] - median_of_neighbours(rate, i)) * dt;
  }
  // A jump stands out of the trajectory's own motion: at 10 Hz the body's
  // oscillations on its suspension (a tenth of a degree at 1-2 Hz) depart
  // from the neighbouring steps by more than a 100 Hz trajectory's do, and
  // are not jumps. The thresholds are raised to kJumpNoiseFactor times the
  // median departure when that is larger.
  constexpr double kJumpNoiseFactor = 8.0;
  auto median_norm = [&](const std::vector<Eigen::Vector3d>& steps) {
    std::vector<double> norms;
    for (int i = 1; i < n; ++i) norms.push_back(steps[i].norm());
    std::nth_element(norms.begin(), norms.begin() + norms.size() / 2,
                     norms.end());
    return norms[norms.size() / 2];
  };
  threshold_m =
      threshold_m > 0.0
          ? std::max(threshold_m, kJumpNoiseFactor * median_norm(position_step))
          : 0.0;
  threshold_rad = threshold_rad > 0.0
                      ? std::max(threshold_rad,
                                 kJumpNoiseFactor * median_norm(rotation_step))
                      : 0.0;
  Eigen::Vector3d position_jump = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation_jump = Eigen::Quaterniond::Identity();
  for (int i = 1; i < n; ++i) {
    bool jumped = false;
    if (threshold_m > 0.0) {
      const Eigen::Vector3d& step = position_step[i];
      if (step.norm() > threshold_m) {
        position_jump += step;
        jumped = true;
      }
    }
    if (threshold_rad > 0.0) {
      const Eigen::Vector3d& step = rotation_step[i];
      if (step.norm() > threshold_rad) {
        // In the ENU frame: R_i = J R_i', J = R_{i-1} Exp(step) R_{i-1}^T.
        const Eigen::Quaterniond body_step(
            Eigen::AngleAxisd(step.norm(), step.normalized()));
        const Eigen::Quaterniond J = poses[i - 1].q_enu_body * body_step *
                                     poses[i - 1].q_enu_body.inverse();
        rotation_jump = (J * rotation_jump).normalized();
        jumped = true;
      }
    }
    out.num_jumps += jumped;
    out.position_offset[i] = position_jump;
    out.rotation_offset[i] = rotation_jump;
    out.poses[i].p_enu = poses[i].p_enu - position_jump;
    out.poses[i].q_enu_body =
        (rotation_jump.inverse() * poses[i].q_enu_body).normalized();
  }
  return out;
}

// Pose of the de-jumped trajectory at `time` (interpolated as Trajectory).
bool InterpolateDejumped(const Trajectory& trajectory,
                         const DejumpedTrajectory& dejumped, double time,
                         Pose* pose) {
  const int i = trajectory.FindSegment(time);
  if (i < 0) return false;
  const double t0 = trajectory.samples()[i].time;
  const double t1 = trajectory.samples()[i + 1].time;
  *pose = InterpolatePoses(dejumped.poses[i], dejumped.poses[i + 1],
                           (time - t0) / (t1 - t0));
  return true;
}

// Image-only position of a point seen in `observations`, with the current
// trajectory and rig: Gauss-Newton on the reprojection error from
// `initial`, numeric Jacobian. Returns false when it does not converge;
// `covariance` is sigma_px^2 (J^T J)^-1.
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

// Residual block ids of one observation type, for evaluation.
struct Blocks {
  std::vector<ceres::ResidualBlockId> control_images;
  std::vector<ceres::ResidualBlockId> tie_images;
  std::vector<ceres::ResidualBlockId> control_priors;
  std::vector<ceres::ResidualBlockId> gnss;
};

class AdjustmentProblem {
 public:
  AdjustmentProblem(const AdjustmentOptions& options, const Rig& rig,
                    bool robust, State* state)
      : options_(options), rig_(rig), state_(state) {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(problem_options);
    if (robust) {
      image_loss_ =
          std::make_unique<ceres::HuberLoss>(options.image_loss_scale);
      control_loss_ =
          std::make_unique<ceres::CauchyLoss>(options.control_loss_scale);
      gnss_loss_ = std::make_unique<ceres::CauchyLoss>(options.gnss_loss_scale);
      line_loss_ = std::make_unique<ceres::CauchyLoss>(options.line_loss_scale);
      motion_loss_ = std::make_unique<ceres::CauchyLoss>(
          options.vehicle_motion_loss_scale);
    }
    Build();
  }

  ceres::Problem* problem() { return problem_.get(); }
  const Blocks& blocks() const { return blocks_; }
  int num_pose_blocks() const { return num_pose_blocks_; }

  ceres::Solver::Summary Solve() {
    ceres::Solver::Options solver_options =
        ToCeresOptions(options_.solver, num_pose_blocks_);
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (ControlPoint& p : state_->points) {
      if (p.status == ControlStatus::kControl) {
        ordering->AddElementToGroup(p.estimate.data(), 0);
      }
    }
    for (TiePoint& t : state_->ties) {
      ordering->AddElementToGroup(t.estimate.data(), 0);
    }
    for (Knot& k : state_->correction.knots()) {
      ordering->AddElementToGroup(k.data(), 1);
    }
    for (Eigen::Vector3d& o : state_->crossing_offsets) {
      if (problem_->HasParameterBlock(o.data())) {
        ordering->AddElementToGroup(o.data(), 1);
      }
    }
    for (auto& r : state_->rig_corrections) {
      if (problem_->HasParameterBlock(r.data())) {
        ordering->AddElementToGroup(r.data(), 1);
      }
    }
    if (problem_->HasParameterBlock(state_->vehicle.data())) {
      ordering->AddElementToGroup(state_->vehicle.data(), 1);
    }
    solver_options.linear_solver_ordering = ordering;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, problem_.get(), &summary);
    VLOG(1) << summary.BriefReport();
    VLOG(2) << summary.FullReport();
    return summary;
  }

  // sqrt(sum r^2 / (residuals - free parameters)), without loss functions.
  double Sigma0() {
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.apply_loss_function = false;
    double cost = 0.0;
    problem_->Evaluate(evaluate, &cost, nullptr, nullptr, nullptr);
    int free_parameters = 0;
    std::vector<double*> parameter_blocks;
    problem_->GetParameterBlocks(&parameter_blocks);
    for (double* block : parameter_blocks) {
      if (!problem_->IsParameterBlockConstant(block)) {
        free_parameters += problem_->ParameterBlockSize(block);
      }
    }
    const int dof = problem_->NumResiduals() - free_parameters;
    return dof > 0 ? std::sqrt(2.0 * cost / dof) : 0.0;
  }

 private:
  void AddImageResidual(const ImageObservation& o, double* point,
                        double sigma_px,
                        std::vector<ceres::ResidualBlockId>* ids) {
    int first = 0;
    double w[4];
    state_->correction.Basis(o.time, &first, w);
    auto& knots = state_->correction.knots();
    const RigCamera& camera = rig_.cameras[o.camera];
    std::vector<double*> blocks = {knots[first].data(), knots[first + 1].data(),
                                   knots[first + 2].data(),
                                   knots[first + 3].data(), point};
    if (options_.self_calibrate_rig) {
      blocks.push_back(state_->rig_corrections[o.camera].data());
    }
    ids->push_back(problem_->AddResidualBlock(
        SplineReprojectionCost::Create(
            o.uv, Eigen::Matrix2d::Identity() / sigma_px, w, o.ins_pose,
            state_->correction.Frame(o.ins_pose), camera.T_body_cam,
            camera.camera.intrinsics(), options_.self_calibrate_rig),
        image_loss_.get(), blocks));
  }

  void Build() {
    auto& knots = state_->correction.knots();
    const int n = static_cast<int>(knots.size());
    const double dt = state_->correction.knot_spacing();
    for (Knot& k : knots) problem_->AddParameterBlock(k.data(), kKnotSize);
    num_pose_blocks_ = n;

    // GNSS/INS absolute: attitude and position as separate blocks so the
    // Cauchy loss of a GNSS jump does not switch off the attitude.
    // The GNSS/INS error is one smooth drift, correlated over
    // prior_correlation_time_s: the prior's sigma holds once per correlation
    // time, not once per knot (which would pin the mean correction to
    // sigma / sqrt(knots)).
    const double widen =
        std::sqrt(std::max(1.0, options_.prior_correlation_time_s / dt));
    Eigen::Matrix<double, 6, 6> S_att = Eigen::Matrix<double, 6, 6>::Zero();
    S_att.diagonal().head<2>().setConstant(
        1.0 / (options_.ins_tilt_sigma_deg * kDegToRad));
    S_att(2, 2) = 1.0 / (options_.ins_heading_sigma_deg * kDegToRad) / widen;
    Eigen::Matrix<double, 6, 6> S_pos = Eigen::Matrix<double, 6, 6>::Zero();
    S_pos.diagonal().tail<3>() =
        Eigen::Vector3d(1.0 / state_->gnss_sigma_m.x(),
                        1.0 / state_->gnss_sigma_m.x(),
                        1.0 / state_->gnss_sigma_m.y()) /
        widen;
    const Eigen::Matrix<double, 6, 1> zero =
        Eigen::Matrix<double, 6, 1>::Zero();
    // Drift rate and its change.
    Eigen::Matrix<double, 6, 6> S_rate = Eigen::Matrix<double, 6, 6>::Zero();
    S_rate.diagonal().head<3>().setConstant(
        1.0 / (options_.drift_rate_sigma_deg_per_s * kDegToRad * dt));
    // A drift of sigma correlated over tau (first-order Gauss-Markov) changes
    // by sigma sqrt(2 dt / tau) per dt: a small drift is a slow one too, so
    // the correction cannot make a local bump at each crossing either.
    const double tau = options_.prior_correlation_time_s;
    const Eigen::Vector2d rate_sigma =
        (state_->gnss_sigma_m * std::sqrt(2.0 / (tau * dt)))
            .cwiseMin(options_.drift_rate_sigma_mps);
    S_rate.diagonal().tail<3>() =
        Eigen::Vector3d(1.0 / rate_sigma.x(), 1.0 / rate_sigma.x(),
                        1.0 / rate_sigma.y()) /
        dt;
    Eigen::Matrix<double, 6, 6> S_acc = Eigen::Matrix<double, 6, 6>::Zero();
    S_acc.diagonal().head<3>().setConstant(
        1.0 / (options_.drift_angular_acceleration_sigma_deg_per_s2 *
               kDegToRad * dt * dt));
    S_acc.diagonal().tail<3>().setConstant(
        1.0 / (options_.drift_acceleration_sigma_mps2 * dt * dt));
    for (int k = 0; k < n; ++k) {
      const Eigen::Matrix<double, 6, 1>& b =
          state_->knot_prior.empty() ? zero : state_->knot_prior[k];
      problem_->AddResidualBlock(LinearPrior<1, 6>::Create(S_att, {1.0}, b),
                                 nullptr, knots[k].data());
      blocks_.gnss.push_back(
          problem_->AddResidualBlock(LinearPrior<1, 6>::Create(S_pos, {1.0}, b),
                                     gnss_loss_.get(), knots[k].data()));
      if (k + 1 < n) {
        problem_->AddResidualBlock(
            LinearPrior<2, 6>::Create(S_rate, {-1.0, 1.0}), nullptr,
            knots[k].data(), knots[k + 1].data());
      }
      if (k + 2 < n) {
        problem_->AddResidualBlock(
            LinearPrior<3, 6>::Create(S_acc, {1.0, -2.0, 1.0}), nullptr,
            knots[k].data(), knots[k + 1].data(), knots[k + 2].data());
      }
    }

    // Rig mounting: parameters only when self-calibrating.
    for (auto& r : state_->rig_corrections) {
      if (options_.self_calibrate_rig) {
        problem_->AddParameterBlock(r.data(), kRigCorrectionSize);
        Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
        S.diagonal().head<3>().setConstant(
            1.0 / (options_.boresight_sigma_deg * kDegToRad));
        S.diagonal().tail<3>().setConstant(1.0 / options_.lever_arm_sigma_m);
        problem_->AddResidualBlock(LinearPrior<1, 6>::Create(S, {1.0}), nullptr,
                                   r.data());
        ++num_pose_blocks_;
      }
    }

    // Control points and their crossings' offsets.
    std::vector<char> offset_used(state_->crossing_offsets.size(), 0);
    for (ControlPoint& p : state_->points) {
      if (p.status != ControlStatus::kControl) continue;
      double* offset = state_->crossing_offsets[p.crossing].data();
      if (!offset_used[p.crossing]) {
        offset_used[p.crossing] = 1;
        problem_->AddParameterBlock(offset, 3);
        if (options_.crossing_offset_sigma_m > 0.0) {
          // Robust: a crossing far from where the database has it (a wrong
          // match, a repainted crossing) moves its own offset, not the
          // trajectory; the blunder test then rejects it.
          problem_->AddResidualBlock(
              LinearPrior<1, 3>::Create(Eigen::Matrix3d::Identity() /
                                            options_.crossing_offset_sigma_m,
                                        {1.0}),
              control_loss_.get(), offset);
          ++num_pose_blocks_;
        } else {
          problem_->SetParameterBlockConstant(offset);
        }
      }
      const Eigen::Matrix3d S = p.sigma_m.cwiseInverse().asDiagonal();
      blocks_.control_priors.push_back(problem_->AddResidualBlock(
          PointPriorError::Create(p.database_enu, S), control_loss_.get(),
          p.estimate.data(), offset));
      for (const ImageObservation& o : p.observations) {
        AddImageResidual(o, p.estimate.data(), options_.vertex_sigma_px,
                         &blocks_.control_images);
      }
    }
    for (TiePoint& t : state_->ties) {
      for (const ImageObservation& o : t.observations) {
        AddImageResidual(o, t.estimate.data(),
                         options_.tie_sigma_px * o.sigma_scale,
                         &blocks_.tie_images);
      }
    }
    for (const auto& [line, ins_pose] : state_->lines) {
      int first = 0;
      double w[4];
      state_->correction.Basis(line.time, &first, w);
      problem_->AddResidualBlock(
          LinePointCost::Create(line, ins_pose,
                                state_->correction.Frame(ins_pose), w),
          line_loss_.get(), knots[first].data(), knots[first + 1].data(),
          knots[first + 2].data(), knots[first + 3].data());
    }
    AddVehicleMotion();
  }

  void AddVehicleMotion() {
    if (state_->motion.empty()) return;
    double* vehicle = state_->vehicle.data();
    problem_->AddParameterBlock(vehicle, kVehicleSize);
    ++num_pose_blocks_;
    const double misalignment =
        1.0 / (options_.vehicle_misalignment_sigma_deg * kDegToRad);
    const Eigen::Matrix3d S =
        Eigen::Vector3d(misalignment, 1.0 / options_.axle_offset_sigma_m,
                        misalignment)
            .asDiagonal();
    problem_->AddResidualBlock(LinearPrior<1, kVehicleSize>::Create(S, {1.0}),
                               nullptr, vehicle);
    auto& knots = state_->correction.knots();
    for (const VehicleMotionSample& sample : state_->motion) {
      VehicleMotionCost* cost =
          VehicleMotionCost::Create(sample, state_->correction);
      std::vector<double*> blocks;
      for (int k = 0; k < cost->num_knots(); ++k) {
        blocks.push_back(knots[cost->first_knot() + k].data());
      }
      blocks.push_back(vehicle);
      problem_->AddResidualBlock(cost, motion_loss_.get(), blocks);
    }
  }

  const AdjustmentOptions& options_;
  const Rig& rig_;
  State* state_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::LossFunction> image_loss_;
  std::unique_ptr<ceres::LossFunction> control_loss_;
  std::unique_ptr<ceres::LossFunction> gnss_loss_;
  std::unique_ptr<ceres::LossFunction> line_loss_;
  std::unique_ptr<ceres::LossFunction> motion_loss_;
  Blocks blocks_;
  int num_pose_blocks_ = 0;
};

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

// Image-only position and normalised residual of every control and check
// vertex. Control vertices are compared with their database position plus
// the crossing's estimated offset (a vertex that disagrees with its own
// crossing is a blunder); check vertices with the database position alone,
// with the offset's prior in the covariance.
void EvaluateControlPoints(const AdjustmentOptions& options, const Rig& rig,
                           State* state) {
  const double floor2 =
      options.blunder_sigma_floor_m * options.blunder_sigma_floor_m;
  for (ControlPoint& p : state->points) {
    const Eigen::Vector3d initial =
        p.status == ControlStatus::kControl ? p.estimate : p.database_enu;
    Eigen::Matrix3d covariance;
    double rms_px = 0.0;
    Eigen::Vector3d X;
    if (!TriangulateWithState(rig, *state, p.observations, initial,
                              options.vertex_sigma_px, &X, &covariance,
                              &rms_px)) {
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
      sigma.diagonal().array() +=
          options.crossing_offset_sigma_m * options.crossing_offset_sigma_m;
    }
    const Eigen::Vector3d d = X - reference;
    const double w2 = d.dot(sigma.ldlt().solve(d));
    p.normalized_residual = std::sqrt(std::max(0.0, w2));
  }
}

// 95% quantile of the chi-square distribution with k degrees of freedom
// (Wilson-Hilferty; within 1% for k >= 1).
double ChiSquare95(int k) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + 1.6448536 * std::sqrt(a);
  return k * c * c * c;
}

// Variance component of the GNSS/INS position prior, from the data: each
// control crossing's discrepancy (database minus image-only position with
// the INS trajectory, median over its vertices) holds the drift there plus
// the database's own error (crossing offset, vertex noise). The mean square
// discrepancy minus the database's share estimates the drift's variance,
// clamped to [min_gnss_sigma_m, gnss_sigma_*]. Returns (horizontal per
// axis, vertical).
Eigen::Vector2d EstimateGnssSigma(const AdjustmentOptions& options,
                                  const Rig& rig, const State& state,
                                  int num_crossings) {
  const Eigen::Vector2d upper(options.gnss_sigma_horizontal_m,
                              options.gnss_sigma_vertical_m);
  if (!options.estimate_gnss_sigma) return upper;
  std::vector<std::vector<Eigen::Vector3d>> d(num_crossings);
  std::vector<Eigen::Vector3d> sigma2(num_crossings, Eigen::Vector3d::Zero());
  for (const ControlPoint& p : state.points) {
    if (p.status != ControlStatus::kControl) continue;
    Eigen::Vector3d X;
    Eigen::Matrix3d covariance;
    double rms_px = 0.0;
    if (!TriangulateWithState(rig, state, p.observations, p.database_enu,
                              options.vertex_sigma_px, &X, &covariance,
                              &rms_px)) {
      continue;
    }
    d[p.crossing].push_back(p.database_enu - X);
    sigma2[p.crossing] += p.sigma_m.cwiseAbs2() + covariance.diagonal();
  }
  double sum_h = 0.0, sum_v = 0.0, database_h = 0.0, database_v = 0.0;
  double test_h = 0.0, test_v = 0.0;  // sum of squared normalised residuals
  int n = 0;
  const double offset2 =
      options.crossing_offset_sigma_m * options.crossing_offset_sigma_m;
  for (int c = 0; c < num_crossings; ++c) {
    const int m = static_cast<int>(d[c].size());
    if (m == 0) continue;
    Eigen::Vector3d median;
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> values;
      for (const Eigen::Vector3d& v : d[c]) values.push_back(v[axis]);
      std::nth_element(values.begin(), values.begin() + m / 2, values.end());
      median[axis] = values[m / 2];
    }
    sum_h += 0.5 * median.head<2>().squaredNorm();
    sum_v += median.z() * median.z();
    const Eigen::Vector3d mean_sigma2 = sigma2[c] / (m * m);
    const double variance_h =
        offset2 + 0.5 * (mean_sigma2.x() + mean_sigma2.y());
    const double variance_v = offset2 + mean_sigma2.z();
    database_h += variance_h;
    database_v += variance_v;
    test_h += median.head<2>().squaredNorm() / variance_h;
    test_v += median.z() * median.z() / variance_v;
    ++n;
  }
  if (n == 0) return upper;
  const double floor2 = options.min_gnss_sigma_m * options.min_gnss_sigma_m;
  // A drift is estimated only where the discrepancies exceed what the
  // database's error explains (chi-square test at 95%): with one or two
  // crossings the mean square is too noisy to trust on its own.
  const bool drift_h = test_h > ChiSquare95(2 * n);
  const bool drift_v = test_v > ChiSquare95(n);
  const Eigen::Vector2d estimate(
      std::sqrt(drift_h ? std::max(floor2, (sum_h - database_h) / n) : floor2),
      std::sqrt(drift_v ? std::max(floor2, (sum_v - database_v) / n) : floor2));
  return estimate.cwiseMin(upper);
}
}  // namespace

const char* ControlStatusName(ControlStatus status) {
  switch (status) {
    case ControlStatus::kControl:
      return "control";
    case ControlStatus::kCheck:
      return "check";
    case ControlStatus::kRejected:
      return "rejected";
  }
  return "?";
}

std::string AdjustmentOptions::Check() const {
  struct Positive {
    const char* name;
    double value;
  };
  const Positive positives[] = {
      {"knot_spacing_s", knot_spacing_s},
      {"gnss_sigma_horizontal_m", gnss_sigma_horizontal_m},
      {"gnss_sigma_vertical_m", gnss_sigma_vertical_m},
      {"gnss_loss_scale", gnss_loss_scale},
      {"ins_tilt_sigma_deg", ins_tilt_sigma_deg},
      {"ins_heading_sigma_deg", ins_heading_sigma_deg},
      {"prior_correlation_time_s", prior_correlation_time_s},
      {"min_gnss_sigma_m", min_gnss_sigma_m},
      {"drift_rate_sigma_mps", drift_rate_sigma_mps},
      {"drift_rate_sigma_deg_per_s", drift_rate_sigma_deg_per_s},
      {"drift_acceleration_sigma_mps2", drift_acceleration_sigma_mps2},
      {"drift_angular_acceleration_sigma_deg_per_s2",
       drift_angular_acceleration_sigma_deg_per_s2},
      {"vertex_sigma_px", vertex_sigma_px},
      {"image_loss_scale", image_loss_scale},
      {"min_database_sigma_m", min_database_sigma_m},
      {"control_loss_scale", control_loss_scale},
      {"blunder_threshold", blunder_threshold},
      {"blunder_sigma_floor_m", blunder_sigma_floor_m},
      {"tie_sigma_px", tie_sigma_px},
      {"line_loss_scale", line_loss_scale},
      {"boresight_sigma_deg", boresight_sigma_deg},
      {"lever_arm_sigma_m", lever_arm_sigma_m},
      {"vertical_slip_sigma_deg", vertical_slip_sigma_deg},
      {"vehicle_motion_rate_hz", vehicle_motion_rate_hz},
      {"vehicle_motion_half_chord_s", vehicle_motion_half_chord_s},
      {"vehicle_misalignment_sigma_deg", vehicle_misalignment_sigma_deg},
      {"axle_offset_sigma_m", axle_offset_sigma_m},
      {"vehicle_motion_loss_scale", vehicle_motion_loss_scale},
  };
  for (const Positive& p : positives) {
    if (!(p.value > 0.0) || !std::isfinite(p.value)) {
      return Violation(p.name, p.value, "must be finite and > 0");
    }
  }
  if (!(sideslip_sigma_deg >= 0.0) || !std::isfinite(sideslip_sigma_deg)) {
    return Violation("sideslip_sigma_deg", sideslip_sigma_deg,
                     "must be finite and >= 0 (0 disables)");
  }
  if (!(vehicle_motion_min_speed_mps >= 0.0)) {
    return Violation("vehicle_motion_min_speed_mps",
                     vehicle_motion_min_speed_mps, "must be >= 0");
  }
  if (!(crossing_offset_sigma_m >= 0.0)) {
    return Violation("crossing_offset_sigma_m", crossing_offset_sigma_m,
                     "must be >= 0");
  }
  if (!(check_crossing_share >= 0.0 && check_crossing_share < 1.0)) {
    return Violation("check_crossing_share", check_crossing_share,
                     "must be in [0, 1)");
  }
  if (min_control_crossings < 1) {
    return Violation("min_control_crossings", min_control_crossings,
                     "must be >= 1");
  }
  if (max_blunder_iterations < 0) {
    return Violation("max_blunder_iterations", max_blunder_iterations,
                     "must be >= 0");
  }
  if (!(reject_crossing_share > 0.0 && reject_crossing_share <= 1.0)) {
    return Violation("reject_crossing_share", reject_crossing_share,
                     "must be in (0, 1]");
  }
  if (max_knots_for_covariance < 0) {
    return Violation("max_knots_for_covariance", max_knots_for_covariance,
                     "must be >= 0");
  }
  const std::string solver_error = solver.Check();
  if (!solver_error.empty()) return "solver." + solver_error;
  return "";
}

std::string AdjustmentSummary::BriefReport() const {
  std::ostringstream out;
  out.precision(3);
  out << (usable ? "usable" : "NOT usable");
  if (!message.empty()) out << " (" << message << ")";
  out << ": " << num_control_points << " control vertices in "
      << num_control_crossings << " crossings, " << num_check_points
      << " check vertices in " << num_check_crossings << " crossings, "
      << num_rejected_points << " rejected, " << num_tie_tracks
      << " tie tracks; sigma0 " << sigma0 << ", " << iterations
      << " iterations in " << solves << " solves, " << time_in_seconds << " s";
  if (num_check_points_evaluated > 0) {
    out << "; check RMSE H " << 100.0 * check_rmse_horizontal_m << " cm, V "
        << 100.0 * check_rmse_vertical_m << " cm";
  }
  return out.str();
}

AdjustmentResult AdjustTrajectory(
    const AdjustmentOptions& options, const AdjustmentInput& input,
    const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  AdjustmentResult result;
  AdjustmentSummary& summary = result.summary;
  const std::string error = options.Check();
  if (!error.empty()) {
    summary.message = "invalid AdjustmentOptions: " + error;
    return result;
  }
  CHECK(input.rig != nullptr && input.frame != nullptr &&
        input.trajectory != nullptr && input.exposures != nullptr &&
        input.roadmarks != nullptr && input.vertices != nullptr &&
        input.matches != nullptr);
  const Rig& rig = *input.rig;
  const LocalFrame& frame = *input.frame;
  const Trajectory& trajectory = *input.trajectory;
  const ExposureTable& exposures = *input.exposures;
  summary.num_exposures = static_cast<int>(exposures.exposures.size());
  auto warn = [&summary](const std::string& warning) {
    LOG(WARNING) << warning;
    summary.warnings.push_back(warning);
  };
  // The INS trajectory the correction applies to: without its jumps.
  const DejumpedTrajectory dejumped =
      RemoveJumps(trajectory, options.jump_threshold_m,
                  options.jump_threshold_deg * kDegToRad);
  summary.num_jumps = dejumped.num_jumps;
  if (dejumped.num_jumps > 0) {
    warn(std::to_string(dejumped.num_jumps) +
         " jumps in the GNSS/INS trajectory (GNSS returning after an "
         "outage?): corrected as continuous INS motion");
  }
  auto ins_pose_at = [&](double time, Pose* pose) {
    return InterpolateDejumped(trajectory, dejumped, time, pose);
  };

  // ------------------------------------------------------------ indices
  std::unordered_map<int64_t, double> exposure_time;
  for (const Exposure& e : exposures.exposures) {
    exposure_time[e.exposure_id] = e.time;
  }
  std::map<std::tuple<int64_t, int64_t, int>, const ReconstructedVertex*>
      vertex_of;
  for (const ReconstructedVertex& v : *input.vertices) {
    vertex_of[{v.exposure_id, v.band_id, v.vertex}] = &v;
  }
  std::map<std::pair<std::string, int>, const RoadmarkBand*> band_of;
  for (const RoadmarkBand& b : input.roadmarks->bands) {
    band_of[{b.crossing_id, b.band}] = &b;
  }

  // ------------------------------------------------------------ control
  State state;
  std::map<std::tuple<std::string, int, int>, int> point_of;
  std::map<std::string, int> crossing_of;
  std::vector<std::string> crossing_names;
  std::vector<double> crossing_first_time;
  int unknown_vertices = 0, unknown_bands = 0, bad_pairs = 0,
      outside_trajectory = 0;
  for (const VertexMatch& m : *input.matches) {
    const auto v = vertex_of.find({m.exposure_id, m.band_id, m.vertex});
    if (v == vertex_of.end()) {
      ++unknown_vertices;
      continue;
    }
    const auto b = band_of.find({m.crossing_id, m.band});
    if (b == band_of.end() || m.db_vertex < 0 || m.db_vertex > 3) {
      ++unknown_bands;
      continue;
    }
    const ReconstructedVertex& vertex = *v->second;
    if (vertex.pair < 0 ||
        vertex.pair >= static_cast<int>(rig.stereo_pairs.size())) {
      ++bad_pairs;
      continue;
    }
    const auto t = exposure_time.find(m.exposure_id);
    Pose ins_pose;
    if (t == exposure_time.end() || !ins_pose_at(t->second, &ins_pose)) {
      ++outside_trajectory;
      continue;
    }
    auto [it, inserted] = point_of.try_emplace(
        std::make_tuple(m.crossing_id, m.band, m.db_vertex),
        static_cast<int>(state.points.size()));
    if (inserted) {
      const RoadmarkBand& band = *b->second;
      ControlPoint p;
      p.crossing_id = m.crossing_id;
      p.band = m.band;
      p.db_vertex = m.db_vertex;
      auto [c, new_crossing] = crossing_of.try_emplace(
          m.crossing_id, static_cast<int>(crossing_names.size()));
      if (new_crossing) {
        crossing_names.push_back(m.crossing_id);
        crossing_first_time.push_back(t->second);
      }
      p.crossing = c->second;
      crossing_first_time[p.crossing] =
          std::min(crossing_first_time[p.crossing], t->second);
      p.database_enu = frame.EnuFromGeodetic(band.corners[m.db_vertex]);
      const double sxy =
          std::max(band.sigma_xy_m, options.min_database_sigma_m);
      const double sz = std::max(band.sigma_z_m, options.min_database_sigma_m);
      p.sigma_m = Eigen::Vector3d(sxy, sxy, sz);
      p.estimate = p.database_enu;
      state.points.push_back(p);
    }
    ControlPoint& p = state.points[it->second];
    const auto& pair = rig.stereo_pairs[vertex.pair];
    p.observations.push_back({t->second, pair[0], vertex.uv_left, ins_pose});
    p.observations.push_back({t->second, pair[1], vertex.uv_right, ins_pose});
  }
  if (unknown_vertices > 0) {
    warn(std::to_string(unknown_vertices) +
         " rows of matches.csv name a vertex that is not in "
         "reconstructed_bands.csv: ignored");
  }
  if (unknown_bands > 0) {
    warn(std::to_string(unknown_bands) +
         " rows of matches.csv name a database band or vertex that is not in "
         "the road-mark database: ignored");
  }
  if (bad_pairs > 0) {
    warn(std::to_string(bad_pairs) +
         " matched vertices name a stereo pair that is not in rig.yaml: "
         "ignored");
  }
  if (outside_trajectory > 0) {
    warn(std::to_string(outside_trajectory) +
         " matched vertices belong to exposures outside the trajectory: "
         "ignored");
  }

  // Check crossings: every k-th crossing in time order.
  const int num_crossings = static_cast<int>(crossing_names.size());
  std::vector<char> is_check(num_crossings, 0);
  if (options.check_crossing_share > 0.0 && num_crossings > 0) {
    std::vector<int> order(num_crossings);
    for (int i = 0; i < num_crossings; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return crossing_first_time[a] < crossing_first_time[b];
    });
    const int k = std::max(
        2, static_cast<int>(std::lround(1.0 / options.check_crossing_share)));
    std::vector<int> checks;
    for (int i = k / 2; i < num_crossings; i += k) checks.push_back(order[i]);
    if (num_crossings - static_cast<int>(checks.size()) >=
        options.min_control_crossings) {
      for (int c : checks) is_check[c] = 1;
    } else if (!checks.empty()) {
      warn("only " + std::to_string(num_crossings) +
           " crossings matched: none held out as check points, the accuracy "
           "reported is not independently checked");
    }
  }
  for (ControlPoint& p : state.points) {
    if (is_check[p.crossing]) p.status = ControlStatus::kCheck;
  }
  state.crossing_offsets.assign(num_crossings, Eigen::Vector3d::Zero());
  state.rig_corrections.assign(rig.cameras.size(),
                               std::array<double, kRigCorrectionSize>{});

  // Tie points.
  if (input.tie_tracks != nullptr) {
    for (size_t i = 0; i < input.tie_tracks->size(); ++i) {
      const TieTrack& track = (*input.tie_tracks)[i];
      TiePoint tie;
      tie.estimate = track.p_enu;
      tie.source = static_cast<int>(i);
      for (const TieObservation& o : track.observations) {
        Pose ins_pose;
        if (o.camera < 0 || o.camera >= static_cast<int>(rig.cameras.size()) ||
            !ins_pose_at(o.time, &ins_pose)) {
          continue;
        }
        tie.observations.push_back({o.time, o.camera, o.uv, ins_pose, o.scale});
      }
      if (tie.observations.size() >= 2) state.ties.push_back(tie);
    }
  }
  summary.num_tie_tracks = static_cast<int>(state.ties.size());
  if (input.line_points != nullptr) {
    for (const LineControlPoint& line : *input.line_points) {
      Pose ins_pose;
      if (ins_pose_at(line.time, &ins_pose)) {
        state.lines.emplace_back(line, ins_pose);
      }
    }
  }

  state.correction =
      TrajectoryCorrection(trajectory.start_time(), trajectory.end_time(),
                           options.knot_spacing_s, options.track_frame);
  summary.num_knots = state.correction.num_knots();
  if (dejumped.num_jumps > 0) {
    for (int k = 0; k < state.correction.num_knots(); ++k) {
      const double t =
          std::clamp(state.correction.KnotTime(k), trajectory.start_time(),
                     trajectory.end_time());
      const int i = std::max(0, trajectory.FindSegment(t));
      Pose pose;
      ins_pose_at(t, &pose);
      const Eigen::Matrix3d R_track_enu =
          state.correction.Frame(pose).transpose();
      const Eigen::AngleAxisd rotation(dejumped.rotation_offset[i]);
      Eigen::Matrix<double, 6, 1> b;
      b.head<3>() = R_track_enu * (rotation.angle() * rotation.axis());
      b.tail<3>() = R_track_enu * dejumped.position_offset[i];
      state.knot_prior.push_back(b);
    }
  }
  if (options.sideslip_sigma_deg > 0.0) {
    std::vector<double> sample_times;
    sample_times.reserve(trajectory.size());
    for (const TrajectorySample& sample : trajectory.samples()) {
      sample_times.push_back(sample.time);
    }
    state.motion = MakeVehicleMotionSamples(
        state.correction, sample_times, options.vehicle_motion_rate_hz,
        options.vehicle_motion_half_chord_s,
        options.vehicle_motion_min_speed_mps,
        Eigen::Vector2d(options.sideslip_sigma_deg,
                        options.vertical_slip_sigma_deg) *
            kDegToRad,
        ins_pose_at);
  }
  summary.num_vehicle_motion = static_cast<int>(state.motion.size());
  // RMS angles (lateral, vertical) left unexplained, degrees.
  auto crab_rms_deg = [&state]() {
    std::vector<double> lateral, vertical;
    for (const VehicleMotionSample& sample : state.motion) {
      const Eigen::Vector2d crab =
          CrabAngleResidual(sample, state.correction, state.vehicle.data()) /
          kDegToRad;
      lateral.push_back(crab.x());
      vertical.push_back(crab.y());
    }
    return Eigen::Vector2d(Rms(lateral), Rms(vertical));
  };
  const Eigen::Vector2d crab_before_deg = crab_rms_deg();

  int num_control = 0;
  for (const ControlPoint& p : state.points) {
    num_control += p.status == ControlStatus::kControl;
  }
  const bool has_control = num_control > 0;
  if (!has_control) {
    warn(
        "no control point (no matched band vertex): the trajectory is not "
        "corrected, poses come from the input trajectory");
  }

  // ------------------------------------------------------------ solve
  state.gnss_sigma_m = EstimateGnssSigma(options, rig, state, num_crossings);
  summary.gnss_sigma_horizontal_m = state.gnss_sigma_m.x();
  summary.gnss_sigma_vertical_m = state.gnss_sigma_m.y();
  LOG(INFO) << "adjustment: GNSS/INS prior sigma " << state.gnss_sigma_m.x()
            << " m horizontal, " << state.gnss_sigma_m.y() << " m vertical";
  const StateRms before = MeasureState(rig, state);
  const int total_solves = 2 + options.max_blunder_iterations;
  auto solve = [&](bool robust) -> std::unique_ptr<AdjustmentProblem> {
    auto problem =
        std::make_unique<AdjustmentProblem>(options, rig, robust, &state);
    const ceres::Solver::Summary s = problem->Solve();
    ++summary.solves;
    summary.iterations += static_cast<int>(s.iterations.size()) - 1;
    summary.num_residuals = s.num_residuals;
    if (progress) progress(summary.solves, total_solves);
    if (!s.IsSolutionUsable() || !std::isfinite(s.final_cost)) {
      summary.message = "Ceres failed: " + s.message;
      return nullptr;
    }
    return problem;
  };
  std::unique_ptr<AdjustmentProblem> problem;
  // Back to the INS and the database, so a removed point leaves no trace.
  auto reset = [&state]() {
    for (Knot& k : state.correction.knots()) k.fill(0.0);
    for (Eigen::Vector3d& o : state.crossing_offsets) o.setZero();
    for (ControlPoint& p : state.points) p.estimate = p.database_enu;
    state.vehicle.fill(0.0);
  };
  // The adjustment with its blunder loop; false (summary.message set) when
  // it fails.
  auto adjust = [&]() -> bool {
    // Least squares first (the drift makes every observation look like an
    // outlier at the start), then robustly.
    if (!(problem = solve(false)) || !(problem = solve(true))) return false;
    for (int iteration = 0; iteration < options.max_blunder_iterations;
         ++iteration) {
      EvaluateControlPoints(options, rig, &state);
      double worst = 0.0;
      for (const ControlPoint& p : state.points) {
        if (p.status == ControlStatus::kControl) {
          worst = std::max(worst, p.normalized_residual);
        }
      }
      // A whole crossing off: its estimated offset against the offset prior.
      std::vector<double> crossing_w(num_crossings, 0.0);
      if (options.crossing_offset_sigma_m > 0.0) {
        for (int c = 0; c < num_crossings; ++c) {
          crossing_w[c] = state.crossing_offsets[c].norm() /
                          options.crossing_offset_sigma_m;
        }
      }
      for (const ControlPoint& p : state.points) {
        if (p.status == ControlStatus::kControl) {
          worst = std::max(worst, crossing_w[p.crossing]);
        }
      }
      if (worst <= options.blunder_threshold) break;
      for (ControlPoint& p : state.points) {
        if (p.status == ControlStatus::kControl &&
            crossing_w[p.crossing] > options.blunder_threshold &&
            crossing_w[p.crossing] >= 0.5 * worst) {
          p.status = ControlStatus::kRejected;
          p.normalized_residual =
              std::max(p.normalized_residual, crossing_w[p.crossing]);
        }
      }
      // Reject the worst vertices (those within half of the worst), then
      // whole crossings that lost too many.
      std::vector<int> rejected_in(num_crossings, 0),
          control_in(num_crossings, 0);
      for (ControlPoint& p : state.points) {
        if (p.status != ControlStatus::kControl) continue;
        ++control_in[p.crossing];
        if (p.normalized_residual > options.blunder_threshold &&
            p.normalized_residual >= 0.5 * worst) {
          p.status = ControlStatus::kRejected;
          ++rejected_in[p.crossing];
        }
      }
      for (ControlPoint& p : state.points) {
        if (p.status == ControlStatus::kControl &&
            rejected_in[p.crossing] >
                options.reject_crossing_share * control_in[p.crossing]) {
          p.status = ControlStatus::kRejected;
        }
      }
      int remaining = 0;
      for (const ControlPoint& p : state.points) {
        remaining += p.status == ControlStatus::kControl;
      }
      if (remaining == 0) {
        summary.message =
            "every control point was rejected as a blunder: the control "
            "disagrees with the trajectory and with itself";
        return false;
      }
      reset();
      if (!(problem = solve(false)) || !(problem = solve(true))) return false;
    }
    summary.sigma0 = problem->Sigma0();
    return true;
  };
  if (has_control || !state.ties.empty() || !state.lines.empty()) {
    const bool any_check = std::any_of(
        state.points.begin(), state.points.end(), [](const ControlPoint& p) {
          return p.status == ControlStatus::kCheck;
        });
    if (!adjust()) return result;
    if (any_check && options.check_points_in_final) {
      // The check points' residuals are those of this adjustment, which
      // did not see them; the final adjustment then uses every crossing.
      EvaluateControlPoints(options, rig, &state);
      for (ControlPoint& p : state.points) {
        if (p.status != ControlStatus::kCheck) continue;
        p.held_out = true;
        p.held_out_normalized_residual = p.normalized_residual;
        Eigen::Matrix3d covariance;
        p.held_out_triangulated = TriangulateWithState(
            rig, state, p.observations, p.database_enu, options.vertex_sigma_px,
            &p.held_out_enu, &covariance, &p.held_out_rms_px);
        p.status = ControlStatus::kControl;
      }
      reset();
      if (!adjust()) return result;
    }
  }
  EvaluateControlPoints(options, rig, &state);
  const StateRms after = MeasureState(rig, state);

  // ------------------------------------------------------------ covariance
  std::vector<Eigen::Matrix3d> sample_covariance;
  if (problem && options.compute_covariance &&
      state.correction.num_knots() <= options.max_knots_for_covariance) {
    ceres::Covariance::Options covariance_options;
    covariance_options.num_threads = options.solver.num_threads;
    covariance_options.algorithm_type = ceres::SPARSE_QR;
    ceres::Covariance covariance(covariance_options);
    auto& knots = state.correction.knots();
    const int n = static_cast<int>(knots.size());
    std::vector<std::pair<const double*, const double*>> pairs;
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < std::min(n, i + 4); ++j) {
        pairs.emplace_back(knots[i].data(), knots[j].data());
      }
    }
    if (covariance.Compute(pairs, problem->problem())) {
      const double scale = std::max(1.0, summary.sigma0 * summary.sigma0);
      sample_covariance.reserve(trajectory.size());
      for (const TrajectorySample& sample : trajectory.samples()) {
        int first = 0;
        double w[4];
        state.correction.Basis(sample.time, &first, w);
        Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
        for (int a = 0; a < 4; ++a) {
          for (int b = 0; b < 4; ++b) {
            const int i = std::min(first + a, first + b);
            const int j = std::max(first + a, first + b);
            Eigen::Matrix<double, 6, 6, Eigen::RowMajor> block;
            covariance.GetCovarianceBlock(knots[i].data(), knots[j].data(),
                                          block.data());
            Eigen::Matrix3d position = block.block<3, 3>(3, 3);
            if (first + a > first + b) position.transposeInPlace();
            C += w[a] * w[b] * position;
          }
        }
        sample_covariance.push_back(scale * C);
      }
      summary.covariance_computed = true;
    } else {
      warn(
          "the posterior covariance could not be computed (rank "
          "deficient): trajectory_corrected.csv keeps the input sd_*");
    }
  }

  // ------------------------------------------------------------ outputs
  result.correction = state.correction;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    result.T_body_cam.push_back(CorrectedBodyFromCamera(
        rig.cameras[c].T_body_cam, state.rig_corrections[c]));
  }
  std::vector<double> correction_h, sd_h, sd_v;
  for (int i = 0; i < trajectory.size(); ++i) {
    const TrajectorySample& sample = trajectory.samples()[i];
    const Pose corrected =
        state.correction.Apply(sample.time, dejumped.poses[i]);
    if (!corrected.p_enu.allFinite() ||
        !corrected.q_enu_body.coeffs().allFinite()) {
      summary.message = "the corrected trajectory is not finite";
      return result;
    }
    result.corrected_poses.push_back(corrected);
    Eigen::Vector3d sd_enu = sample.sd_enu_m;
    if (!sample_covariance.empty()) {
      sd_enu = sample_covariance[i].diagonal().cwiseMax(0.0).cwiseSqrt();
      sd_h.push_back(std::hypot(sd_enu.x(), sd_enu.y()));
      sd_v.push_back(sd_enu.z());
    }
    result.corrected_samples.push_back(SampleFromPose(
        sample.time, corrected, frame, sd_enu, sample.sd_attitude_rad));
    const Eigen::Vector3d d = corrected.p_enu - trajectory.poses()[i].p_enu;
    correction_h.push_back(d.head<2>().norm());
    summary.max_correction_horizontal_m =
        std::max(summary.max_correction_horizontal_m, d.head<2>().norm());
    summary.max_correction_vertical_m =
        std::max(summary.max_correction_vertical_m, std::abs(d.z()));
  }
  summary.rms_correction_horizontal_m = Rms(correction_h);
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  summary.median_posterior_sd_horizontal_m = median(sd_h);
  summary.median_posterior_sd_vertical_m = median(sd_v);

  // Camera poses, one per row of exposures.csv.
  int no_pose = 0;
  for (const ExposureImage& image : exposures.images) {
    Pose ins_pose;
    if (!ins_pose_at(image.time, &ins_pose)) {
      ++no_pose;
      continue;
    }
    const Pose corrected = state.correction.Apply(image.time, ins_pose);
    const Eigen::Isometry3d T_enu_cam =
        corrected.T_enu_body() * result.T_body_cam[image.camera];
    CameraPose pose;
    pose.exposure_id = image.exposure_id;
    pose.camera = rig.cameras[image.camera].camera.name();
    pose.time = image.time;
    pose.p_enu = T_enu_cam.translation();
    pose.position = frame.GeodeticFromEnu(pose.p_enu);
    pose.q_enu_cam = Eigen::Quaterniond(T_enu_cam.linear()).normalized();
    result.camera_poses.push_back(pose);
  }
  if (no_pose > 0) {
    warn(std::to_string(no_pose) +
         " images were taken outside the trajectory's time span: no pose");
  }

  // Bands placed with the corrected trajectory.
  std::map<std::pair<int64_t, int64_t>,
           std::array<const ReconstructedVertex*, 4>>
      band_vertices;
  for (const ReconstructedVertex& v : *input.vertices) {
    if (v.vertex < 0 || v.vertex > 3) continue;
    auto& slots = band_vertices[{v.exposure_id, v.band_id}];
    slots[v.vertex] = &v;
  }
  std::map<std::pair<int64_t, int64_t>, const VertexMatch*> band_match;
  for (const VertexMatch& m : *input.matches) {
    band_match.emplace(std::make_pair(m.exposure_id, m.band_id), &m);
  }
  for (const auto& [key, slots] : band_vertices) {
    if (std::any_of(
            slots.begin(), slots.end(),
            [](const ReconstructedVertex* v) { return v == nullptr; })) {
      continue;
    }
    const auto t = exposure_time.find(key.first);
    Pose ins_pose;
    if (t == exposure_time.end() || !ins_pose_at(t->second, &ins_pose)) {
      continue;
    }
    const Eigen::Isometry3d T_enu_body =
        state.correction.Apply(t->second, ins_pose).T_enu_body();
    AdjustedBand band;
    band.exposure_id = key.first;
    band.band_id = key.second;
    for (int v = 0; v < 4; ++v) {
      band.corners[v] = frame.GeodeticFromEnu(T_enu_body * slots[v]->p_body);
    }
    const auto m = band_match.find(key);
    if (m != band_match.end()) {
      band.crossing_id = m->second->crossing_id;
      band.band = m->second->band;
    }
    result.bands.push_back(band);
  }

  // Control and check points. Held-out check points are reported with their
  // residuals from the adjustment that did not see them.
  for (ControlPoint& p : state.points) {
    if (p.held_out && p.status == ControlStatus::kControl) {
      p.status = ControlStatus::kCheck;
      p.normalized_residual = p.held_out_normalized_residual;
      summary.check_points_in_final = true;
    }
  }
  std::vector<double> control_h, control_v, check_h, check_v;
  // What the database alone puts into a check residual, per the model the
  // adjustment uses for it: the vertex sigma and the crossing offset.
  std::vector<double> database_h, database_v;
  const double offset_variance =
      options.crossing_offset_sigma_m * options.crossing_offset_sigma_m;
  for (ControlPoint& p : state.points) {
    ControlPointResult r;
    r.crossing_id = p.crossing_id;
    r.band = p.band;
    r.db_vertex = p.db_vertex;
    r.status = p.status;
    r.database_enu = p.database_enu;
    r.normalized_residual = p.normalized_residual;
    r.n_images = static_cast<int>(p.observations.size());
    Eigen::Matrix3d covariance;
    double rms_px = 0.0;
    Eigen::Vector3d X;
    const bool from_held_out = p.held_out && p.status == ControlStatus::kCheck;
    if (from_held_out) {
      X = p.held_out_enu;
      rms_px = p.held_out_rms_px;
    }
    const bool triangulated =
        from_held_out
            ? p.held_out_triangulated
            : TriangulateWithState(
                  rig, state, p.observations,
                  p.status == ControlStatus::kControl ? p.estimate
                                                      : p.database_enu,
                  options.vertex_sigma_px, &X, &covariance, &rms_px);
    r.image_enu = triangulated ? X : p.database_enu;
    if (p.status == ControlStatus::kControl) {
      r.adjusted_enu = p.estimate;
      std::vector<double> errors;
      for (const ImageObservation& o : p.observations) {
        Eigen::Vector2d e;
        if (PixelResidual(rig, state, o, p.estimate, &e)) {
          errors.push_back(e.norm() / std::sqrt(2.0));
        }
      }
      r.rms_px = Rms(errors);
    } else {
      r.adjusted_enu = r.image_enu;
      r.rms_px = rms_px / std::sqrt(2.0);
    }
    const Eigen::Vector3d d = r.adjusted_enu - r.database_enu;
    if (p.status == ControlStatus::kControl) {
      ++summary.num_control_points;
      control_h.push_back(d.head<2>().norm());
      control_v.push_back(d.z());
    } else if (p.status == ControlStatus::kCheck) {
      ++summary.num_check_points;
      if (triangulated) {
        check_h.push_back(d.head<2>().norm());
        check_v.push_back(d.z());
        database_h.push_back(std::sqrt(p.sigma_m.head<2>().squaredNorm() +
                                       2.0 * offset_variance));
        database_v.push_back(
            std::sqrt(p.sigma_m.z() * p.sigma_m.z() + offset_variance));
      }
    } else {
      ++summary.num_rejected_points;
    }
    result.control_points.push_back(r);
  }
  std::set<int> control_crossings, check_crossings;
  for (const ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kControl)
      control_crossings.insert(p.crossing);
    if (p.status == ControlStatus::kCheck) check_crossings.insert(p.crossing);
  }
  summary.num_control_crossings = static_cast<int>(control_crossings.size());
  summary.num_check_crossings = static_cast<int>(check_crossings.size());
  summary.control_rmse_horizontal_m = Rms(control_h);
  summary.control_rmse_vertical_m = Rms(control_v);
  summary.check_rmse_horizontal_m = Rms(check_h);
  summary.check_rmse_vertical_m = Rms(check_v);
  summary.num_check_points_evaluated = static_cast<int>(check_h.size());
  summary.check_database_rms_horizontal_m = Rms(database_h);
  summary.check_database_rms_vertical_m = Rms(database_v);
  auto implied = [](double rmse, double database) {
    return std::sqrt(std::max(0.0, rmse * rmse - database * database));
  };
  summary.check_implied_trajectory_horizontal_m = implied(
      summary.check_rmse_horizontal_m, summary.check_database_rms_horizontal_m);
  summary.check_implied_trajectory_vertical_m = implied(
      summary.check_rmse_vertical_m, summary.check_database_rms_vertical_m);
  if (summary.num_rejected_points > 0) {
    std::set<std::string> names;
    for (const ControlPoint& p : state.points) {
      if (p.status == ControlStatus::kRejected) names.insert(p.crossing_id);
    }
    std::string list;
    for (const std::string& name : names)
      list += (list.empty() ? "" : ", ") + name;
    warn(std::to_string(summary.num_rejected_points) +
         " control vertices rejected as blunders (crossings " + list + ")");
  }

  // Tie points after adjustment.
  for (const TiePoint& tie : state.ties) {
    TieTrack track = (*input.tie_tracks)[tie.source];
    track.p_enu = tie.estimate;
    result.tie_tracks.push_back(track);
  }

  summary.rms.push_back({"control_image", "px", after.control_images,
                         before.control_px, after.control_px});
  summary.rms.push_back({"control_database", "m", after.control_points,
                         before.control_m, after.control_m});
  if (!state.ties.empty()) {
    summary.rms.push_back(
        {"tie_image", "px", after.tie_images, before.tie_px, after.tie_px});
  }
  if (!state.motion.empty()) {
    const Eigen::Vector2d crab_after_deg = crab_rms_deg();
    summary.rms.push_back({"vehicle_lateral_slip", "deg",
                           summary.num_vehicle_motion, crab_before_deg.x(),
                           crab_after_deg.x()});
    summary.rms.push_back({"vehicle_vertical_slip", "deg",
                           summary.num_vehicle_motion, crab_before_deg.y(),
                           crab_after_deg.y()});
    summary.vehicle_yaw_misalignment_deg = state.vehicle[0] / kDegToRad;
    summary.vehicle_axle_offset_m = state.vehicle[1];
    summary.vehicle_pitch_misalignment_deg = state.vehicle[2] / kDegToRad;
    LOG(INFO) << "adjustment: vehicle motion over "
              << summary.num_vehicle_motion << " constraints: lateral slip "
              << crab_before_deg.x() << " -> " << crab_after_deg.x()
              << " deg RMS, vertical " << crab_before_deg.y() << " -> "
              << crab_after_deg.y() << "; INS misalignment yaw "
              << summary.vehicle_yaw_misalignment_deg << " deg, pitch "
              << summary.vehicle_pitch_misalignment_deg << " deg, axle offset "
              << summary.vehicle_axle_offset_m << " m";
    if (crab_after_deg.x() > 3.0 * options.sideslip_sigma_deg ||
        crab_after_deg.y() > 3.0 * options.vertical_slip_sigma_deg) {
      warn(
          "the vehicle's direction of travel departs from its corrected "
          "attitude by " +
          std::to_string(crab_after_deg.x()) + " deg RMS laterally, " +
          std::to_string(crab_after_deg.y()) +
          " deg vertically, more than 3 x sideslip_sigma_deg or "
          "vertical_slip_sigma_deg: the vehicle-motion constraint does not "
          "fit this vehicle (set them wider, or 0 to disable it)");
    }
  }
  summary.rms.push_back({"trajectory_correction_horizontal", "m",
                         trajectory.size(), 0.0,
                         summary.rms_correction_horizontal_m});
  summary.time_in_seconds = Seconds(start);
  summary.usable = true;
  summary.message = has_control ? "adjusted" : "not adjusted: no control";
  LOG(INFO) << "adjustment: " << summary.BriefReport();
  return result;
}

}  // namespace zebrageo
