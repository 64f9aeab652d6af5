// SimulationOptions: the field table (--set, truth/meta.json), Check(),
// the presets.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <variant>

#include "simulator/options_json.h"
#include "simulator/simulator.h"
#include "survey/csv.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

// ------------------------------------------------------------ field table
using FieldPointer =
    std::variant<double SimulationOptions::*, int SimulationOptions::*,
                 bool SimulationOptions::*, uint64_t SimulationOptions::*,
                 std::string SimulationOptions::*,
                 PixelDepth SimulationOptions::*>;

struct Field {
  const char* name;
  FieldPointer pointer;
};

#define ZEBRAGEO_SIM_FIELD(name) \
  Field { #name, &SimulationOptions::name }

// Every field of SimulationOptions, in declaration order. A test checks that
// SetOption reaches each of them.
const std::vector<Field>& Fields() {
  static const std::vector<Field> fields = {
      ZEBRAGEO_SIM_FIELD(preset),
      ZEBRAGEO_SIM_FIELD(scenario),
      ZEBRAGEO_SIM_FIELD(seed),
      ZEBRAGEO_SIM_FIELD(origin_lat_deg),
      ZEBRAGEO_SIM_FIELD(origin_lon_deg),
      ZEBRAGEO_SIM_FIELD(origin_h_m),
      ZEBRAGEO_SIM_FIELD(start_heading_deg),
      ZEBRAGEO_SIM_FIELD(road_length_m),
      ZEBRAGEO_SIM_FIELD(road_width_m),
      ZEBRAGEO_SIM_FIELD(crossfall),
      ZEBRAGEO_SIM_FIELD(crown_rounding_m),
      ZEBRAGEO_SIM_FIELD(sidewalk_width_m),
      ZEBRAGEO_SIM_FIELD(max_grade),
      ZEBRAGEO_SIM_FIELD(grade_wavelength_m),
      ZEBRAGEO_SIM_FIELD(curved_share),
      ZEBRAGEO_SIM_FIELD(min_curve_radius_m),
      ZEBRAGEO_SIM_FIELD(max_curve_radius_m),
      ZEBRAGEO_SIM_FIELD(transition_length_m),
      ZEBRAGEO_SIM_FIELD(num_crossings),
      ZEBRAGEO_SIM_FIELD(min_crossing_spacing_m),
      ZEBRAGEO_SIM_FIELD(min_bands_per_crossing),
      ZEBRAGEO_SIM_FIELD(max_bands_per_crossing),
      ZEBRAGEO_SIM_FIELD(band_width_m),
      ZEBRAGEO_SIM_FIELD(band_gap_m),
      ZEBRAGEO_SIM_FIELD(min_band_length_m),
      ZEBRAGEO_SIM_FIELD(max_band_length_m),
      ZEBRAGEO_SIM_FIELD(skew_probability),
      ZEBRAGEO_SIM_FIELD(max_skew_deg),
      ZEBRAGEO_SIM_FIELD(paint_wear),
      ZEBRAGEO_SIM_FIELD(missing_paint_probability),
      ZEBRAGEO_SIM_FIELD(stop_line_probability),
      ZEBRAGEO_SIM_FIELD(lane_lines),
      ZEBRAGEO_SIM_FIELD(lane_line_width_m),
      ZEBRAGEO_SIM_FIELD(dash_length_m),
      ZEBRAGEO_SIM_FIELD(dash_gap_m),
      ZEBRAGEO_SIM_FIELD(stains_per_100m),
      ZEBRAGEO_SIM_FIELD(manholes_per_100m),
      ZEBRAGEO_SIM_FIELD(facades),
      ZEBRAGEO_SIM_FIELD(window_period_m),
      ZEBRAGEO_SIM_FIELD(facade_gap_probability),
      ZEBRAGEO_SIM_FIELD(parked_vehicles_per_100m),
      ZEBRAGEO_SIM_FIELD(occluding_vehicle_probability),
      ZEBRAGEO_SIM_FIELD(end_band_vehicle_probability),
      ZEBRAGEO_SIM_FIELD(shadows),
      ZEBRAGEO_SIM_FIELD(sun_elevation_deg),
      ZEBRAGEO_SIM_FIELD(sun_azimuth_deg),
      ZEBRAGEO_SIM_FIELD(vehicle_speed_mps),
      ZEBRAGEO_SIM_FIELD(speed_variation),
      ZEBRAGEO_SIM_FIELD(exposure_spacing_m),
      ZEBRAGEO_SIM_FIELD(exposure_spacing_jitter_m),
      ZEBRAGEO_SIM_FIELD(imu_height_m),
      ZEBRAGEO_SIM_FIELD(suspension_roll_deg),
      ZEBRAGEO_SIM_FIELD(suspension_pitch_deg),
      ZEBRAGEO_SIM_FIELD(suspension_frequency_hz),
      ZEBRAGEO_SIM_FIELD(trajectory_rate_hz),
      ZEBRAGEO_SIM_FIELD(start_time_s),
      ZEBRAGEO_SIM_FIELD(stereo_baseline_m),
      ZEBRAGEO_SIM_FIELD(camera_height_m),
      ZEBRAGEO_SIM_FIELD(camera_forward_m),
      ZEBRAGEO_SIM_FIELD(camera_pitch_down_deg),
      ZEBRAGEO_SIM_FIELD(rear_pair),
      ZEBRAGEO_SIM_FIELD(rear_camera_back_m),
      ZEBRAGEO_SIM_FIELD(camera_misalignment_deg),
      ZEBRAGEO_SIM_FIELD(image_width),
      ZEBRAGEO_SIM_FIELD(image_height),
      ZEBRAGEO_SIM_FIELD(focal_px),
      ZEBRAGEO_SIM_FIELD(k1),
      ZEBRAGEO_SIM_FIELD(k2),
      ZEBRAGEO_SIM_FIELD(p1),
      ZEBRAGEO_SIM_FIELD(p2),
      ZEBRAGEO_SIM_FIELD(k3),
      ZEBRAGEO_SIM_FIELD(noise_sigma),
      ZEBRAGEO_SIM_FIELD(shot_noise),
      ZEBRAGEO_SIM_FIELD(blur_sigma_px),
      ZEBRAGEO_SIM_FIELD(vignetting),
      ZEBRAGEO_SIM_FIELD(gain_variation),
      ZEBRAGEO_SIM_FIELD(pixel_depth),
      ZEBRAGEO_SIM_FIELD(supersampling),
      ZEBRAGEO_SIM_FIELD(render_images),
      ZEBRAGEO_SIM_FIELD(threads),
      ZEBRAGEO_SIM_FIELD(drift_along_track_m),
      ZEBRAGEO_SIM_FIELD(drift_cross_track_m),
      ZEBRAGEO_SIM_FIELD(drift_vertical_m),
      ZEBRAGEO_SIM_FIELD(drift_bias_share),
      ZEBRAGEO_SIM_FIELD(drift_period_s),
      ZEBRAGEO_SIM_FIELD(heading_drift_deg),
      ZEBRAGEO_SIM_FIELD(tilt_drift_deg),
      ZEBRAGEO_SIM_FIELD(outage_start_s),
      ZEBRAGEO_SIM_FIELD(outage_duration_s),
      ZEBRAGEO_SIM_FIELD(outage_drift_m),
      ZEBRAGEO_SIM_FIELD(gnss_return_jump_m),
      ZEBRAGEO_SIM_FIELD(num_multipath_switches),
      ZEBRAGEO_SIM_FIELD(multipath_jump_m),
      ZEBRAGEO_SIM_FIELD(multipath_switch_length_m),
      ZEBRAGEO_SIM_FIELD(jitter_direction_deg),
      ZEBRAGEO_SIM_FIELD(jitter_correlation_s),
      ZEBRAGEO_SIM_FIELD(reported_sd_horizontal_m),
      ZEBRAGEO_SIM_FIELD(reported_sd_vertical_m),
      ZEBRAGEO_SIM_FIELD(reported_sd_tilt_deg),
      ZEBRAGEO_SIM_FIELD(reported_sd_heading_deg),
      ZEBRAGEO_SIM_FIELD(database_sigma_xy_m),
      ZEBRAGEO_SIM_FIELD(database_sigma_z_m),
      ZEBRAGEO_SIM_FIELD(database_min_offset_m),
      ZEBRAGEO_SIM_FIELD(database_max_offset_m),
      ZEBRAGEO_SIM_FIELD(num_missing_crossings),
      ZEBRAGEO_SIM_FIELD(num_stale_crossings),
      ZEBRAGEO_SIM_FIELD(num_missing_bands),
      ZEBRAGEO_SIM_FIELD(num_repainted_crossings),
      ZEBRAGEO_SIM_FIELD(repaint_shift_m),
      ZEBRAGEO_SIM_FIELD(num_missing_end_bands),
      ZEBRAGEO_SIM_FIELD(num_missing_interior_bands),
      ZEBRAGEO_SIM_FIELD(database_line_gap_share),
      ZEBRAGEO_SIM_FIELD(num_moved_lines),
      ZEBRAGEO_SIM_FIELD(num_removed_stop_lines),
  };
  return fields;
}
#undef ZEBRAGEO_SIM_FIELD

std::string FormatValue(const SimulationOptions& options,
                        const FieldPointer& pointer) {
  return std::visit(
      [&options](auto member) -> std::string {
        const auto& value = options.*member;
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, double>) {
          return FormatDouble(value);
        } else if constexpr (std::is_same_v<T, bool>) {
          return value ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return value;
        } else if constexpr (std::is_same_v<T, PixelDepth>) {
          return value == PixelDepth::kUint16 ? "16" : "8";
        } else {
          return std::to_string(value);
        }
      },
      pointer);
}

