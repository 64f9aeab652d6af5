#include "adjustment/adjustment_problem.h"

#include <ceres/manifold.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "adjustment/cost_functions.h"
#include "adjustment/solver_options.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {

AdjustmentProblem::AdjustmentProblem(const AdjustmentOptions& options,
                                     const Rig& rig, bool robust, State* state)
    : options_(options), rig_(rig), state_(state) {
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  if (robust) {
    image_loss_ =
        std::make_unique<ceres::HuberLoss>(options.control.image_loss_scale);
    control_loss_ =
        std::make_unique<ceres::CauchyLoss>(options.control.control_loss_scale);
    line_loss_ =
        std::make_unique<ceres::CauchyLoss>(options.road_lines.line_loss_scale);
    motion_loss_ = std::make_unique<ceres::CauchyLoss>(
        options.vehicle_motion.vehicle_motion_loss_scale);
  }
  AddKnotPriors();
  AddExposureOffsets();
  AddRigPriors();
  AddControl();
  AddTiesAndLines();
  AddVehicleMotion();
}

namespace {

// Ends the solve between iterations once the run is cancelled.
class CancelCallback : public ceres::IterationCallback {
 public:
  explicit CancelCallback(const CancellationToken& cancel) : cancel_(cancel) {}
  ceres::CallbackReturnType operator()(
      const ceres::IterationSummary&) override {
    return cancel_.IsCancelled() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const CancellationToken& cancel_;
};

}  // namespace

ceres::Solver::Summary AdjustmentProblem::Solve(
    const CancellationToken& cancel) {
  ceres::Solver::Options solver_options =
      ToCeresOptions(options_.solver, num_pose_blocks_);
  CancelCallback cancel_callback(cancel);
  if (cancel.flag() != nullptr) {
    solver_options.callbacks.push_back(&cancel_callback);
  }
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
  for (Eigen::Vector3d& offset : state_->exposure_offsets) {
    if (problem_->HasParameterBlock(offset.data())) {
      ordering->AddElementToGroup(offset.data(), 1);
    }
  }
  solver_options.linear_solver_ordering = ordering;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, problem_.get(), &summary);
  VLOG(1) << summary.BriefReport();
  VLOG(2) << summary.FullReport();
  return summary;
}

