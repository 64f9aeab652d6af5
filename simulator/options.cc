// SimulationOptions: Check() and the presets (the field table behind
// --set and truth/meta.json is in option_fields.cc).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "simulator/simulator.h"
#include "survey/csv.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

// ------------------------------------------------------------ Check helpers
class Checker {
 public:
  template <typename T>
  void Range(const char* name, T value, T lo, T hi) {
    if (!(value >= lo && value <= hi)) {
      std::ostringstream m;
      m << name << " = " << Text(value) << ": must be in [" << Text(lo) << ", "
        << Text(hi) << "]";
      Add(m.str());
    }
  }
  void Require(bool ok, const std::string& message) {
    if (!ok) Add(message);
  }
  std::string Result() const { return result_; }

 private:
  static std::string Text(double v) { return FormatDouble(v); }
  static std::string Text(int v) { return std::to_string(v); }
  void Add(const std::string& message) {
    result_ += (result_.empty() ? "" : "; ") + message;
  }
  std::string result_;
};

// False when r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6) stops increasing before
// it reaches `r_max` (the distortion folds inside the image).
bool RadialDistortionMonotonic(double k1, double k2, double k3, double r_max) {
  for (double r = 0.0; r < 3.0; r += 1e-3) {
    const double r2 = r * r;
    const double derivative =
        1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2 + 7.0 * k3 * r2 * r2 * r2;
    if (derivative <= 0.05) return false;
    if (r * (1.0 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2) >= r_max) {
      return true;
    }
  }
  return false;
}

std::string Fmt(double v) { return FormatDouble(v); }

double RoundTo(double value, double step) {
  return std::round(value / step) * step;
}

