// The trajectory adjustment's results from its final state
// (adjustment_outputs.h).
#include "adjustment/adjustment_outputs.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

#include "adjustment/input_guard.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// Corrected samples and poses, one per input sample; the correction's size.
bool FillTrajectory(const OutputContext& context, const State& state,
                    AdjustmentResult* result) {
  const Trajectory& trajectory = *context.input->trajectory;
  const LocalFrame& frame = *context.input->frame;
  AdjustmentSummary& summary = result->summary;
  std::vector<double> correction_h, sd_h, sd_v;
  for (int i = 0; i < trajectory.size(); ++i) {
    const TrajectorySample& sample = trajectory.samples()[i];
    if (!context.adjusted) {
      result->corrected_poses.push_back(trajectory.poses()[i]);
      result->corrected_samples.push_back(sample);
      correction_h.push_back(0.0);
      continue;
    }
    Pose corrected =
        state.correction.Apply(sample.time, context.dejumped->poses[i]);
    corrected.p_enu += ExposureOffsetAt(state, sample.time);
    if (!corrected.p_enu.allFinite() ||
        !corrected.q_enu_body.coeffs().allFinite()) {
      summary.message = "the corrected trajectory is not finite";
      return false;
    }
    // Where the guard keeps the input, the input's pose and stated sd.
    const bool guarded = context.guard != nullptr &&
                         context.guard->AdjustedWeight(sample.time) < 1.0;
    if (guarded) {
      corrected = GuardedPose(*context.guard, sample.time, corrected,
                              trajectory.poses()[i]);
    }
    result->corrected_poses.push_back(corrected);
    Eigen::Vector3d sd_enu = sample.sd_enu_m;
    if (!context.sample_covariance.empty() && !guarded) {
      sd_enu =
          context.sample_covariance[i].diagonal().cwiseMax(0.0).cwiseSqrt();
      sd_h.push_back(std::hypot(sd_enu.x(), sd_enu.y()));
      sd_v.push_back(sd_enu.z());
    }
    result->corrected_samples.push_back(SampleFromPose(
        sample.time, corrected, frame, sd_enu, sample.sd_attitude_rad));
    const Eigen::Vector3d d = corrected.p_enu - trajectory.poses()[i].p_enu;
    correction_h.push_back(d.head<2>().norm());
    summary.max_correction_horizontal_m =
        std::max(summary.max_correction_horizontal_m, d.head<2>().norm());
    summary.max_correction_vertical_m =
        std::max(summary.max_correction_vertical_m, std::abs(d.z()));
  }
  summary.rms_correction_horizontal_m = Rms(correction_h);
  summary.median_posterior_sd_horizontal_m = Median(sd_h);
  summary.median_posterior_sd_vertical_m = Median(sd_v);
  return true;
}

// One camera pose per row of exposures.csv.
void FillCameraPoses(const OutputContext& context, const State& state,
                     AdjustmentResult* result) {
  const Rig& rig = *context.input->rig;
  int no_pose = 0;
  for (const ExposureImage& image : context.input->exposures->images) {
    Pose corrected;
    if (!OutputPoseAt(context, state, image.time, &corrected)) {
      ++no_pose;
      continue;
    }
    const Eigen::Isometry3d T_enu_cam =
        corrected.T_enu_body() * result->T_body_cam[image.camera];
    CameraPose pose;
    pose.exposure_id = image.exposure_id;
    pose.camera = rig.cameras[image.camera].camera.name();
    pose.time = image.time;
    pose.p_enu = T_enu_cam.translation();
    pose.position = context.input->frame->GeodeticFromEnu(pose.p_enu);
    pose.q_enu_cam = Eigen::Quaterniond(T_enu_cam.linear()).normalized();
    result->camera_poses.push_back(pose);
  }
  if (no_pose > 0) {
    context.warn(std::to_string(no_pose) +
                 " images were taken outside the trajectory's time span: no "
                 "pose");
  }
}

