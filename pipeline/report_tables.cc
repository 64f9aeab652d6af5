#include "pipeline/report_tables.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>
#include <vector>

#include "pipeline/svg_plot.h"
#include "survey/csv.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace report_internal {
namespace {

using nlohmann::json;

constexpr char kControlColour[] = "#1f77b4";
constexpr char kCheckColour[] = "#d62728";

std::string Cell(double value, int decimals) {
  if (!std::isfinite(value)) return "–";
  // -0.04 shown to 1 decimal is 0.0, not -0.0.
  const double unit = std::pow(10.0, -decimals);
  return FormatFixed(std::abs(value) < 0.5 * unit ? 0.0 : value, decimals);
}

// A row of <td>s (or <th>s).
std::string Row(const std::vector<std::string>& cells, bool header = false,
                const std::string& row_class = "") {
  std::string html =
      row_class.empty() ? "<tr>" : "<tr class='" + row_class + "'>";
  for (const std::string& cell : cells) {
    html += header ? "<th>" + cell + "</th>" : "<td>" + cell + "</td>";
  }
  return html + "</tr>\n";
}

const char* RoleName(const GcpResidual& r) {
  if (r.status == GcpStatus::kRejected) return "rejected";
  return r.role == GcpRole::kControl ? "control" : "check";
}

struct Spread {
  int count = 0;
  double rms = NAN, median = NAN, p95 = NAN, max = NAN;
};

Spread SpreadOf(const std::vector<double>& values) {
  Spread s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) return s;
  s.rms = Rms(values);
  s.median = Median(values);
  s.p95 = Percentile(values, 0.95);
  s.max = *std::max_element(values.begin(), values.end());
  return s;
}

// One bar chart of the observation types measured in `unit`, bars on a
// common scale with a labelled axis.
std::string RmsChart(
    const std::string& unit,
    const std::vector<std::tuple<std::string, double, double>>& rows) {
  constexpr int kRowPx = 44, kLabelPx = 230, kBarPx = 440, kWidthPx = 860;
  double largest = 1e-12;
  for (const auto& [type, before, after] : rows) {
    largest = std::max({largest, before, after});
  }
  // The axis ends at a round number: 4 ticks of 1, 2, 2.5 or 5 x 10^k.
  const double power = std::pow(10.0, std::floor(std::log10(largest / 4)));
  double step = 10.0 * power;
  for (double factor : {1.0, 2.0, 2.5, 5.0}) {
    if (4 * factor * power >= largest) {
      step = factor * power;
      break;
    }
  }
  const double top = 4 * step;
  // Decimals of the step (2.5 x 10^k needs one more than 10^k).
  const int decimals =
      std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)) +
                      (std::fmod(step / power + 1e-9, 1.0) > 0.1 ? 1 : 0));
  std::ostringstream bars;
  int n = 0;
  for (const auto& [type, before, after] : rows) {
    const int y = 40 + n++ * kRowPx;
    bars << "<text x='0' y='" << y + 16 << "'>" << EscapeHtml(HumanKey(type))
         << "</text>";
    int row = 0;
    for (const auto& [value, colour, name] :
         {std::tuple<double, const char*, const char*>{before, "#aaa",
                                                       "before"},
          {after, kControlColour, "after"}}) {
      const int bar_y = y + row++ * 18;
      const double w = std::max(1.0, kBarPx * value / top);
      bars << "<rect x='" << kLabelPx << "' y='" << bar_y << "' width='"
           << FormatFixed(w, 1) << "' height='14' fill='" << colour
           << "'/><text x='" << kLabelPx + w + 6 << "' y='" << bar_y + 11
           << "'>" << name << " " << FormatFixed(value, 3) << " "
           << EscapeHtml(unit) << "</text>";
    }
    bars << "\n";
  }
  const int axis_y = 44 + n * kRowPx;
  const int height = axis_y + 34;
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidthPx
      << "' height='" << height << "' viewBox='0 0 " << kWidthPx << " "
      << height << "' font-family='sans-serif' font-size='11' data-plot='rms-"
      << EscapeHtml(unit) << "'>\n"
      << "<text x='" << kWidthPx / 2
      << "' y='16' text-anchor='middle' font-size='14' font-weight='bold'>"
      << "Residual RMS before and after the adjustment (" << EscapeHtml(unit)
      << ")</text>\n"
      << bars.str() << "<line x1='" << kLabelPx << "' y1='" << axis_y
      << "' x2='" << kLabelPx + kBarPx << "' y2='" << axis_y
      << "' stroke='#333'/>";
  for (int i = 0; i <= 4; ++i) {
    const double x = kLabelPx + kBarPx * i / 4.0;
    svg << "<line x1='" << x << "' y1='" << axis_y << "' x2='" << x << "' y2='"
        << axis_y + 4 << "' stroke='#333'/><text x='" << x << "' y='"
        << axis_y + 16 << "' text-anchor='middle'>"
        << FormatFixed(step * i, decimals) << "</text>";
  }
  svg << "<text x='" << kLabelPx + kBarPx / 2 << "' y='" << axis_y + 30
      << "' text-anchor='middle'>RMS (" << EscapeHtml(unit) << ")</text>\n"
      << "</svg>\n";
  return svg.str();
}

}  // namespace