// The street, its marks and scenery.
void CheckStreetRanges(const SimulationOptions& o, Checker* c) {
  c->Range("origin_lat_deg", o.origin_lat_deg, -89.0, 89.0);
  c->Range("origin_lon_deg", o.origin_lon_deg, -180.0, 180.0);
  c->Range("origin_h_m", o.origin_h_m, -1000.0, 10000.0);
  c->Range("start_heading_deg", o.start_heading_deg, -360.0, 360.0);
  c->Range("road_length_m", o.road_length_m, 30.0, 200000.0);
  c->Range("road_width_m", o.road_width_m, 6.5, 26.0);
  c->Range("crossfall", o.crossfall, 0.0, 0.08);
  c->Range("crown_rounding_m", o.crown_rounding_m, 0.01, 2.0);
  c->Range("sidewalk_width_m", o.sidewalk_width_m, 2.0, 10.0);
  c->Range("max_grade", o.max_grade, 0.0, 0.12);
  c->Range("grade_wavelength_m", o.grade_wavelength_m, 50.0, 1e6);
  c->Range("curved_share", o.curved_share, 0.0, 1.0);
  c->Range("min_curve_radius_m", o.min_curve_radius_m, 60.0, 1e5);
  c->Range("max_curve_radius_m", o.max_curve_radius_m, o.min_curve_radius_m,
           1e5);
  c->Range("transition_length_m", o.transition_length_m, 0.0, 200.0);
  c->Range("num_crossings", o.num_crossings, 0, 100000);
  c->Range("min_crossing_spacing_m", o.min_crossing_spacing_m, 15.0, 1e5);
  c->Range("min_bands_per_crossing", o.min_bands_per_crossing, 2, 40);
  c->Range("max_bands_per_crossing", o.max_bands_per_crossing,
           o.min_bands_per_crossing, 40);
  c->Range("band_width_m", o.band_width_m, 0.2, 1.0);
  c->Range("band_gap_m", o.band_gap_m, 0.2, 1.5);
  c->Range("ladder_probability", o.ladder_probability, 0.0, 1.0);
  c->Range("min_ladder_bar_width_m", o.min_ladder_bar_width_m, 0.05, 1.0);
  c->Range("max_ladder_bar_width_m", o.max_ladder_bar_width_m,
           o.min_ladder_bar_width_m, 1.0);
  c->Range("min_band_width_m", o.min_band_width_m, 0.2, 1.0);
  c->Range("max_band_width_m", o.max_band_width_m, o.min_band_width_m, 1.0);
  c->Range("min_band_gap_m", o.min_band_gap_m, 0.2, 1.5);
  c->Range("max_band_gap_m", o.max_band_gap_m, o.min_band_gap_m, 1.5);
  if (o.band_sizes_per_crossing) {
    c->Require(o.road_width_m - 0.5 + o.max_band_gap_m >=
                   2.0 * (o.max_band_width_m + o.max_band_gap_m),
               "road_width_m = " + Fmt(o.road_width_m) +
                   ": must fit at least 2 bands of max_band_width_m + "
                   "max_band_gap_m");
  }
  c->Range("min_band_length_m", o.min_band_length_m, 1.0, 10.0);
  c->Range("max_band_length_m", o.max_band_length_m, o.min_band_length_m, 10.0);
  c->Range("skew_probability", o.skew_probability, 0.0, 1.0);
  c->Range("max_skew_deg", o.max_skew_deg, 0.0, 45.0);
  c->Range("paint_wear", o.paint_wear, 0.0, 1.0);
  c->Range("num_junctions", o.num_junctions, 0, 1000);
  c->Range("four_way_probability", o.four_way_probability, 0.0, 1.0);
  c->Range("junction_max_angle_deg", o.junction_max_angle_deg, 0.0, 45.0);
  c->Range("min_side_street_width_m", o.min_side_street_width_m, 4.0, 20.0);
  c->Range("max_side_street_width_m", o.max_side_street_width_m,
           o.min_side_street_width_m, 20.0);
  c->Range("side_crossing_probability", o.side_crossing_probability, 0.0, 1.0);
  c->Range("min_side_crossing_setback_m", o.min_side_crossing_setback_m, 0.0,
           30.0);
  c->Range("max_side_crossing_setback_m", o.max_side_crossing_setback_m,
           o.min_side_crossing_setback_m, 30.0);
  c->Range("side_crossing_vehicle_probability",
           o.side_crossing_vehicle_probability, 0.0, 1.0);
  c->Range("bike_squares_probability", o.bike_squares_probability, 0.0, 1.0);
  c->Range("two_square_rows_probability", o.two_square_rows_probability, 0.0,
           1.0);
  c->Range("bike_lane_probability", o.bike_lane_probability, 0.0, 1.0);
  c->Range("square_size_m", o.square_size_m, 0.2, 1.0);
  c->Range("square_column_probability", o.square_column_probability, 0.0, 1.0);
  c->Range("give_way_teeth_probability", o.give_way_teeth_probability, 0.0,
           1.0);
  c->Range("min_stop_line_distance_m", o.min_stop_line_distance_m, 0.5, 10.0);
  c->Range("max_stop_line_distance_m", o.max_stop_line_distance_m,
           o.min_stop_line_distance_m, 10.0);
  c->Range("truck_probability", o.truck_probability, 0.0, 1.0);
  c->Range("missing_paint_probability", o.missing_paint_probability, 0.0, 1.0);
  c->Range("stop_line_probability", o.stop_line_probability, 0.0, 1.0);
  c->Range("lane_line_width_m", o.lane_line_width_m, 0.05, 0.5);
  c->Range("dash_length_m", o.dash_length_m, 0.5, 50.0);
  c->Range("dash_gap_m", o.dash_gap_m, 0.5, 50.0);
  c->Range("stains_per_100m", o.stains_per_100m, 0.0, 100.0);
  c->Range("manholes_per_100m", o.manholes_per_100m, 0.0, 50.0);
  c->Range("window_period_m", o.window_period_m, 1.5, 10.0);
  c->Range("facade_gap_probability", o.facade_gap_probability, 0.0, 1.0);
  c->Range("parked_vehicles_per_100m", o.parked_vehicles_per_100m, 0.0, 20.0);
  c->Range("occluding_vehicle_probability", o.occluding_vehicle_probability,
           0.0, 1.0);
  c->Range("end_band_vehicle_probability", o.end_band_vehicle_probability, 0.0,
           1.0);
  c->Range("sun_elevation_deg", o.sun_elevation_deg, 5.0, 90.0);
  c->Range("sun_azimuth_deg", o.sun_azimuth_deg, -360.0, 360.0);
}