double AdjustmentProblem::Sigma0() {
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

std::vector<double> AdjustmentProblem::Residuals(
    const std::vector<ceres::ResidualBlockId>& ids) {
  std::vector<double> residuals;
  if (ids.empty()) return residuals;
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  evaluate.residual_blocks = ids;
  problem_->Evaluate(evaluate, nullptr, &residuals, nullptr, nullptr);
  return residuals;
}

void AdjustmentProblem::AddImageResidual(
    const ImageObservation& o, double* point, double sigma_px,
    std::vector<ceres::ResidualBlockId>* ids) {
  int first = 0;
  double w[4];
  state_->correction.Basis(o.time, &first, w);
  auto& knots = state_->correction.knots();
  const RigCamera& camera = rig_.cameras[o.camera];
  std::vector<double*> blocks = {knots[first].data(), knots[first + 1].data(),
                                 knots[first + 2].data(),
                                 knots[first + 3].data(), point};
  if (options_.rig_calibration.self_calibrate_rig) {
    blocks.push_back(state_->rig_corrections[o.camera].data());
  }
  ids->push_back(
      AddWithExposure(SplineReprojectionCost::Create(
                          o.uv, Eigen::Matrix2d::Identity() / sigma_px, w,
                          o.ins_pose, state_->correction.Frame(o.ins_pose),
                          camera.T_body_cam, camera.camera.intrinsics(),
                          options_.rig_calibration.self_calibrate_rig),
                      image_loss_.get(), blocks, o.exposure));
}

ceres::ResidualBlockId AdjustmentProblem::AddWithExposure(
    ceres::CostFunction* cost, ceres::LossFunction* loss,
    std::vector<double*> blocks, int exposure) {
  if (exposure < 0 || !state_->model.HasJitter()) {
    return problem_->AddResidualBlock(cost, loss, blocks);
  }
  blocks.push_back(state_->exposure_offsets[exposure].data());
  return problem_->AddResidualBlock(new WithExposureOffset(cost), loss, blocks);
}

void AdjustmentProblem::AddExposureOffsets() {
  // The jitter of the positions: each exposure's offset follows the
  // previous one's by a Gauss-Markov step over the time between them.
  if (!state_->model.HasJitter()) return;
  const Eigen::Vector3d sigma =
      state_->model.jitter_sigma_m.cwiseMax(Eigen::Vector3d::Constant(1e-4));
  const Eigen::Vector3d& tau = state_->model.jitter_tau_s;
  for (size_t e = 0; e < state_->exposure_offsets.size(); ++e) {
    double* offset = state_->exposure_offsets[e].data();
    problem_->AddParameterBlock(offset, 3);
    if (e == 0) {
      problem_->AddResidualBlock(VectorProcessPrior::CreateFirst(sigma),
                                 nullptr, offset);
      continue;
    }
    const double dt = state_->exposure_times[e] - state_->exposure_times[e - 1];
    Eigen::Vector3d phi;
    for (int i = 0; i < 3; ++i) phi[i] = std::exp(-dt / tau[i]);
    problem_->AddResidualBlock(VectorProcessPrior::CreateStep(sigma, phi),
                               nullptr, state_->exposure_offsets[e - 1].data(),
                               offset);
    ++num_pose_blocks_;
  }
}

void AdjustmentProblem::AddKnotPriors() {
  // The GNSS/INS error as a correlated process (adjustment_state.h):
  // attitude and position as separate blocks, so that the robust loss of a
  // position innovation (a GNSS jump the de-jumping missed) does not switch
  // off the attitude prior.
  auto& knots = state_->correction.knots();
  const int n = static_cast<int>(knots.size());
  const double dt = state_->correction.knot_spacing();
  for (Knot& k : knots) problem_->AddParameterBlock(k.data(), kKnotSize);
  num_pose_blocks_ = n;
  HoldAxes();
  const Eigen::Matrix<double, 6, 1> sigma = state_->model.Sigma();
  const Eigen::Matrix<double, 6, 1> level = state_->model.LevelSigma();
  const Eigen::Matrix<double, 6, 1> tau = state_->model.Tau();
  Eigen::Matrix<double, 6, 1> phi;
  for (int i = 0; i < 6; ++i) phi[i] = std::exp(-dt / tau[i]);
  const Eigen::Matrix<double, 6, 1> zero = Eigen::Matrix<double, 6, 1>::Zero();
  auto b = [&](int k) -> const Eigen::Matrix<double, 6, 1>& {
    return state_->knot_prior.empty() ? zero : state_->knot_prior[k];
  };
  for (int k = 0; k < n; ++k) {
    for (int part = 0; part < 2; ++part) {
      const int offset = 3 * part;
      Eigen::Vector3d s = sigma.segment<3>(offset);
      if (part == 1 && k > 0 && !state_->knot_extra_variance_m2.empty()) {
        // A jump that stays a step, an outage's closure: the innovation's
        // variance grows by what the error gains over this step.
        for (int i = 0; i < 3; ++i) {
          s[i] = std::sqrt(s[i] * s[i] +
                           state_->knot_extra_variance_m2[k][i] /
                               std::max(1e-12, 1.0 - phi[3 + i] * phi[3 + i]));
        }
      }
      // No robust loss on the process: with a small sigma a robust loss
      // makes a metre-size single-knot spike cheap, and the GNSS jumps it
      // would be for are taken out of the trajectory beforehand
      // (trajectory_jumps.h).
      ceres::ResidualBlockId id;
      if (k == 0) {
        id = problem_->AddResidualBlock(
            KnotProcessPrior::CreateFirst(offset, level.segment<3>(offset),
                                          b(0)),
            nullptr, knots[0].data());
      } else {
        id = problem_->AddResidualBlock(
            KnotProcessPrior::CreateStep(offset, s, phi.segment<3>(offset),
                                         b(k - 1), b(k)),
            nullptr, knots[k - 1].data(), knots[k].data());
      }
      (part == 0 ? blocks_.attitude_prior : blocks_.position_prior)
          .push_back(id);
    }
  }
}

void AdjustmentProblem::HoldAxes() {
  // Held axes stay at the prior's centre: the input's attitude and
  // position (with its jumps, knot_prior).
  std::vector<int> held;
  for (int a = 0; a < 3; ++a) {
    if (state_->attitude_held[a]) held.push_back(a);
  }
  if (state_->along_track_held) held.push_back(3);
  if (held.empty()) return;
  auto& knots = state_->correction.knots();
  for (size_t k = 0; k < knots.size(); ++k) {
    for (int a : held) {
      knots[k][a] = state_->knot_prior.empty() ? 0.0 : state_->knot_prior[k][a];
    }
    problem_->SetManifold(knots[k].data(),
                          new ceres::SubsetManifold(kKnotSize, held));
  }
}

void AdjustmentProblem::AddRigPriors() {
  // Rig mounting: parameters only when self-calibrating.
  if (!options_.rig_calibration.self_calibrate_rig) return;
  for (auto& r : state_->rig_corrections) {
    problem_->AddParameterBlock(r.data(), kRigCorrectionSize);
    Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
    S.diagonal().head<3>().setConstant(
        1.0 / options_.rig_calibration.boresight_sigma_rad);
    S.diagonal().tail<3>().setConstant(
        1.0 / options_.rig_calibration.lever_arm_sigma_m);
    problem_->AddResidualBlock(LinearPrior<1, 6>::Create(S, {1.0}), nullptr,
                               r.data());
    ++num_pose_blocks_;
  }
}

void AdjustmentProblem::AddControl() {
  // Control points and their crossings' offsets.
  std::vector<char> offset_used(state_->crossing_offsets.size(), 0);
  for (ControlPoint& p : state_->points) {
    if (p.status != ControlStatus::kControl) continue;
    double* offset = state_->crossing_offsets[p.crossing].data();
    if (!offset_used[p.crossing]) {
      offset_used[p.crossing] = 1;
      problem_->AddParameterBlock(offset, 3);
      if (options_.control.crossing_offset_sigma_m > 0.0) {
        // Robust: a crossing far from where the database has it (a wrong
        // match, a repainted crossing) moves its own offset, not the
        // trajectory; the blunder test then rejects it.
        problem_->AddResidualBlock(
            LinearPrior<1, 3>::Create(
                Eigen::Matrix3d::Identity() /
                    options_.control.crossing_offset_sigma_m,
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
    if (options_.rig_calibration.self_calibrate_rig) {
      for (const ImageObservation& o : p.observations) {
        AddImageResidual(o, p.estimate.data(), options_.control.vertex_sigma_px,
                         &blocks_.control_images);
      }
      continue;
    }
    auto& knots = state_->correction.knots();
    for (const StereoObservation& o : p.stereo) {
      int first = 0;
      double w[4];
      state_->correction.Basis(o.time, &first, w);
      const Eigen::Matrix3d information =
          ObservationCovariance(options_, o).inverse();
      // S^T S = information.
      const Eigen::Matrix3d S_body = information.llt().matrixL().transpose();
      blocks_.control_images.push_back(AddWithExposure(
          new SplineStereoVertexCost(
              StereoVertexError(o.p_body, S_body, o.ins_pose,
                                state_->correction.Frame(o.ins_pose)),
              w),
          image_loss_.get(),
          {knots[first].data(), knots[first + 1].data(),
           knots[first + 2].data(), knots[first + 3].data(), p.estimate.data()},
          o.exposure));
    }
  }
}

void AdjustmentProblem::AddTiesAndLines() {
  for (TiePoint& t : state_->ties) {
    for (const ImageObservation& o : t.observations) {
      AddImageResidual(o, t.estimate.data(),
                       state_->model.tie_sigma_px * o.sigma_scale,
                       &blocks_.tie_images);
    }
  }
  auto& knots = state_->correction.knots();
  for (const State::Line& line : state_->lines) {
    int first = 0;
    double w[4];
    state_->correction.Basis(line.point.time, &first, w);
    blocks_.lines.push_back(AddWithExposure(
        LinePointCost::Create(line.point, line.ins_pose,
                              state_->correction.Frame(line.ins_pose), w),
        line_loss_.get(),
        {knots[first].data(), knots[first + 1].data(), knots[first + 2].data(),
         knots[first + 3].data()},
        line.exposure));
  }
}

void AdjustmentProblem::AddVehicleMotion() {
  if (state_->motion.empty()) return;
  double* vehicle = state_->vehicle.data();
  problem_->AddParameterBlock(vehicle, kVehicleSize);
  ++num_pose_blocks_;
  // Road lines alone (the along-track position held): a yaw misalignment
  // and a cross-track ramp are one and the same beyond the lines' span,
  // so the misalignment's prior tightens (AdjustmentOptions); the pitch
  // misalignment shares the prior, and tightens with it (as measured).
  const double misalignment_sigma_rad =
      state_->along_track_held
          ? std::min(options_.vehicle_motion.vehicle_misalignment_sigma_rad,
                     options_.vehicle_motion.lines_only_misalignment_sigma_rad)
          : options_.vehicle_motion.vehicle_misalignment_sigma_rad;
  const double misalignment = 1.0 / misalignment_sigma_rad;
  const Eigen::Matrix3d S =
      Eigen::Vector3d(misalignment,
                      1.0 / options_.vehicle_motion.axle_offset_sigma_m,
                      misalignment)
          .asDiagonal();
  problem_->AddResidualBlock(LinearPrior<1, kVehicleSize>::Create(S, {1.0}),
                             nullptr, vehicle);
  auto& knots = state_->correction.knots();
  for (VehicleMotionSample sample : state_->motion) {
    sample.sigma_lateral_rad = state_->model.motion_sigma_rad.x();
    sample.sigma_vertical_rad = state_->model.motion_sigma_rad.y();
    VehicleMotionCost* cost =
        VehicleMotionCost::Create(sample, state_->correction);
    std::vector<double*> blocks;
    for (int k = 0; k < cost->num_knots(); ++k) {
      blocks.push_back(knots[cost->first_knot() + k].data());
    }
    blocks.push_back(vehicle);
    blocks_.motion.push_back(
        problem_->AddResidualBlock(cost, motion_loss_.get(), blocks));
  }
}

}  // namespace adjustment_internal
}  // namespace zebrageo