// Each reconstructed band placed with the corrected trajectory.
void FillBands(const OutputContext& context, State* state,
               AdjustmentResult* result) {
  std::unordered_map<int64_t, double> exposure_time;
  for (const Exposure& e : context.input->exposures->exposures) {
    exposure_time[e.exposure_id] = e.time;
  }
  // Bands placed with the corrected trajectory.
  std::map<std::pair<int64_t, int64_t>,
           std::array<const ReconstructedVertex*, 4>>
      band_vertices;
  for (const ReconstructedVertex& v : *context.input->vertices) {
    if (v.vertex < 0 || v.vertex > 3) continue;
    auto& slots = band_vertices[{v.exposure_id, v.band_id}];
    slots[v.vertex] = &v;
  }
  std::map<std::pair<int64_t, int64_t>, const VertexMatch*> band_match;
  for (const VertexMatch& m : *context.input->matches) {
    band_match.emplace(std::make_pair(m.exposure_id, m.band_id), &m);
  }
  for (const auto& [key, slots] : band_vertices) {
    if (std::any_of(
            slots.begin(), slots.end(),
            [](const ReconstructedVertex* v) { return v == nullptr; })) {
      continue;
    }
    const auto t = exposure_time.find(key.first);
    Pose pose;
    if (t == exposure_time.end() ||
        !OutputPoseAt(context, *state, t->second, &pose)) {
      continue;
    }
    const Eigen::Isometry3d T_enu_body = pose.T_enu_body();
    AdjustedBand band;
    band.exposure_id = key.first;
    band.band_id = key.second;
    for (int v = 0; v < 4; ++v) {
      band.corners[v] =
          context.input->frame->GeodeticFromEnu(T_enu_body * slots[v]->p_body);
    }
    const auto m = band_match.find(key);
    if (m != band_match.end()) {
      band.crossing_id = m->second->crossing_id;
      band.band = m->second->band;
    }
    result->bands.push_back(band);
  }
}

// Held-out check points are reported with their residuals from the
// adjustment that did not see them.
void MarkHeldOutAsChecks(State* state, AdjustmentSummary* summary) {
  for (ControlPoint& p : state->points) {
    if (p.held_out && p.status == ControlStatus::kControl) {
      p.status = ControlStatus::kCheck;
      p.normalized_residual = p.held_out_normalized_residual;
      summary->check_points_in_final = true;
    }
  }
}

// The result of control point p: where its images put it (from the
// held-out adjustment, or triangulated from its stereo observations), its
// adjusted position and its reprojection RMS per axis. *triangulated: the
// images placed it (else image_enu is the database's).
ControlPointResult ControlPointResultOf(const AdjustmentOptions& options,
                                        const Rig& rig, const State& state,
                                        const ControlPoint& p,
                                        bool* triangulated) {
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
  *triangulated =
      from_held_out ? p.held_out_triangulated
                    : StereoPosition(options, state, p.stereo, &X, &covariance);
  if (*triangulated && !from_held_out) {
    std::vector<double> errors;
    for (const ImageObservation& o : p.observations) {
      Eigen::Vector2d e;
      if (PixelResidual(rig, state, o, X, &e)) errors.push_back(e.norm());
    }
    rms_px = Rms(errors);
  }
  r.image_enu = *triangulated ? X : p.database_enu;
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
  return r;
}

// Adjusted minus database, horizontal and vertical, of the control points
// and of the check points the images placed; and what the database alone
// puts into each such check residual.
struct ControlResiduals {
  std::vector<double> control_h, control_v, check_h, check_v;
  std::vector<double> database_h, database_v;
};

// Adds point p's residuals (result r) and counts it in *summary.
// offset_variance: of the crossing offset the adjustment models.
void AddResiduals(const ControlPoint& p, const ControlPointResult& r,
                  bool triangulated, double offset_variance,
                  ControlResiduals* residuals, AdjustmentSummary* summary) {
  const Eigen::Vector3d d = r.adjusted_enu - r.database_enu;
  if (p.status == ControlStatus::kControl) {
    ++summary->num_control_points;
    residuals->control_h.push_back(d.head<2>().norm());
    residuals->control_v.push_back(d.z());
  } else if (p.status == ControlStatus::kCheck) {
    ++summary->num_check_points;
    if (triangulated) {
      residuals->check_h.push_back(d.head<2>().norm());
      residuals->check_v.push_back(d.z());
      residuals->database_h.push_back(
          std::sqrt(p.sigma_m.head<2>().squaredNorm() + 2.0 * offset_variance));
      residuals->database_v.push_back(
          std::sqrt(p.sigma_m.z() * p.sigma_m.z() + offset_variance));
    }
  } else {
    ++summary->num_rejected_points;
  }
}