// The vehicle, its motion, the rig and the images.
void CheckVehicleAndCameraRanges(const SimulationOptions& o, Checker* c) {
  c->Range("vehicle_speed_mps", o.vehicle_speed_mps, 1.0, 40.0);
  c->Range("speed_variation", o.speed_variation, 0.0, 0.5);
  c->Range("exposure_spacing_m", o.exposure_spacing_m, 0.5, 20.0);
  c->Range("exposure_spacing_jitter_m", o.exposure_spacing_jitter_m, 0.0,
           0.45 * o.exposure_spacing_m);
  c->Range("imu_height_m", o.imu_height_m, 0.3, 2.5);
  c->Range("suspension_roll_deg", o.suspension_roll_deg, 0.0, 3.0);
  c->Range("suspension_pitch_deg", o.suspension_pitch_deg, 0.0, 3.0);
  c->Range("suspension_frequency_hz", o.suspension_frequency_hz, 0.1, 10.0);
  c->Range("trajectory_rate_hz", o.trajectory_rate_hz, 10.0, 400.0);
  c->Range("start_time_s", o.start_time_s, 0.0, 1e9);
  c->Range("stereo_baseline_m", o.stereo_baseline_m, 0.1, 3.0);
  c->Range("camera_height_m", o.camera_height_m, o.imu_height_m + 0.2, 5.0);
  c->Range("camera_forward_m", o.camera_forward_m, -3.0, 3.0);
  c->Range("camera_pitch_down_deg", o.camera_pitch_down_deg, 0.0, 60.0);
  c->Range("rear_camera_back_m", o.rear_camera_back_m, 0.0, 5.0);
  c->Range("camera_misalignment_deg", o.camera_misalignment_deg, 0.0, 3.0);
  c->Range("image_width", o.image_width, 64, 8192);
  c->Range("image_height", o.image_height, 64, 8192);
  c->Range("focal_px", o.focal_px, 50.0, 20000.0);
  c->Range("k1", o.k1, -1.0, 1.0);
  c->Range("k2", o.k2, -1.0, 1.0);
  c->Range("p1", o.p1, -0.05, 0.05);
  c->Range("p2", o.p2, -0.05, 0.05);
  c->Range("k3", o.k3, -1.0, 1.0);
  c->Range("noise_sigma", o.noise_sigma, 0.0, 50.0);
  c->Range("shot_noise", o.shot_noise, 0.0, 10.0);
  c->Range("blur_sigma_px", o.blur_sigma_px, 0.0, 5.0);
  c->Range("vignetting", o.vignetting, 0.0, 0.9);
  c->Range("gain_variation", o.gain_variation, 0.0, 0.5);
  c->Range("supersampling", o.supersampling, 1, 16);
  c->Range("threads", o.threads, 0, 1024);
}