std::pair<std::string, std::string> SplitUnit(const std::string& key) {
  static const std::vector<std::pair<std::string, std::string>> kUnits = {
      {"_m2", "m²"}, {"_cm", "cm"}, {"_mm", "mm"},   {"_m", "m"},
      {"_s", "s"},   {"_deg", "°"}, {"_px", "px"},   {"_mb", "MB"},
      {"_hz", "Hz"}, {"_sd", "sd"}, {"_ppm", "ppm"}, {"_pct", "%"}};
  for (const auto& [suffix, name] : kUnits) {
    if (key.size() > suffix.size() &&
        key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return {key.substr(0, key.size() - suffix.size()), name};
    }
  }
  return {key, key == "z" ? "sd" : ""};
}

std::string HumanKey(const std::string& key) {
  const auto [stem, unit] = SplitUnit(key);
  std::string words;
  std::istringstream parts(stem);
  std::string part;
  while (std::getline(parts, part, '_')) {
    if (part == "rms" || part == "rmse" || part == "id" || part == "gcp" ||
        part == "crs" || part == "3d" || part == "2d" || part == "sd") {
      std::transform(part.begin(), part.end(), part.begin(), ::toupper);
    }
    words += (words.empty() ? "" : " ") + part;
  }
  if (!words.empty() && words[0] >= 'a' && words[0] <= 'z') {
    words[0] = static_cast<char>(words[0] - 'a' + 'A');
  }
  return unit.empty() ? words : words + " (" + unit + ")";
}

std::string AccuracyTable(const json& gcp) {
  std::ostringstream html;
  html << "<table>"
       << Row({"Points", "Crossings", "Vertices", "RMSE horizontal (cm)",
               "RMSE vertical (cm)", "RMSE 3D (cm)", "Largest 3D (cm)"},
              true);
  for (const char* role : {"control", "check"}) {
    const json& g = gcp.value(role, json::object());
    const auto cm = [&g](const char* key) {
      return g.contains(key) && g[key].is_number()
                 ? FormatFixed(100.0 * g[key].get<double>(), 1)
                 : std::string("–");
    };
    html << Row(
        {role, std::to_string(g.value("crossings", 0)),
         std::to_string(g.value("vertices", 0)), cm("rmse_horizontal_m"),
         cm("rmse_vertical_m"), cm("rmse_3d_m"), cm("max_3d_m")},
        false, role);
  }
  html << "</table>\n";
  return html.str();
}