nlohmann::json JsonValue(const SimulationOptions& options,
                         const FieldPointer& pointer) {
  return std::visit(
      [&options](auto member) -> nlohmann::json {
        const auto& value = options.*member;
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<T, PixelDepth>) {
          return value == PixelDepth::kUint16 ? 16 : 8;
        } else {
          return value;
        }
      },
      pointer);
}

// Parses `text` into the field; "" or the reason it does not parse.
std::string ParseValue(const std::string& text, const FieldPointer& pointer,
                       SimulationOptions* options) {
  return std::visit(
      [&](auto member) -> std::string {
        auto& value = options->*member;
        using T = std::decay_t<decltype(value)>;
        const char* begin = text.c_str();
        char* end = nullptr;
        errno = 0;
        if constexpr (std::is_same_v<T, double>) {
          const double parsed = std::strtod(begin, &end);
          if (text.empty() || *end != '\0' || !std::isfinite(parsed)) {
            return "\"" + text + "\" is not a finite number";
          }
          value = parsed;
        } else if constexpr (std::is_same_v<T, int>) {
          const long parsed = std::strtol(begin, &end, 10);
          if (text.empty() || *end != '\0' || errno == ERANGE ||
              parsed < std::numeric_limits<int>::min() ||
              parsed > std::numeric_limits<int>::max()) {
            return "\"" + text + "\" is not an integer";
          }
          value = static_cast<int>(parsed);
        } else if constexpr (std::is_same_v<T, uint64_t>) {
          const unsigned long long parsed = std::strtoull(begin, &end, 10);
          if (text.empty() || *end != '\0' || errno == ERANGE ||
              text[0] == '-') {
            return "\"" + text + "\" is not a non-negative integer";
          }
          value = parsed;
        } else if constexpr (std::is_same_v<T, bool>) {
          if (text == "true" || text == "1" || text == "yes" || text == "on") {
            value = true;
          } else if (text == "false" || text == "0" || text == "no" ||
                     text == "off") {
            value = false;
          } else {
            return "\"" + text + "\" is not a boolean (true or false)";
          }
        } else if constexpr (std::is_same_v<T, PixelDepth>) {
          if (text == "8") {
            value = PixelDepth::kUint8;
          } else if (text == "16") {
            value = PixelDepth::kUint16;
          } else {
            return "\"" + text + "\" is not a pixel depth (8 or 16)";
          }
        } else {
          value = text;
        }
        return "";
      },
      pointer);
}

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

}  // namespace