// The GNSS/INS errors and the road-mark database's faults.
void CheckErrorAndDatabaseRanges(const SimulationOptions& o, Checker* c) {
  c->Range("drift_along_track_m", o.drift_along_track_m, 0.0, 100.0);
  c->Range("drift_cross_track_m", o.drift_cross_track_m, 0.0, 100.0);
  c->Range("drift_vertical_m", o.drift_vertical_m, 0.0, 100.0);
  c->Range("drift_bias_share", o.drift_bias_share, 0.0, 1.0);
  c->Range("drift_period_s", o.drift_period_s, 1.0, 1e6);
  c->Range("heading_drift_deg", o.heading_drift_deg, 0.0, 10.0);
  c->Range("tilt_drift_deg", o.tilt_drift_deg, 0.0, 10.0);
  c->Range("outage_start_s", o.outage_start_s, 0.0, 1e6);
  c->Range("outage_duration_s", o.outage_duration_s, 0.0, 1e6);
  c->Range("outage_drift_m", o.outage_drift_m, 0.0, 1000.0);
  c->Range("gnss_return_jump_m", o.gnss_return_jump_m, 0.0, 100.0);
  c->Range("gnss_return_decay_s", o.gnss_return_decay_s, 0.1, 1e6);
  c->Range("outage_heading_drift_deg", o.outage_heading_drift_deg, 0.0, 10.0);
  c->Range("outage_sd_growth_m", o.outage_sd_growth_m, 0.0, 100.0);
  c->Range("outage_clear_after_m", o.outage_clear_after_m, 0.0, 1e5);
  c->Range("num_multipath_switches", o.num_multipath_switches, 0, 100000);
  c->Range("multipath_jump_m", o.multipath_jump_m, 0.0, 20.0);
  c->Range("multipath_switch_length_m", o.multipath_switch_length_m, 1.0,
           1000.0);
  c->Range("jitter_direction_deg", o.jitter_direction_deg, 0.0, 30.0);
  c->Range("jitter_correlation_s", o.jitter_correlation_s, 0.01, 1000.0);
  c->Range("reported_sd_horizontal_m", o.reported_sd_horizontal_m, 0.0, 100.0);
  c->Range("reported_sd_vertical_m", o.reported_sd_vertical_m, 0.0, 100.0);
  c->Range("reported_sd_tilt_deg", o.reported_sd_tilt_deg, 0.0, 10.0);
  c->Range("reported_sd_heading_deg", o.reported_sd_heading_deg, 0.0, 10.0);
  c->Range("database_sigma_xy_m", o.database_sigma_xy_m, 0.0, 10.0);
  c->Range("database_sigma_z_m", o.database_sigma_z_m, 0.0, 10.0);
  c->Range("database_min_offset_m", o.database_min_offset_m, 0.0, 10.0);
  c->Range("database_max_offset_m", o.database_max_offset_m,
           o.database_min_offset_m, 10.0);
  c->Range("num_missing_crossings", o.num_missing_crossings, 0, 100000);
  c->Range("num_stale_crossings", o.num_stale_crossings, 0, 100000);
  c->Range("num_missing_bands", o.num_missing_bands, 0, 100000);
  c->Range("num_repainted_crossings", o.num_repainted_crossings, 0, 100000);
  c->Range("repaint_shift_m", o.repaint_shift_m, 0.0, 2.0);
  c->Range("num_missing_end_bands", o.num_missing_end_bands, 0, 100000);
  c->Range("num_missing_interior_bands", o.num_missing_interior_bands, 0,
           100000);
  c->Range("database_line_gap_share", o.database_line_gap_share, 0.0, 0.9);
  c->Range("num_moved_lines", o.num_moved_lines, 0, 100000);
  c->Range("num_removed_stop_lines", o.num_removed_stop_lines, 0, 100000);
}

