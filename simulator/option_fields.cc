// SimulationOptions' field table: `--set key=value` (SetOption), the
// option names and values, and the options in truth/meta.json.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

#include "simulator/options_json.h"
#include "simulator/simulator.h"
#include "survey/csv.h"

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
      ZEBRAGEO_SIM_FIELD(ladder_probability),
      ZEBRAGEO_SIM_FIELD(min_ladder_bar_width_m),
      ZEBRAGEO_SIM_FIELD(max_ladder_bar_width_m),
      ZEBRAGEO_SIM_FIELD(band_sizes_per_crossing),
      ZEBRAGEO_SIM_FIELD(min_band_width_m),
      ZEBRAGEO_SIM_FIELD(max_band_width_m),
      ZEBRAGEO_SIM_FIELD(min_band_gap_m),
      ZEBRAGEO_SIM_FIELD(max_band_gap_m),
      ZEBRAGEO_SIM_FIELD(min_band_length_m),
      ZEBRAGEO_SIM_FIELD(max_band_length_m),
      ZEBRAGEO_SIM_FIELD(skew_probability),
      ZEBRAGEO_SIM_FIELD(max_skew_deg),
      ZEBRAGEO_SIM_FIELD(paint_wear),
      ZEBRAGEO_SIM_FIELD(missing_paint_probability),
      ZEBRAGEO_SIM_FIELD(stop_line_probability),
      ZEBRAGEO_SIM_FIELD(num_junctions),
      ZEBRAGEO_SIM_FIELD(four_way_probability),
      ZEBRAGEO_SIM_FIELD(junction_max_angle_deg),
      ZEBRAGEO_SIM_FIELD(min_side_street_width_m),
      ZEBRAGEO_SIM_FIELD(max_side_street_width_m),
      ZEBRAGEO_SIM_FIELD(side_crossing_probability),
      ZEBRAGEO_SIM_FIELD(min_side_crossing_setback_m),
      ZEBRAGEO_SIM_FIELD(max_side_crossing_setback_m),
      ZEBRAGEO_SIM_FIELD(side_crossing_vehicle_probability),
      ZEBRAGEO_SIM_FIELD(median_width_m),
      ZEBRAGEO_SIM_FIELD(split_crossing_probability),
      ZEBRAGEO_SIM_FIELD(max_stagger_m),
      ZEBRAGEO_SIM_FIELD(lanes_per_direction),
      ZEBRAGEO_SIM_FIELD(num_lane_changes),
      ZEBRAGEO_SIM_FIELD(bike_squares_probability),
      ZEBRAGEO_SIM_FIELD(two_square_rows_probability),
      ZEBRAGEO_SIM_FIELD(bike_lane_probability),
      ZEBRAGEO_SIM_FIELD(square_size_m),
      ZEBRAGEO_SIM_FIELD(square_column_probability),
      ZEBRAGEO_SIM_FIELD(give_way_teeth_probability),
      ZEBRAGEO_SIM_FIELD(min_stop_line_distance_m),
      ZEBRAGEO_SIM_FIELD(max_stop_line_distance_m),
      ZEBRAGEO_SIM_FIELD(truck_probability),
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
      ZEBRAGEO_SIM_FIELD(gnss_return_decay_s),
      ZEBRAGEO_SIM_FIELD(outage_ins_drift),
      ZEBRAGEO_SIM_FIELD(outage_heading_drift_deg),
      ZEBRAGEO_SIM_FIELD(outage_sd_growth_m),
      ZEBRAGEO_SIM_FIELD(outage_clear_after_m),
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

}  // namespace

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