// ------------------------------------------------------------ options
std::string SimulationOptions::Check() const {
  Checker c;
  c.Range("origin_lat_deg", origin_lat_deg, -89.0, 89.0);
  c.Range("origin_lon_deg", origin_lon_deg, -180.0, 180.0);
  c.Range("origin_h_m", origin_h_m, -1000.0, 10000.0);
  c.Range("start_heading_deg", start_heading_deg, -360.0, 360.0);
  c.Range("road_length_m", road_length_m, 30.0, 200000.0);
  c.Range("road_width_m", road_width_m, 6.5, 20.0);
  c.Range("crossfall", crossfall, 0.0, 0.08);
  c.Range("crown_rounding_m", crown_rounding_m, 0.01, 2.0);
  c.Range("sidewalk_width_m", sidewalk_width_m, 2.0, 10.0);
  c.Range("max_grade", max_grade, 0.0, 0.12);
  c.Range("grade_wavelength_m", grade_wavelength_m, 50.0, 1e6);
  c.Range("curved_share", curved_share, 0.0, 1.0);
  c.Range("min_curve_radius_m", min_curve_radius_m, 60.0, 1e5);
  c.Range("max_curve_radius_m", max_curve_radius_m, min_curve_radius_m, 1e5);
  c.Range("transition_length_m", transition_length_m, 0.0, 200.0);
  c.Range("num_crossings", num_crossings, 0, 100000);
  c.Range("min_crossing_spacing_m", min_crossing_spacing_m, 15.0, 1e5);
  c.Range("min_bands_per_crossing", min_bands_per_crossing, 2, 40);
  c.Range("max_bands_per_crossing", max_bands_per_crossing,
          min_bands_per_crossing, 40);
  c.Range("band_width_m", band_width_m, 0.2, 1.0);
  c.Range("band_gap_m", band_gap_m, 0.2, 1.5);
  c.Range("min_band_length_m", min_band_length_m, 1.0, 10.0);
  c.Range("max_band_length_m", max_band_length_m, min_band_length_m, 10.0);
  c.Range("skew_probability", skew_probability, 0.0, 1.0);
  c.Range("max_skew_deg", max_skew_deg, 0.0, 45.0);
  c.Range("paint_wear", paint_wear, 0.0, 1.0);
  c.Range("missing_paint_probability", missing_paint_probability, 0.0, 1.0);
  c.Range("stop_line_probability", stop_line_probability, 0.0, 1.0);
  c.Range("lane_line_width_m", lane_line_width_m, 0.05, 0.5);
  c.Range("dash_length_m", dash_length_m, 0.5, 50.0);
  c.Range("dash_gap_m", dash_gap_m, 0.5, 50.0);
  c.Range("stains_per_100m", stains_per_100m, 0.0, 100.0);
  c.Range("manholes_per_100m", manholes_per_100m, 0.0, 50.0);
  c.Range("window_period_m", window_period_m, 1.5, 10.0);
  c.Range("facade_gap_probability", facade_gap_probability, 0.0, 1.0);
  c.Range("parked_vehicles_per_100m", parked_vehicles_per_100m, 0.0, 20.0);
  c.Range("occluding_vehicle_probability", occluding_vehicle_probability, 0.0,
          1.0);
  c.Range("end_band_vehicle_probability", end_band_vehicle_probability, 0.0,
          1.0);
  c.Range("sun_elevation_deg", sun_elevation_deg, 5.0, 90.0);
  c.Range("sun_azimuth_deg", sun_azimuth_deg, -360.0, 360.0);
  c.Range("vehicle_speed_mps", vehicle_speed_mps, 1.0, 40.0);
  c.Range("speed_variation", speed_variation, 0.0, 0.5);
  c.Range("exposure_spacing_m", exposure_spacing_m, 0.5, 20.0);
  c.Range("exposure_spacing_jitter_m", exposure_spacing_jitter_m, 0.0,
          0.45 * exposure_spacing_m);
  c.Range("imu_height_m", imu_height_m, 0.3, 2.5);
  c.Range("suspension_roll_deg", suspension_roll_deg, 0.0, 3.0);
  c.Range("suspension_pitch_deg", suspension_pitch_deg, 0.0, 3.0);
  c.Range("suspension_frequency_hz", suspension_frequency_hz, 0.1, 10.0);
  c.Range("trajectory_rate_hz", trajectory_rate_hz, 10.0, 400.0);
  c.Range("start_time_s", start_time_s, 0.0, 1e9);
  c.Range("stereo_baseline_m", stereo_baseline_m, 0.1, 3.0);
  c.Range("camera_height_m", camera_height_m, imu_height_m + 0.2, 5.0);
  c.Range("camera_forward_m", camera_forward_m, -3.0, 3.0);
  c.Range("camera_pitch_down_deg", camera_pitch_down_deg, 0.0, 60.0);
  c.Range("rear_camera_back_m", rear_camera_back_m, 0.0, 5.0);
  c.Range("camera_misalignment_deg", camera_misalignment_deg, 0.0, 3.0);
  c.Range("image_width", image_width, 64, 8192);
  c.Range("image_height", image_height, 64, 8192);
  c.Range("focal_px", focal_px, 50.0, 20000.0);
  c.Range("k1", k1, -1.0, 1.0);
  c.Range("k2", k2, -1.0, 1.0);
  c.Range("p1", p1, -0.05, 0.05);
  c.Range("p2", p2, -0.05, 0.05);
  c.Range("k3", k3, -1.0, 1.0);
  c.Range("noise_sigma", noise_sigma, 0.0, 50.0);
  c.Range("shot_noise", shot_noise, 0.0, 10.0);
  c.Range("blur_sigma_px", blur_sigma_px, 0.0, 5.0);
  c.Range("vignetting", vignetting, 0.0, 0.9);
  c.Range("gain_variation", gain_variation, 0.0, 0.5);
  c.Range("supersampling", supersampling, 1, 16);
  c.Range("threads", threads, 0, 1024);
  c.Range("drift_along_track_m", drift_along_track_m, 0.0, 100.0);
  c.Range("drift_cross_track_m", drift_cross_track_m, 0.0, 100.0);
  c.Range("drift_vertical_m", drift_vertical_m, 0.0, 100.0);
  c.Range("drift_bias_share", drift_bias_share, 0.0, 1.0);
  c.Range("drift_period_s", drift_period_s, 1.0, 1e6);
  c.Range("heading_drift_deg", heading_drift_deg, 0.0, 10.0);
  c.Range("tilt_drift_deg", tilt_drift_deg, 0.0, 10.0);
  c.Range("outage_start_s", outage_start_s, 0.0, 1e6);
  c.Range("outage_duration_s", outage_duration_s, 0.0, 1e6);
  c.Range("outage_drift_m", outage_drift_m, 0.0, 1000.0);
  c.Range("gnss_return_jump_m", gnss_return_jump_m, 0.0, 100.0);
  c.Range("num_multipath_switches", num_multipath_switches, 0, 100000);
  c.Range("multipath_jump_m", multipath_jump_m, 0.0, 20.0);
  c.Range("multipath_switch_length_m", multipath_switch_length_m, 1.0, 1000.0);
  c.Range("jitter_direction_deg", jitter_direction_deg, 0.0, 30.0);
  c.Range("jitter_correlation_s", jitter_correlation_s, 0.01, 1000.0);
  c.Range("reported_sd_horizontal_m", reported_sd_horizontal_m, 0.0, 100.0);
  c.Range("reported_sd_vertical_m", reported_sd_vertical_m, 0.0, 100.0);
  c.Range("reported_sd_tilt_deg", reported_sd_tilt_deg, 0.0, 10.0);
  c.Range("reported_sd_heading_deg", reported_sd_heading_deg, 0.0, 10.0);
  c.Range("database_sigma_xy_m", database_sigma_xy_m, 0.0, 10.0);
  c.Range("database_sigma_z_m", database_sigma_z_m, 0.0, 10.0);
  c.Range("database_min_offset_m", database_min_offset_m, 0.0, 10.0);
  c.Range("database_max_offset_m", database_max_offset_m, database_min_offset_m,
          10.0);
  c.Range("num_missing_crossings", num_missing_crossings, 0, 100000);
  c.Range("num_stale_crossings", num_stale_crossings, 0, 100000);
  c.Range("num_missing_bands", num_missing_bands, 0, 100000);
  c.Range("num_repainted_crossings", num_repainted_crossings, 0, 100000);
  c.Range("repaint_shift_m", repaint_shift_m, 0.0, 2.0);
  c.Range("num_missing_end_bands", num_missing_end_bands, 0, 100000);
  c.Range("num_missing_interior_bands", num_missing_interior_bands, 0, 100000);
  c.Range("database_line_gap_share", database_line_gap_share, 0.0, 0.9);
  c.Range("num_moved_lines", num_moved_lines, 0, 100000);
  c.Range("num_removed_stop_lines", num_removed_stop_lines, 0, 100000);

  // Consistency between fields.
  const int faulty = num_missing_crossings + num_missing_bands +
                     num_repainted_crossings + num_missing_end_bands +
                     num_missing_interior_bands;
  c.Require(faulty <= num_crossings,
            "num_missing_crossings + num_missing_bands + "
            "num_repainted_crossings + num_missing_end_bands + "
            "num_missing_interior_bands = " +
                std::to_string(faulty) + ": must be <= num_crossings = " +
                std::to_string(num_crossings));
  const int positions = num_crossings + num_stale_crossings;
  if (positions > 0 && road_length_m >= 30.0 &&
      min_crossing_spacing_m >= 15.0) {
    const double needed = positions * min_crossing_spacing_m + 22.0;
    c.Require(road_length_m >= needed,
              "road_length_m = " + Fmt(road_length_m) + ": must be >= " +
                  Fmt(needed) + " for " + std::to_string(positions) +
                  " crossings (num_crossings + num_stale_crossings) " +
                  Fmt(min_crossing_spacing_m) +
                  " m apart (min_crossing_spacing_m)");
  }
  const double longest_crossing =
      max_band_length_m +
      road_width_m * std::tan(std::min(max_skew_deg, 45.0) * kPi / 180.0);
  c.Require(min_crossing_spacing_m >= longest_crossing + 6.0,
            "min_crossing_spacing_m = " + Fmt(min_crossing_spacing_m) +
                ": must be >= " + Fmt(RoundTo(longest_crossing + 6.0, 0.01)) +
                " (longest skewed crossing + 6 m) so crossings do not overlap");
  if (band_width_m > 0.0 && band_gap_m > 0.0) {
    const int fit = static_cast<int>(std::floor(
        (road_width_m - 0.5 + band_gap_m) / (band_width_m + band_gap_m)));
    c.Require(fit >= 2, "road_width_m = " + Fmt(road_width_m) +
                            ": must fit at least 2 bands of band_width_m + "
                            "band_gap_m");
  }
  if (num_missing_interior_bands > 0) {
    c.Require(
        min_bands_per_crossing >= 3,
        "min_bands_per_crossing = " + std::to_string(min_bands_per_crossing) +
            ": must be >= 3 when num_missing_interior_bands > 0");
  }
  if (num_missing_bands > 0) {
    c.Require(
        min_bands_per_crossing >= 3,
        "min_bands_per_crossing = " + std::to_string(min_bands_per_crossing) +
            ": must be >= 3 when num_missing_bands > 0");
  }
  if (image_width >= 64 && image_height >= 64 && focal_px >= 50.0) {
    // Largest distorted radius of the image (right camera: +3 % distortion,
    // principal point +-8 px) must be reached before the model folds.
    const double half_diagonal =
        std::hypot(0.5 * image_width + 10.0, 0.5 * image_height + 10.0);
    const double r_max = 1.05 * half_diagonal / (0.995 * focal_px);
    bool ok = true;
    for (double scale : {0.97, 1.03}) {
      ok &=
          RadialDistortionMonotonic(scale * k1, scale * k2, scale * k3, r_max);
    }
    c.Require(ok, "k1 = " + Fmt(k1) + ", k2 = " + Fmt(k2) +
                      ", k3 = " + Fmt(k3) +
                      ": the radial distortion folds inside the image "
                      "(r (1 + k1 r^2 + k2 r^4 + k3 r^6) must increase up to "
                      "the image corners)");
  }
  if (outage_duration_s > 0.0) {
    c.Require(drift_period_s >= 1.0, "drift_period_s: must be >= 1");
  }
  return c.Result();
}