// Consistency between fields.
void CheckConsistency(const SimulationOptions& o, Checker* c) {
  const int faulty = o.num_missing_crossings + o.num_missing_bands +
                     o.num_repainted_crossings + o.num_missing_end_bands +
                     o.num_missing_interior_bands;
  c->Require(faulty <= o.num_crossings,
             "num_missing_crossings + num_missing_bands + "
             "num_repainted_crossings + num_missing_end_bands + "
             "num_missing_interior_bands = " +
                 std::to_string(faulty) + ": must be <= num_crossings = " +
                 std::to_string(o.num_crossings));
  const int positions = o.num_crossings + o.num_stale_crossings;
  if (positions > 0 && o.road_length_m >= 30.0 &&
      o.min_crossing_spacing_m >= 15.0) {
    const double needed = positions * o.min_crossing_spacing_m + 22.0;
    c->Require(o.road_length_m >= needed,
               "road_length_m = " + Fmt(o.road_length_m) + ": must be >= " +
                   Fmt(needed) + " for " + std::to_string(positions) +
                   " crossings (num_crossings + num_stale_crossings) " +
                   Fmt(o.min_crossing_spacing_m) +
                   " m apart (min_crossing_spacing_m)");
  }
  const double longest_crossing =
      o.max_band_length_m +
      o.road_width_m * std::tan(std::min(o.max_skew_deg, 45.0) * kPi / 180.0);
  c->Require(
      o.min_crossing_spacing_m >= longest_crossing + 6.0,
      "min_crossing_spacing_m = " + Fmt(o.min_crossing_spacing_m) +
          ": must be >= " + Fmt(RoundTo(longest_crossing + 6.0, 0.01)) +
          " (longest skewed crossing + 6 m) so crossings do not overlap");
  if (o.band_width_m > 0.0 && o.band_gap_m > 0.0) {
    const int fit =
        static_cast<int>(std::floor((o.road_width_m - 0.5 + o.band_gap_m) /
                                    (o.band_width_m + o.band_gap_m)));
    c->Require(fit >= 2, "road_width_m = " + Fmt(o.road_width_m) +
                             ": must fit at least 2 bands of band_width_m + "
                             "band_gap_m");
  }
  if (o.num_missing_interior_bands > 0) {
    c->Require(
        o.min_bands_per_crossing >= 3,
        "min_bands_per_crossing = " + std::to_string(o.min_bands_per_crossing) +
            ": must be >= 3 when num_missing_interior_bands > 0");
  }
  if (o.num_missing_bands > 0) {
    c->Require(
        o.min_bands_per_crossing >= 3,
        "min_bands_per_crossing = " + std::to_string(o.min_bands_per_crossing) +
            ": must be >= 3 when num_missing_bands > 0");
  }
  if (o.image_width >= 64 && o.image_height >= 64 && o.focal_px >= 50.0) {
    // Largest distorted radius of the image (right camera: +3 % distortion,
    // principal point +-8 px) must be reached before the model folds.
    const double half_diagonal =
        std::hypot(0.5 * o.image_width + 10.0, 0.5 * o.image_height + 10.0);
    const double r_max = 1.05 * half_diagonal / (0.995 * o.focal_px);
    bool ok = true;
    for (double scale : {0.97, 1.03}) {
      ok &= RadialDistortionMonotonic(scale * o.k1, scale * o.k2, scale * o.k3,
                                      r_max);
    }
    c->Require(ok, "k1 = " + Fmt(o.k1) + ", k2 = " + Fmt(o.k2) +
                       ", k3 = " + Fmt(o.k3) +
                       ": the radial distortion folds inside the image "
                       "(r (1 + k1 r^2 + k2 r^4 + k3 r^6) must increase up to "
                       "the image corners)");
  }
  if (o.outage_duration_s > 0.0) {
    c->Require(o.drift_period_s >= 1.0, "drift_period_s: must be >= 1");
  }
  // Avenues (issue 52): each half of the road holds a lane of 2.5 m per
  // lane and at least 2 bands beside the island.
  c->Range("median_width_m", o.median_width_m, 0.0, 8.0);
  c->Range("split_crossing_probability", o.split_crossing_probability, 0.0,
           1.0);
  c->Range("max_stagger_m", o.max_stagger_m, 0.0, 10.0);
  c->Range("lanes_per_direction", o.lanes_per_direction, 1, 5);
  c->Range("num_lane_changes", o.num_lane_changes, 0, 20);
  // A plain street (no median, one lane each way) is held by road_width_m's
  // own range; the rule names the avenue's fields only where they are set.
  const bool avenue = o.median_width_m > 0.0 || o.lanes_per_direction > 1;
  const double carriageway = 0.5 * (o.road_width_m - o.median_width_m);
  c->Require(
      !avenue || (carriageway >= 2.5 * o.lanes_per_direction &&
                  carriageway >= 2.0 * (o.band_width_m + o.band_gap_m) + 0.5),
      "median_width_m = " + Fmt(o.median_width_m) +
          ": each side of it must hold lanes_per_direction lanes of "
          "2.5 m and 2 bands (road_width_m = " +
          Fmt(o.road_width_m) + ")");
}

}  // namespace

