// adjustment.json and report.json of a results folder (SURVEY_FORMAT.md
// "Outputs"): the adjustment's figures as a typed record, one reader and one
// writer, like survey/results.h. The adjustment writes adjustment.json; the
// second registration pass reads it (is there a posterior covariance, how
// many crossings); the report embeds it in report.json as "adjustment".
// Units as the keys say (_m metres, _s seconds, _deg degrees, _px pixels);
// vectors along-track, cross-track, up where the key says "model".
#ifndef ZEBRAGEO_SURVEY_RESULTS_ADJUSTMENT_H_
#define ZEBRAGEO_SURVEY_RESULTS_ADJUSTMENT_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace zebrageo {

inline constexpr char kAdjustmentJsonFile[] = "adjustment.json";

struct AdjustmentRecord {
  bool usable = false;
  std::string message;
  double sigma0 = 0.0;
  int iterations = 0;
  int solves = 0;
  double time_s = 0.0;
  struct Counts {
    int exposures = 0;
    int64_t trajectory_samples = 0;
    int knots = 0;
    int control_vertices = 0;
    int check_vertices = 0;
    int rejected_vertices = 0;
    int control_crossings = 0;
    int check_crossings = 0;
    int tie_tracks = 0;
    int residuals = 0;
    int64_t reconstructed_vertices = 0;
    int64_t matches = 0;
  } counts;
  struct Rms {
    std::string unit;
    int count = 0;
    double before = 0.0;
    double after = 0.0;
  };
  std::map<std::string, Rms> rms;  // by observation type
  double control_rmse_horizontal_m = 0.0;
  double control_rmse_vertical_m = 0.0;
  // Check points (held out). The RMSE figures are written as null when no
  // check point was evaluated (evaluated_vertices == 0).
  struct Check {
    double rmse_horizontal_m = 0.0;
    double rmse_vertical_m = 0.0;
    int vertices = 0;
    int evaluated_vertices = 0;
    double database_rms_horizontal_m = 0.0;  // expected_from_database
    double database_rms_vertical_m = 0.0;
    double implied_trajectory_horizontal_m = 0.0;
    double implied_trajectory_vertical_m = 0.0;
    int crossings = 0;
    bool held_out_then_control = false;
  } check;
  double max_correction_horizontal_m = 0.0;
  double max_correction_vertical_m = 0.0;
  double rms_correction_horizontal_m = 0.0;
  // No zebra crossing was control: road lines alone corrected the
  // trajectory (across them and in height; along-track is the input's).
  bool road_lines_only = false;
  bool posterior_sd_computed = false;
  double median_posterior_sd_horizontal_m = 0.0;
  double median_posterior_sd_vertical_m = 0.0;
  // Stretches where one axis of the position (axis "along_track",
  // "cross_track" or "up") is held by no control: its posterior sd above
  // threshold_m, or no control holding it near, over length_m of
  // trajectory (issue 51). Absent from older files.
  struct WeakStretch {
    std::string axis;
    double begin_time_s = 0.0;
    double end_time_s = 0.0;
    double length_m = 0.0;
    double threshold_m = 0.0;
    double max_sd_m = 0.0;  // NaN (null) without the posterior covariance
    double median_sd_m = 0.0;
    bool held_by_no_control = false;  // else the sd alone says it is weak
  };
  std::vector<WeakStretch> weakly_held;
  // Control vertices the blunder test removed.
  struct Rejected {
    std::string crossing_id;
    int band = 0;
    int vertex = 0;  // db_vertex
    double normalized_residual = 0.0;
    Eigen::Vector3d d_enu_m = Eigen::Vector3d::Zero();
  };
  std::vector<Rejected> rejected;
  struct RigCamera {
    std::string camera;
    Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
    double boresight_change_deg = 0.0;
  };
  std::vector<RigCamera> rig;
  struct Model {
    double knot_spacing_s = 0.0;
    bool position_model_estimated = false;
    Eigen::Vector3d position_sigma_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d position_tau_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d attitude_sigma_deg = Eigen::Vector3d::Zero();
    // Per attitude axis: its largest correction over its posterior sd,
    // and whether it was held at the input's for being below the
    // adjustment's threshold (AdjustmentOptions::attitude_significance).
    Eigen::Vector3d attitude_significance = Eigen::Vector3d::Zero();
    std::array<bool, 3> attitude_held{};
    Eigen::Vector2d vehicle_motion_sigma_deg = Eigen::Vector2d::Zero();
    double tie_sigma_px = 0.0;
    double vertex_sigma_px = 0.0;
    double crossing_offset_sigma_m = 0.0;
    double check_crossing_share = 0.0;
    double blunder_threshold = 0.0;
    bool self_calibrate_rig = false;
  } model;
  struct TiePoints {
    int images_read = 0;
    int images_missing = 0;
    int matches = 0;
    int tracks = 0;
    int observations = 0;
    double time_s = 0.0;
  };
  std::optional<TiePoints> tie_points;  // absent without tie points
  // Never worse than the input (issue 43): every matched crossing placed
  // with the input and with the adjusted trajectory, and the stretches
  // where the input was kept because the adjusted trajectory fitted the
  // matched crossings worse (times of the trajectory; the open end of a
  // stretch reaching the survey's start or end is NaN, written null).
  struct Guard {
    struct Crossing {
      std::string crossing_id;
      bool used = true;  // control or check; false: rejected
      double input_misfit_m = 0.0;
      double adjusted_misfit_m = 0.0;
      double z = 0.0;  // evidence that the adjusted is worse, in sd
      bool worse = false;
    };
    struct Stretch {
      double blend_begin_time_s = 0.0;
      double begin_time_s = 0.0;
      double end_time_s = 0.0;
      double blend_end_time_s = 0.0;
      std::vector<std::string> crossings;
      double input_misfit_m = 0.0;
      double adjusted_misfit_m = 0.0;
    };
    std::vector<Crossing> crossings;
    std::vector<Stretch> input_kept;
  } guard;
  std::vector<std::string> warnings;
};

// The file's JSON (also embedded in report.json as "adjustment").
nlohmann::json AdjustmentJson(const AdjustmentRecord& record);
void WriteAdjustmentRecord(const AdjustmentRecord& record,
                           const std::string& path);
// Throws InputError for malformed JSON or a missing or mistyped field.
AdjustmentRecord ReadAdjustmentRecord(const std::string& path,
                                      const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_ADJUSTMENT_H_