std::vector<std::string> PresetNames() {
  return {"demo", "urban", "outage", "sparse", "ambiguity", "large", "random"};
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

std::string SetOption(const std::string& key_equals_value,
                      SimulationOptions* options) {
  const size_t equals = key_equals_value.find('=');
  if (equals == std::string::npos) {
    return "\"" + key_equals_value + "\": expected key=value";
  }
  const std::string key = key_equals_value.substr(0, equals);
  const std::string value = key_equals_value.substr(equals + 1);
  for (const Field& field : Fields()) {
    if (key != field.name) continue;
    const std::string error = ParseValue(value, field.pointer, options);
    return error.empty() ? "" : key + ": " + error;
  }
  std::string names;
  for (const Field& field : Fields()) {
    names += (names.empty() ? "" : ", ") + std::string(field.name);
  }
  return "unknown option \"" + key + "\" (known: " + names + ")";
}

std::vector<std::string> OptionNames() {
  std::vector<std::string> names;
  for (const Field& field : Fields()) names.push_back(field.name);
  return names;
}

std::map<std::string, std::string> OptionValues(
    const SimulationOptions& options) {
  std::map<std::string, std::string> values;
  for (const Field& field : Fields()) {
    values[field.name] = FormatValue(options, field.pointer);
  }
  return values;
}

nlohmann::json OptionsToJson(const SimulationOptions& options) {
  nlohmann::json json = nlohmann::json::object();
  for (const Field& field : Fields()) {
    json[field.name] = JsonValue(options, field.pointer);
  }
  return json;
}

}  // namespace zebrageo