std::string GcpTable(const ReportData& data) {
  if (data.residuals.empty()) return "<p class='none'>no control points</p>\n";
  std::vector<const GcpResidual*> rows;
  for (const GcpResidual& r : data.residuals) rows.push_back(&r);
  std::stable_sort(rows.begin(), rows.end(), [](const auto* a, const auto* b) {
    return std::tie(a->crossing_id, a->band, a->vertex) <
           std::tie(b->crossing_id, b->band, b->vertex);
  });
  std::ostringstream html;
  html << "<p>Each database vertex matched in the images: control points "
          "held the adjustment, check points were held out of it (their "
          "residual is where the images alone put them), rejected ones failed "
          "the blunder test. Residual = adjusted minus database, east, north, "
          "up of the local frame.</p>\n<div class='scroll'><table>"
       << Row({"Crossing", "Band", "Vertex", "Used as", "East (cm)",
               "North (cm)", "Up (cm)", "Horizontal (cm)", "3D (cm)", "Images",
               "Image RMS (px)", "Normalised residual (sd)"},
              true);
  for (const GcpResidual* r : rows) {
    html << Row(
        {EscapeHtml(r->crossing_id), std::to_string(r->band),
         std::to_string(r->vertex), RoleName(*r), Cell(100.0 * r->d_enu.x(), 1),
         Cell(100.0 * r->d_enu.y(), 1), Cell(100.0 * r->d_enu.z(), 1),
         Cell(100.0 * r->d_enu.head<2>().norm(), 1),
         Cell(100.0 * r->d_enu.norm(), 1), std::to_string(r->n_images),
         Cell(r->rms_px, 2), Cell(r->normalized_residual, 2)},
        false, RoleName(*r));
  }
  html << "</table></div>\n";
  return html.str();
}

std::string CameraResidualSection(const ReportData& data) {
  if (data.image_residuals.empty()) {
    return "<p class='none'>no reprojection residuals (needs poses.csv, "
           "matches.csv, reconstructed_bands.csv and gcp_residuals.csv)</p>\n";
  }
  std::map<std::string, std::vector<double>> control, check, all;
  std::map<std::pair<std::string, int64_t>, std::vector<double>> exposure;
  std::vector<double> control_all, check_all;
  for (const ImageResidual& r : data.image_residuals) {
    (r.role == GcpRole::kControl ? control : check)[r.camera].push_back(
        r.error_px);
    (r.role == GcpRole::kControl ? control_all : check_all)
        .push_back(r.error_px);
    all[r.camera].push_back(r.error_px);
    exposure[{r.camera, r.exposure_id}].push_back(r.error_px);
  }
  std::ostringstream html;
  html << "<div id='camera-residuals'>"
       << "<p>Each control and check point's adjusted position projected "
          "through the adjusted camera pose (poses.csv) and the calibration, "
          "against where the stereo reconstruction measured it: the "
          "distance in the image, in pixels. Per exposure: the RMS over the "
          "points an exposure saw, summarised over the exposures.</p>\n"
       << "<table>"
       << Row({"Camera", "Observations (control)", "Observations (check)",
               "RMS control (px)", "RMS check (px)", "Median (px)",
               "95th percentile (px)", "Largest (px)", "Exposures",
               "Exposure RMS median (px)", "Exposure RMS 95th pct (px)",
               "Worst exposure (RMS px)"},
              true);
  for (const auto& [camera, values] : all) {
    const Spread total = SpreadOf(values);
    std::vector<double> per_exposure;
    int64_t worst_id = 0;
    double worst = -1.0;
    for (const auto& [key, errors] : exposure) {
      if (key.first != camera) continue;
      per_exposure.push_back(Rms(errors));
      if (per_exposure.back() > worst) {
        worst = per_exposure.back();
        worst_id = key.second;
      }
    }
    const Spread exposures = SpreadOf(per_exposure);
    html << Row({EscapeHtml(camera), std::to_string(control[camera].size()),
                 std::to_string(check[camera].size()),
                 Cell(SpreadOf(control[camera]).rms, 2),
                 Cell(SpreadOf(check[camera]).rms, 2), Cell(total.median, 2),
                 Cell(total.p95, 2), Cell(total.max, 2),
                 std::to_string(exposures.count), Cell(exposures.median, 2),
                 Cell(exposures.p95, 2),
                 std::to_string(worst_id) + " (" + Cell(worst, 2) + ")"});
  }
  html << "</table>\n<div class='row'>"
       << RenderHistogram("Control points: reprojection error",
                          "image distance (px)", control_all, 20,
                          kControlColour, "observations");
  if (!check_all.empty()) {
    html << RenderHistogram("Check points: reprojection error",
                            "image distance (px)", check_all, 20, kCheckColour,
                            "observations");
  }
  html << "</div></div>\n";
  return html.str();
}