// The summary's crossing counts and RMS residuals of control and check
// points, and the trajectory error the check residuals imply.
void SummariseControlResiduals(const State& state,
                               const ControlResiduals& residuals,
                               AdjustmentSummary* summary) {
  std::set<int> control_crossings, check_crossings;
  for (const ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kControl)
      control_crossings.insert(p.crossing);
    if (p.status == ControlStatus::kCheck) check_crossings.insert(p.crossing);
  }
  summary->num_control_crossings = static_cast<int>(control_crossings.size());
  summary->num_check_crossings = static_cast<int>(check_crossings.size());
  summary->control_rmse_horizontal_m = Rms(residuals.control_h);
  summary->control_rmse_vertical_m = Rms(residuals.control_v);
  summary->check_rmse_horizontal_m = Rms(residuals.check_h);
  summary->check_rmse_vertical_m = Rms(residuals.check_v);
  summary->num_check_points_evaluated =
      static_cast<int>(residuals.check_h.size());
  summary->check_database_rms_horizontal_m = Rms(residuals.database_h);
  summary->check_database_rms_vertical_m = Rms(residuals.database_v);
  auto implied = [](double rmse, double database) {
    return std::sqrt(std::max(0.0, rmse * rmse - database * database));
  };
  summary->check_implied_trajectory_horizontal_m =
      implied(summary->check_rmse_horizontal_m,
              summary->check_database_rms_horizontal_m);
  summary->check_implied_trajectory_vertical_m = implied(
      summary->check_rmse_vertical_m, summary->check_database_rms_vertical_m);
}

// The warning naming the crossings of the rejected control vertices.
std::string RejectedPointsWarning(const State& state,
                                  const AdjustmentSummary& summary) {
  std::set<std::string> names;
  for (const ControlPoint& p : state.points) {
    if (p.status == ControlStatus::kRejected) names.insert(p.crossing_id);
  }
  std::string list;
  for (const std::string& name : names)
    list += (list.empty() ? "" : ", ") + name;
  return std::to_string(summary.num_rejected_points) +
         " control vertices rejected (crossings " + list +
         "): inconsistent with the other crossings, or blunders; not "
         "used as control, removed from matches.csv";
}

// Control, check and rejected points with their residuals; the summary's
// counts and RMSEs.
void FillControlPoints(const OutputContext& context, State* state,
                       AdjustmentResult* result) {
  const AdjustmentOptions& options = *context.options;
  const Rig& rig = *context.input->rig;
  AdjustmentSummary& summary = result->summary;
  MarkHeldOutAsChecks(state, &summary);
  // What the database alone puts into a check residual, per the model the
  // adjustment uses for it: the vertex sigma and the crossing offset.
  const double offset_variance = options.control.crossing_offset_sigma_m *
                                 options.control.crossing_offset_sigma_m;
  ControlResiduals residuals;
  for (const ControlPoint& p : state->points) {
    bool triangulated = false;
    const ControlPointResult r =
        ControlPointResultOf(options, rig, *state, p, &triangulated);
    AddResiduals(p, r, triangulated, offset_variance, &residuals, &summary);
    result->control_points.push_back(r);
  }
  SummariseControlResiduals(*state, residuals, &summary);
  if (summary.num_rejected_points > 0) {
    context.warn(RejectedPointsWarning(*state, summary));
  }
}

void SummariseModel(const State& state, AdjustmentSummary* summary) {
  summary->position_sigma_m = state.model.position_sigma_m;
  summary->position_tau_s = state.model.position_tau_s;
  summary->attitude_sigma_rad = state.model.attitude_sigma_rad;
  summary->motion_sigma_rad = state.model.motion_sigma_rad;
  summary->tie_sigma_px = state.model.tie_sigma_px;
}

}  // namespace