// ------------------------------------------------------------ options
std::string SimulationOptions::Check() const {
  Checker c;
  CheckStreetRanges(*this, &c);
  CheckVehicleAndCameraRanges(*this, &c);
  CheckErrorAndDatabaseRanges(*this, &c);
  CheckConsistency(*this, &c);
  return c.Result();
}

std::vector<std::string> PresetNames() {
  return {"demo",      "urban", "outage",    "long_outage", "sparse",
          "ambiguity", "large", "junctions", "avenue",      "random"};
}

std::string ApplyPreset(const std::string& name, SimulationOptions* options) {
  const uint64_t seed = options->seed;
  if (name == "random") {
    return DrawRandomOptions(seed, RandomPresetLimits(), options);
  }
  SimulationOptions o;
  o.seed = seed;
  o.preset = name;
  if (name == "demo") {
    o.road_length_m = 170.0;
    o.num_crossings = 3;
    o.num_stale_crossings = 1;
    o.min_crossing_spacing_m = 35.0;
    o.max_band_length_m = 4.5;
    o.exposure_spacing_m = 3.2;
    o.curved_share = 0.3;
    o.drift_along_track_m = 0.4;
    o.drift_cross_track_m = 0.4;
    o.drift_vertical_m = 0.15;
  } else if (name == "urban") {
    o.road_length_m = 1000.0;
    o.road_width_m = 10.0;
    o.num_crossings = 12;
    o.min_crossing_spacing_m = 50.0;
    o.num_stale_crossings = 1;
    o.num_missing_crossings = 1;
    o.num_missing_bands = 2;
    o.num_repainted_crossings = 1;
    o.curved_share = 0.5;
    o.min_curve_radius_m = 100.0;
    o.window_period_m = 2.8;
    o.parked_vehicles_per_100m = 5.0;
    o.occluding_vehicle_probability = 0.4;
    o.stains_per_100m = 6.0;
    o.drift_along_track_m = 1.4;
    o.drift_cross_track_m = 1.4;
    o.drift_vertical_m = 0.4;
    o.heading_drift_deg = 0.2;
    o.tilt_drift_deg = 0.04;
  } else if (name == "outage") {
    o.road_length_m = 1200.0;
    o.num_crossings = 10;
    o.min_crossing_spacing_m = 50.0;
    o.num_missing_crossings = 1;
    o.drift_along_track_m = 0.3;
    o.drift_cross_track_m = 0.3;
    o.drift_vertical_m = 0.1;
    o.outage_start_s = 30.0;
    o.outage_duration_s = 70.0;
    o.outage_drift_m = 3.0;
    o.gnss_return_jump_m = 0.3;
    o.heading_drift_deg = 0.15;
  } else if (name == "long_outage") {
    // The field's long outage (issue 43): its INS error grows to 3 m over
    // 360 m, the return steps 3 m, two crossings lie inside it and none
    // for 140 m after it; the solution's sd do not grow.
    o.road_length_m = 660.0;
    o.num_crossings = 5;
    o.num_stale_crossings = 0;
    o.min_crossing_spacing_m = 20.0;
    o.vehicle_speed_mps = 7.4;
    o.speed_variation = 0.1;
    o.drift_along_track_m = 0.5;
    o.drift_cross_track_m = 0.5;
    o.drift_vertical_m = 0.15;
    o.heading_drift_deg = 0.03;
    o.tilt_drift_deg = 0.02;
    o.outage_duration_s = 49.0;
    o.outage_drift_m = 3.0;
    o.outage_ins_drift = true;
    o.outage_heading_drift_deg = 0.1;
    o.outage_sd_growth_m = 0.0;
    o.outage_clear_after_m = 140.0;
    o.gnss_return_jump_m = 0.3;
    o.gnss_return_decay_s = 60.0;
  } else if (name == "sparse") {
    o.road_length_m = 1500.0;
    o.num_crossings = 4;
    o.num_stale_crossings = 0;
    o.min_crossing_spacing_m = 300.0;
    o.drift_along_track_m = 0.8;
    o.drift_cross_track_m = 0.8;
    o.drift_vertical_m = 0.25;
    o.heading_drift_deg = 0.15;
  } else if (name == "ambiguity") {
    o.road_length_m = 600.0;
    o.road_width_m = 9.0;
    o.num_crossings = 8;
    o.min_crossing_spacing_m = 45.0;
    o.skew_probability = 0.2;
    // About one band period (band_width_m + band_gap_m = 1 m) across the
    // road, i.e. along the bands' repetition direction, nearly constant.
    o.drift_cross_track_m = 1.0;
    o.drift_along_track_m = 0.15;
    o.drift_vertical_m = 0.1;
    o.drift_bias_share = 0.85;
  } else if (name == "junctions") {
    // Issue 51: a street of junctions, T and four-way, whose side-street
    // crossings hold the along-track position; the last control is one.
    o.road_length_m = 400.0;
    o.road_width_m = 9.0;
    o.num_crossings = 3;
    o.num_stale_crossings = 0;
    o.min_crossing_spacing_m = 40.0;
    o.num_junctions = 3;
    o.four_way_probability = 0.5;
    o.side_crossing_vehicle_probability = 0.3;
    o.drift_along_track_m = 0.8;
    o.drift_cross_track_m = 0.5;
    o.drift_vertical_m = 0.15;
    // A wide-angle rig (85 degrees across, the default lens's distortion as
    // a function of the pixel radius), as the random preset has with
    // junctions: the side streets' crossings whole in view within 15 m.
    const double focal = 0.5 * o.image_width / std::tan(DegToRad(42.5));
    const double scale2 = (focal / o.focal_px) * (focal / o.focal_px);
    o.k1 *= scale2;
    o.k2 *= scale2 * scale2;
    o.k3 *= scale2 * scale2 * scale2;
    o.focal_px = focal;
  } else if (name == "avenue") {
    // Issue 52: a 20 m avenue with a 2.5 m median whose refuge island
    // splits every crossing (half of them held as two crossings, staggered
    // up to 4 m), two lanes each way, the vehicle changing lanes twice.
    o.road_length_m = 400.0;
    o.road_width_m = 20.0;
    o.median_width_m = 2.5;
    o.split_crossing_probability = 0.5;
    o.max_stagger_m = 4.0;
    o.lanes_per_direction = 2;
    o.num_lane_changes = 2;
    o.num_crossings = 5;
    o.num_stale_crossings = 0;
    o.max_bands_per_crossing = 24;
    o.max_skew_deg = 15.0;
    o.min_crossing_spacing_m = 40.0;
    o.drift_along_track_m = 0.6;
    o.drift_cross_track_m = 0.6;
    o.drift_vertical_m = 0.15;
  } else if (name == "large") {
    o.road_length_m = 10000.0;
    o.num_crossings = 80;
    o.min_crossing_spacing_m = 60.0;
    o.num_stale_crossings = 3;
    o.num_missing_crossings = 3;
    o.num_missing_bands = 4;
    o.num_repainted_crossings = 2;
    o.drift_along_track_m = 1.0;
    o.drift_cross_track_m = 1.0;
    o.drift_vertical_m = 0.3;
    o.drift_period_s = 120.0;
    o.outage_start_s = 300.0;
    o.outage_duration_s = 60.0;
    o.outage_drift_m = 2.0;
    o.render_images = false;
  } else {
    std::string names;
    for (const std::string& n : PresetNames()) {
      names += (names.empty() ? "" : ", ") + n;
    }
    return "unknown preset \"" + name + "\" (known: " + names + ")";
  }
  *options = o;
  return "";
}

}  // namespace zebrageo