std::string GuardTable(const json& crossings) {
  std::ostringstream html;
  html << "<table>"
       << Row({"Crossing", "Used as control or check", "Input misfit (cm)",
               "Adjusted misfit (cm)", "Adjusted worse by (sd)",
               "Adjusted worse"},
              true);
  for (const json& c : crossings) {
    const auto cm = [&c](const char* key) {
      return c.contains(key) && c[key].is_number()
                 ? Cell(100.0 * c[key].get<double>(), 1)
                 : std::string("–");
    };
    html << Row({EscapeHtml(c.value("crossing_id", std::string())),
                 c.value("used", false) ? "yes" : "no (rejected)",
                 cm("input_misfit_m"), cm("adjusted_misfit_m"),
                 c.contains("z") && c["z"].is_number()
                     ? Cell(c["z"].get<double>(), 1)
                     : std::string("–"),
                 c.value("worse", false) ? "<b>yes</b>" : "no"});
  }
  html << "</table>\n";
  return html.str();
}

std::string ObservationRmsSection(const json& adjustment) {
  if (!adjustment.is_object() || !adjustment.contains("rms")) return "";
  // Units in the order of their first type.
  std::vector<std::pair<std::string,
                        std::vector<std::tuple<std::string, double, double>>>>
      by_unit;
  std::ostringstream html;
  html << "<p>RMS of the residuals per observation type, before and after "
          "the adjustment:</p>\n<table>"
       << Row({"Observation", "Unit", "Count", "RMS before", "RMS after"},
              true);
  for (const auto& [type, values] : adjustment["rms"].items()) {
    if (!values.is_object() || !values.contains("before") ||
        !values.contains("after") || !values["before"].is_number() ||
        !values["after"].is_number()) {
      continue;
    }
    const std::string unit = values.value("unit", "");
    const double before = values["before"].get<double>();
    const double after = values["after"].get<double>();
    html << Row({EscapeHtml(HumanKey(type)), EscapeHtml(unit),
                 std::to_string(values.value("count", 0)), Cell(before, 3),
                 Cell(after, 3)});
    auto it = std::find_if(by_unit.begin(), by_unit.end(),
                           [&unit](const auto& u) { return u.first == unit; });
    if (it == by_unit.end()) it = by_unit.insert(by_unit.end(), {unit, {}});
    it->second.emplace_back(type, before, after);
  }
  html << "</table>\n";
  for (const auto& [unit, rows] : by_unit) html << RmsChart(unit, rows);
  return html.str();
}

std::string CrsParagraph(const ReportData& data, const json& report) {
  std::ostringstream html;
  html << "<p><b>Coordinate systems.</b> Output CRS: ";
  if (data.output_crs.empty()) {
    html << "WGS84 (EPSG:4979: latitude, longitude in degrees, ellipsoidal "
            "height in metres), as in the contract; survey.yaml sets no "
            "output_crs.";
  } else {
    html << "<b>" << EscapeHtml(data.output_crs) << "</b>"
         << (data.output_crs_description.empty()
                 ? ""
                 : " (" + EscapeHtml(data.output_crs_description) + ")")
         << ": poses.csv, trajectory_corrected.csv, gcp_residuals.csv and "
            "matches.csv carry crs_x, crs_y, crs_z in it beside WGS84, and "
            "bands.geojson is in it.";
  }
  const json origin = report["survey"].value("origin", json::array());
  html << " Plots and residuals: the survey's local east-north-up frame in "
          "metres";
  if (origin.is_array() && origin.size() == 3) {
    html << ", origin at latitude " << FormatFixed(origin[0].get<double>(), 7)
         << "°, longitude " << FormatFixed(origin[1].get<double>(), 7)
         << "°, height " << FormatFixed(origin[2].get<double>(), 3)
         << " m (WGS84)";
  }
  html << ".</p>\n";
  return html.str();
}

}  // namespace report_internal
}  // namespace zebrageo
