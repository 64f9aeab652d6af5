#include <glog/logging.h>

#include <cmath>
#include <sstream>
#include <string>

#include "adjustment/trajectory_adjuster.h"

namespace zebrageo {
namespace {

template <typename T>
std::string Violation(const char* field, T value, const char* constraint) {
  std::ostringstream message;
  message << field << " = " << value << ": " << constraint;
  return message.str();
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

void LogAdjustmentWarning(const AdjustmentOptions& options,
                          const std::string& warning) {
  if (options.log_warnings) {
    LOG(WARNING) << warning;
  } else {
    VLOG(1) << warning;
  }
}

std::string AdjustmentOptions::Check() const {
  struct Positive {
    const char* name;
    double value;
  };
  const Positive positives[] = {
      {"knot_spacing_s", knot_spacing_s},
      {"min_position_sigma_m", min_position_sigma_m},
      {"position_tau_s", position_tau_s},
      {"jitter_window_s", jitter_window_s},
      {"min_jitter_m", min_jitter_m},
      {"min_attitude_sigma_rad", min_attitude_sigma_rad},
      {"attitude_tau_s", attitude_tau_s},
      {"crossing_consistency_chi_square", crossing_consistency_chi_square},
      {"two_crossings_position_sigma_m", two_crossings_position_sigma_m},
      {"vertex_sigma_px", vertex_sigma_px},
      {"stereo_covariance_scale", stereo_covariance_scale},
      {"min_stereo_sigma_m", min_stereo_sigma_m},
      {"image_loss_scale", image_loss_scale},
      {"min_database_sigma_m", min_database_sigma_m},
      {"control_loss_scale", control_loss_scale},
      {"blunder_threshold", blunder_threshold},
      {"blunder_sigma_floor_m", blunder_sigma_floor_m},
      {"tie_sigma_px", tie_sigma_px},
      {"line_loss_scale", line_loss_scale},
      {"line_discrepancy_bin_s", line_discrepancy_bin_s},
      {"boresight_sigma_rad", boresight_sigma_rad},
      {"lever_arm_sigma_m", lever_arm_sigma_m},
      {"vertical_slip_sigma_rad", vertical_slip_sigma_rad},
      {"vehicle_motion_rate_hz", vehicle_motion_rate_hz},
      {"vehicle_motion_correlation_s", vehicle_motion_correlation_s},
      {"vehicle_motion_half_chord_s", vehicle_motion_half_chord_s},
      {"vehicle_misalignment_sigma_rad", vehicle_misalignment_sigma_rad},
      {"lines_only_misalignment_sigma_rad", lines_only_misalignment_sigma_rad},
      {"axle_offset_sigma_m", axle_offset_sigma_m},
      {"vehicle_motion_loss_scale", vehicle_motion_loss_scale},
  };
  for (const Positive& p : positives) {
    if (!(p.value > 0.0) || !std::isfinite(p.value)) {
      return Violation(p.name, p.value, "must be finite and > 0");
    }
  }
  if (const std::string why = never_worse.Check(); !why.empty()) return why;
  if (const std::string why = sideways_switches.Check(); !why.empty()) {
    return "sideways_switches." + why;
  }
  if (!(sideslip_sigma_rad >= 0.0) || !std::isfinite(sideslip_sigma_rad)) {
    return Violation("sideslip_sigma_rad", sideslip_sigma_rad,
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
  if (!(max_position_sigma_m >= min_position_sigma_m) ||
      !std::isfinite(max_position_sigma_m)) {
    return Violation("max_position_sigma_m", max_position_sigma_m,
                     "must be finite and >= min_position_sigma_m");
  }
  if (!(max_attitude_sigma_rad >= min_attitude_sigma_rad) ||
      !std::isfinite(max_attitude_sigma_rad)) {
    return Violation("max_attitude_sigma_rad", max_attitude_sigma_rad,
                     "must be finite and >= min_attitude_sigma_rad");
  }
  if (min_crossings_for_tau < 2) {
    return Violation("min_crossings_for_tau", min_crossings_for_tau,
                     "must be >= 2");
  }
  if (line_discrepancy_min_points < 1) {
    return Violation("line_discrepancy_min_points", line_discrepancy_min_points,
                     "must be >= 1");
  }
  if (max_variance_iterations < 0) {
    return Violation("max_variance_iterations", max_variance_iterations,
                     "must be >= 0");
  }
  if (max_blunder_iterations < 0) {
    return Violation("max_blunder_iterations", max_blunder_iterations,
                     "must be >= 0");
  }
  if (!(reject_crossing_share > 0.0 && reject_crossing_share <= 1.0)) {
    return Violation("reject_crossing_share", reject_crossing_share,
                     "must be in (0, 1]");
  }
  if (!(attitude_significance >= 0.0) ||
      !std::isfinite(attitude_significance)) {
    return Violation("attitude_significance", attitude_significance,
                     "must be finite and >= 0 (0 disables)");
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

}  // namespace zebrageo
