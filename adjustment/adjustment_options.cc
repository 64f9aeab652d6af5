#include "adjustment/adjustment_options.h"

#include <glog/logging.h>

#include <cmath>
#include <sstream>
#include <string>

#include "adjustment/trajectory_adjuster.h"
#include "survey/option_check.h"

namespace zebrageo {

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

void LogAdjustmentWarning(const AdjustmentOptions& options,
                          const std::string& warning) {
  if (options.log_warnings) {
    LOG(WARNING) << warning;
  } else {
    VLOG(1) << warning;
  }
}

std::string TrajectoryModelOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, knot_spacing_s, 0.0);
  OPTION_GT(check, min_position_sigma_m, 0.0);
  OPTION_GE(check, max_position_sigma_m, min_position_sigma_m);
  OPTION_GT(check, position_tau_s, 0.0);
  OPTION_GE(check, min_crossings_for_tau, 2);
  OPTION_GT(check, min_attitude_sigma_rad, 0.0);
  OPTION_GE(check, max_attitude_sigma_rad, min_attitude_sigma_rad);
  OPTION_GT(check, attitude_tau_s, 0.0);
  OPTION_GE(check, attitude_significance, 0.0);  // 0 disables
  OPTION_GE(check, max_variance_iterations, 0);
  return check.problem();
}

std::string TrajectoryFaultOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, jitter_window_s, 0.0);
  OPTION_GT(check, min_jitter_m, 0.0);
  OPTION_GE(check, jump_threshold_m, 0.0);  // 0 disables
  OPTION_GE(check, jump_threshold_rad, 0.0);
  OPTION_NESTED(check, sideways_switches);
  return check.problem();
}

std::string ControlPointOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, stereo_covariance_scale, 0.0);
  OPTION_GT(check, min_stereo_sigma_m, 0.0);
  OPTION_GT(check, vertex_sigma_px, 0.0);
  OPTION_GT(check, image_loss_scale, 0.0);
  OPTION_GT(check, min_database_sigma_m, 0.0);
  OPTION_GE(check, crossing_offset_sigma_m, 0.0);  // 0 disables
  OPTION_GT(check, control_loss_scale, 0.0);
  OPTION_IN(check, check_crossing_share, "[", 0.0, 1.0, ")");
  OPTION_GE(check, min_control_crossings, 1);
  return check.problem();
}

std::string ControlSelectionOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, crossing_consistency_chi_square, 0.0);
  OPTION_GT(check, two_crossings_position_sigma_m, 0.0);
  return check.problem();
}

std::string BlunderOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, blunder_threshold, 0.0);
  OPTION_GT(check, blunder_sigma_floor_m, 0.0);
  OPTION_GE(check, max_blunder_iterations, 0);
  OPTION_IN(check, reject_crossing_share, "(", 0.0, 1.0, "]");
  return check.problem();
}

std::string LineControlOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, line_loss_scale, 0.0);
  OPTION_GT(check, line_discrepancy_bin_s, 0.0);
  OPTION_GE(check, line_discrepancy_min_points, 1);
  return check.problem();
}

std::string TiePointWeightOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, tie_sigma_px, 0.0);
  return check.problem();
}

std::string VehicleMotionOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, sideslip_sigma_rad, 0.0);  // 0 disables
  OPTION_GT(check, vertical_slip_sigma_rad, 0.0);
  OPTION_GT(check, vehicle_motion_rate_hz, 0.0);
  OPTION_GT(check, vehicle_motion_correlation_s, 0.0);
  OPTION_GT(check, vehicle_motion_half_chord_s, 0.0);
  OPTION_GE(check, vehicle_motion_min_speed_mps, 0.0);
  OPTION_GT(check, vehicle_misalignment_sigma_rad, 0.0);
  OPTION_GT(check, lines_only_misalignment_sigma_rad, 0.0);
  OPTION_GT(check, axle_offset_sigma_m, 0.0);
  OPTION_GT(check, vehicle_motion_loss_scale, 0.0);
  return check.problem();
}

std::string RigCalibrationOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, boresight_sigma_rad, 0.0);
  OPTION_GT(check, lever_arm_sigma_m, 0.0);
  return check.problem();
}

std::string CovarianceOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, max_knots_for_covariance, 0);
  OPTION_GT(check, weak_sd_database_factor, 0.0);
  OPTION_GT(check, weak_sd_floor_m, 0.0);
  OPTION_GT(check, weak_control_radius_m, 0.0);
  OPTION_GT(check, weak_min_length_m, 0.0);
  return check.problem();
}

std::string AdjustmentOptions::Check() const {
  OptionCheck check;
  OPTION_NESTED(check, model);
  OPTION_NESTED(check, trajectory_faults);
  OPTION_NESTED(check, control);
  OPTION_NESTED(check, selection);
  OPTION_NESTED(check, blunders);
  OPTION_NESTED(check, road_lines);
  OPTION_NESTED(check, tie_points);
  OPTION_NESTED(check, vehicle_motion);
  OPTION_NESTED(check, rig_calibration);
  OPTION_NESTED(check, covariance);
  OPTION_NESTED(check, never_worse);
  OPTION_NESTED(check, solver);
  return check.problem();
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

}  // namespace zebrageo