Eigen::Vector3d ExposureOffsetAt(const State& state, double time) {
  const std::vector<double>& times = state.exposure_times;
  if (!state.model.HasJitter() || times.empty() || time < times.front() ||
      time > times.back()) {
    return Eigen::Vector3d::Zero();
  }
  // ENU offset of exposure e, from its track frame.
  auto enu = [&state](int e) -> Eigen::Vector3d {
    return state.exposure_frames[e] * state.exposure_offsets[e];
  };
  const auto it = std::lower_bound(times.begin(), times.end(), time);
  const int b = static_cast<int>(it - times.begin());
  if (std::abs(times[b] - time) < 1e-6 || b == 0) return enu(b);
  const double u = (time - times[b - 1]) / (times[b] - times[b - 1]);
  return (1.0 - u) * enu(b - 1) + u * enu(b);
}

bool OutputPoseAt(const OutputContext& context, const State& state, double time,
                  Pose* pose) {
  const Trajectory& trajectory = *context.input->trajectory;
  if (!context.adjusted) return trajectory.InterpolatePose(time, pose);
  Pose ins_pose;
  if (!InterpolateDejumped(trajectory, *context.dejumped, time, &ins_pose)) {
    return false;
  }
  *pose = state.correction.Apply(time, ins_pose);
  pose->p_enu += ExposureOffsetAt(state, time);
  if (context.guard != nullptr && context.guard->AdjustedWeight(time) < 1.0) {
    Pose input;
    if (!trajectory.InterpolatePose(time, &input)) return false;
    *pose = GuardedPose(*context.guard, time, *pose, input);
  }
  return true;
}

bool FillOutputs(const OutputContext& context, State* state,
                 AdjustmentResult* result) {
  const Rig& rig = *context.input->rig;
  result->correction = state->correction;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    result->T_body_cam.push_back(CorrectedBodyFromCamera(
        rig.cameras[c].T_body_cam, state->rig_corrections[c]));
  }
  if (!FillTrajectory(context, *state, result)) return false;
  FillCameraPoses(context, *state, result);
  FillBands(context, state, result);
  FillControlPoints(context, state, result);
  // Tie points after adjustment.
  for (const TiePoint& tie : state->ties) {
    TieTrack track = (*context.input->tie_tracks)[tie.source];
    track.p_enu = tie.estimate;
    result->tie_tracks.push_back(track);
  }

  return true;
}

Eigen::Vector2d CrabRmsDeg(const State& state) {
  std::vector<double> lateral, vertical;
  for (const VehicleMotionSample& sample : state.motion) {
    const Eigen::Vector2d crab =
        CrabAngleResidual(sample, state.correction, state.vehicle.data());
    lateral.push_back(RadToDeg(crab.x()));
    vertical.push_back(RadToDeg(crab.y()));
  }
  return Eigen::Vector2d(Rms(lateral), Rms(vertical));
}

void SummariseFinalState(const OutputContext& context, const State& state,
                         const StateRms& before, const StateRms& after,
                         const Eigen::Vector2d& crab_before_deg,
                         AdjustmentSummary* summary) {
  summary->rms.push_back({"control_image", "px", after.control_images,
                          before.control_px, after.control_px});
  summary->rms.push_back({"control_database", "m", after.control_points,
                          before.control_m, after.control_m});
  if (!state.ties.empty()) {
    summary->rms.push_back(
        {"tie_image", "px", after.tie_images, before.tie_px, after.tie_px});
  }
  if (!state.motion.empty()) {
    const Eigen::Vector2d crab_after_deg = CrabRmsDeg(state);
    summary->rms.push_back({"vehicle_lateral_slip", "deg",
                            summary->num_vehicle_motion, crab_before_deg.x(),
                            crab_after_deg.x()});
    summary->rms.push_back({"vehicle_vertical_slip", "deg",
                            summary->num_vehicle_motion, crab_before_deg.y(),
                            crab_after_deg.y()});
    summary->vehicle_yaw_misalignment_deg = RadToDeg(state.vehicle[0]);
    summary->vehicle_axle_offset_m = state.vehicle[1];
    summary->vehicle_pitch_misalignment_deg = RadToDeg(state.vehicle[2]);
  }
  SummariseModel(state, summary);
  summary->rms.push_back({"trajectory_correction_horizontal", "m",
                          context.input->trajectory->size(), 0.0,
                          summary->rms_correction_horizontal_m});
}

}  // namespace adjustment_internal
}  // namespace zebrageo
