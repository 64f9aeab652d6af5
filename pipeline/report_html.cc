#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "pipeline/report_data.h"
#include "pipeline/report_tables.h"
#include "pipeline/svg_plot.h"
#include "pipeline/version.h"
#include "survey/csv.h"

namespace zebrageo {
namespace report_internal {
namespace {

using nlohmann::json;

// --- HTML ---------------------------------------------------------------

std::string JsonCell(const json& value) {
  if (value.is_number_float()) return FormatFixed(value.get<double>(), 3);
  if (value.is_string()) return EscapeHtml(value.get<std::string>());
  if (value.is_null()) return "–";
  return EscapeHtml(value.dump());
}

// A table of an array of objects, columns = keys of the first row.
std::string ArrayTable(const json& rows, size_t max_rows = 500) {
  if (!rows.is_array() || rows.empty()) return "<p class='none'>none</p>\n";
  std::vector<std::string> columns;
  for (const auto& [key, value] : rows.front().items()) {
    if (!value.is_array() && !value.is_object()) columns.push_back(key);
  }
  std::ostringstream html;
  html << "<table><tr>";
  for (const std::string& c : columns)
    html << "<th>" << EscapeHtml(HumanKey(c)) << "</th>";
  html << "</tr>\n";
  size_t shown = 0;
  for (const json& row : rows) {
    if (++shown > max_rows) break;
    html << "<tr>";
    for (const std::string& c : columns) {
      html << "<td>" << (row.contains(c) ? JsonCell(row[c]) : "") << "</td>";
    }
    html << "</tr>\n";
  }
  html << "</table>\n";
  if (rows.size() > max_rows) {
    html << "<p>(" << rows.size() - max_rows
         << " more rows in report.json)</p>\n";
  }
  return html.str();
}

// `unit`: of every value (the keys name none), e.g. "s" for timings.
std::string KeyValueTable(const json& object, const std::string& unit = "") {
  const std::string suffix = unit.empty() ? "" : " (" + unit + ")";
  std::ostringstream html;
  html << "<table>";
  for (const auto& [key, value] : object.items()) {
    if (value.is_object()) {
      // {"unit": "px", "before": ...}: the unit of the object's figures.
      // "check_rmse_m": {"horizontal": ...}: the unit of the key's figures.
      const auto [stem, key_unit] = SplitUnit(key);
      const std::string sub_unit = value.value("unit", key_unit);
      for (const auto& [sub_key, sub_value] : value.items()) {
        if (sub_value.is_object() || sub_value.is_array() ||
            sub_key == "unit") {
          continue;
        }
        std::string header = HumanKey(stem + "_" + sub_key);
        if (!sub_unit.empty() &&
            (sub_value.is_number_float() || sub_value.is_null()) &&
            header.find('(') == std::string::npos) {
          header += " (" + sub_unit + ")";
        }
        html << "<tr><th>" << EscapeHtml(header) << "</th><td>"
             << JsonCell(sub_value) << "</td></tr>";
      }
      continue;
    }
    if (value.is_array()) continue;
    html << "<tr><th>" << EscapeHtml(HumanKey(key) + suffix) << "</th><td>"
         << JsonCell(value) << "</td></tr>";
  }
  html << "</table>\n";
  return html.str();
}

// Subsamples long series so the SVG stays small (a few thousand points).
template <typename T>
std::vector<T> Thin(const std::vector<T>& values, size_t max_points) {
  if (values.size() <= max_points) return values;
  std::vector<T> out;
  const double step = static_cast<double>(values.size()) / max_points;
  for (double i = 0; i < values.size(); i += step) {
    out.push_back(values[static_cast<size_t>(i)]);
  }
  return out;
}

std::string TrajectoryMap(const ReportData& data) {
  SvgPlot plot("Trajectory and correction magnitude", "east (m)", "north (m)",
               860, 520);
  plot.SetEqualAspect(true);
  constexpr size_t kMaxPoints = 3000;
  PlotSeries track;
  track.markers = true;
  for (size_t i = 0; i < data.input_enu.size(); ++i) {
    track.x.push_back(data.input_enu[i].x());
    track.y.push_back(data.input_enu[i].y());
    if (data.has_corrected) {
      track.colour_values.push_back(data.correction_enu[i].head<2>().norm());
    }
  }
  track.x = Thin(track.x, kMaxPoints);
  track.y = Thin(track.y, kMaxPoints);
  track.colour_values = Thin(track.colour_values, kMaxPoints);
  if (data.has_corrected) {
    double max_value = 0.0;
    for (double v : track.colour_values) max_value = std::max(max_value, v);
    plot.SetColourScale(0.0, max_value, "horizontal correction (m)");
  }
  plot.SetName("trajectory");
  plot.AddSeries(track);
  PlotSeries crossings;
  crossings.label = "database crossings";
  crossings.colour = "#d62728";
  crossings.markers = true;
  for (const auto& [id, centre] : data.crossing_centres_enu) {
    crossings.x.push_back(centre.x());
    crossings.y.push_back(centre.y());
    crossings.point_ids.push_back(id);
  }
  plot.AddSeries(crossings);
  return plot.Render();
}

std::string CorrectionPlots(const ReportData& data) {
  if (!data.has_corrected) return "<p class='none'>no corrected trajectory</p>";
  constexpr size_t kMaxPoints = 3000;
  const double t0 = data.time_s.empty() ? 0.0 : data.time_s.front();
  std::vector<double> t;
  for (double v : data.time_s) t.push_back(v - t0);
  t = Thin(t, kMaxPoints);
  SvgPlot position("Trajectory correction (corrected minus input)",
                   "time since start (s)", "correction (m)");
  const char* names[3] = {"east", "north", "up"};
  const char* colours[3] = {"#1f77b4", "#2ca02c", "#ff7f0e"};
  for (int axis = 0; axis < 3; ++axis) {
    PlotSeries s;
    s.label = names[axis];
    s.colour = colours[axis];
    s.x = t;
    std::vector<double> y;
    for (const Eigen::Vector3d& c : data.correction_enu) y.push_back(c[axis]);
    s.y = Thin(y, kMaxPoints);
    position.AddSeries(std::move(s));
  }
  SvgPlot heading("Heading correction", "time since start (s)",
                  "heading correction (°)");
  PlotSeries h;
  h.label = "heading";
  h.colour = "#9467bd";
  h.x = t;
  h.y = Thin(data.heading_correction_deg, kMaxPoints);
  heading.AddSeries(std::move(h));
  return position.Render() + heading.Render();
}

std::string ResidualPlots(const ReportData& data) {
  if (data.residuals.empty()) return "<p class='none'>no control points</p>";
  // Horizontal residual vectors at the database vertices, exaggerated.
  double max_h = 1e-6;
  for (const GcpResidual& r : data.residuals) {
    max_h = std::max(max_h, r.d_enu.head<2>().norm());
  }
  Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
  for (const Eigen::Vector3d& p : data.residual_positions_enu) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const double extent = std::max(10.0, (hi - lo).maxCoeff());
  const double scale = 0.05 * extent / max_h;
  SvgPlot vectors("Horizontal GCP residuals (adjusted minus database)",
                  "east (m)", "north (m)", 860, 520);
  vectors.SetEqualAspect(true);
  vectors.SetName("gcp");
  vectors.SetNote("arrows exaggerated x" + FormatFixed(scale, 0) +
                  "; blue = control, red = check");
  // A marker per crossing with ground control, at its centre: visible
  // whatever the arrows' lengths.
  for (const GcpRole role : {GcpRole::kControl, GcpRole::kCheck}) {
    PlotSeries markers;
    markers.markers = true;
    markers.marker_radius_px = 4.0;
    markers.label =
        role == GcpRole::kControl ? "control crossing" : "check crossing";
    markers.colour = role == GcpRole::kControl ? "#1f77b4" : "#d62728";
    std::map<std::string, bool> seen;
    for (const GcpResidual& r : data.residuals) {
      const auto centre = data.crossing_centres_enu.find(r.crossing_id);
      if (r.role != role || centre == data.crossing_centres_enu.end() ||
          !seen.emplace(r.crossing_id, true).second) {
        continue;
      }
      markers.x.push_back(centre->second.x());
      markers.y.push_back(centre->second.y());
      markers.point_ids.push_back(r.crossing_id);
    }
    if (!markers.x.empty()) vectors.AddSeries(std::move(markers));
  }
  for (size_t i = 0; i < data.residuals.size(); ++i) {
    const Eigen::Vector3d& p = data.residual_positions_enu[i];
    if (!p.allFinite()) continue;
    const GcpResidual& r = data.residuals[i];
    vectors.AddArrow({p.x(), p.y(), scale * r.d_enu.x(), scale * r.d_enu.y(),
                      r.role == GcpRole::kControl ? "#1f77b4" : "#d62728"});
  }
  std::vector<double> control, check;
  for (const GcpResidual& r : data.residuals) {
    (r.role == GcpRole::kControl ? control : check)
        .push_back(100.0 * r.d_enu.norm());
  }
  std::string html = vectors.Render();
  html += "<div class='row'>";
  html += RenderHistogram("Control points: 3D residual", "3D residual (cm)",
                          control, 20, "#1f77b4", "points");
  if (!check.empty()) {
    html += RenderHistogram("Check points: 3D residual", "3D residual (cm)",
                            check, 20, "#d62728", "points");
  }
  html += "</div>";
  return html;
}

// Road-line control per stretch: how many matched line points constrained
// each direction (lane lines: cross-track and height; along-track only
// stop lines), against time, and the stretches as a table.
std::string RoadLineSection(const json& road_lines, const ReportData& data) {
  if (!road_lines.is_object()) {
    return "<p class='none'>road lines not used (run without --no-lines and "
           "with road lines in the database)</p>\n";
  }
  const double t0 = data.time_s.empty() ? 0.0 : data.time_s.front();
  SvgPlot plot("Road-line control per stretch", "time since start (s)",
               "matched line points (count)");
  plot.SetNote(road_lines.value("note", std::string()));
  const char* keys[3] = {"cross_track_points", "height_points",
                         "along_track_points"};
  const char* labels[3] = {"cross-track", "height", "along-track"};
  const char* colours[3] = {"#1f77b4", "#ff7f0e", "#2ca02c"};
  json rows = json::array();
  for (int k = 0; k < 3; ++k) {
    PlotSeries series;
    series.label = labels[k];
    series.colour = colours[k];
    series.markers = true;
    for (const json& s : road_lines.value("stretches", json::array())) {
      const double t =
          s.value("time0", 0.0) - t0 + 0.5 * road_lines.value("stretch_s", 0.0);
      series.x.push_back(t);
      series.y.push_back(s.value(keys[k], 0));
    }
    plot.AddSeries(std::move(series));
  }
  for (const json& s : road_lines.value("stretches", json::array())) {
    std::string controlled;
    for (const json& d : s.value("controlled", json::array())) {
      controlled += (controlled.empty() ? "" : ", ") + d.get<std::string>();
    }
    const double start = s.value("time0", 0.0) - t0;
    rows.push_back({{"from (s)", start},
                    {"to (s)", start + road_lines.value("stretch_s", 0.0)},
                    {"cross-track points", s.value(keys[0], 0)},
                    {"height points", s.value(keys[1], 0)},
                    {"along-track points", s.value(keys[2], 0)},
                    {"controlled", controlled}});
  }
  std::ostringstream html;
  html << "<p>" << road_lines.value("used_points", 0) << " of "
       << road_lines.value("reconstructed_points", 0)
       << " reconstructed line points used as control ("
       << road_lines.value("matched_points", 0)
       << " matched; the rest of the matched ones lie on rejected database "
          "lines).</p>\n"
       << plot.Render() << ArrayTable(rows)
       << "<p>Database lines rejected (repainted or stale):</p>\n"
       << ArrayTable(road_lines.value("rejected_lines", json::array()));
  return html.str();
}

}  // namespace

std::string RenderHtml(const json& report, const ReportData& data) {
  std::ostringstream html;
  const std::string name = report["survey"]["name"].get<std::string>();
  html << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
       << "<title>zebrageo report: " << EscapeHtml(name) << "</title>\n<style>"
       << "body{font-family:sans-serif;margin:24px;max-width:1100px;color:#222}"
       << "h1{font-size:22px}h2{font-size:18px;margin-top:28px;"
       << "border-bottom:1px solid #ccc}table{border-collapse:collapse;"
       << "margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;"
       << "text-align:left;font-size:13px}th{background:#f3f3f3}"
       << ".warn{background:#fff4e0;border-left:4px solid #f0a000;"
       << "padding:4px 10px;margin:4px 0}.none{color:#777}"
       << ".row{display:flex;flex-wrap:wrap;gap:12px}svg{margin:6px 0}"
       << ".scroll{max-height:420px;overflow-y:auto;display:inline-block}"
       << "tr.check td{background:#fdecec}tr.rejected td{color:#999;"
       << "text-decoration:line-through}td{font-variant-numeric:tabular-nums}"
       << "</style></head><body>\n";
  html << "<h1>zebrageo report: " << EscapeHtml(name) << "</h1>\n";
  html << "<p>zebrageo " << ZEBRAGEO_VERSION_STRING << ". Survey "
       << EscapeHtml(report["survey"]["folder"].get<std::string>()) << ": "
       << report["survey"]["exposures"] << " exposures, "
       << FormatFixed(report["survey"]["length_m"].get<double>(), 0) << " m, "
       << FormatFixed(report["survey"]["duration_s"].get<double>(), 1)
       << " s.</p>\n"
       << CrsParagraph(data, report);

  html << "<h2>Warnings</h2>\n";
  if (report["warnings"].empty()) html << "<p class='none'>none</p>\n";
  for (const json& w : report["warnings"]) {
    html << "<div class='warn'>" << EscapeHtml(w.get<std::string>())
         << "</div>\n";
  }

  html << "<h2>Accuracy</h2>\n";
  html << "<p>Check points are crossings held out of the adjustment: their "
          "residuals are the honest accuracy figure (they include the "
          "database's own error).</p>\n";
  html << AccuracyTable(report["gcp"]);
  if (!report["rms_before"].empty()) {
    html << ObservationRmsSection(report["adjustment"]);
  }
  if (report.contains("corrections")) {
    html << "<p>Corrections applied to the trajectory:</p>\n"
         << KeyValueTable(report["corrections"]);
  }
  // Never worse than the input (issue 43): each matched crossing placed
  // with the input and with the adjusted trajectory.
  const json guard =
      report.value("adjustment", json::object()).value("guard", json::object());
  if (!guard.value("crossings", json::array()).empty()) {
    html << "<h2>Compared with the input trajectory</h2>\n<p>"
         << (guard.value("input_kept", false)
                 ? "The adjusted trajectory fits some matched crossings worse "
                   "than the input trajectory does: there the input "
                   "trajectory is kept (see the warnings)."
                 : "The adjusted trajectory fits every matched crossing at "
                   "least as well as the input trajectory does.")
         << " Each crossing's distance from the database, placed with "
            "each trajectory:</p>\n"
         << GuardTable(guard["crossings"]);
  }

  html << "<h2>Trajectory</h2>\n"
       << TrajectoryMap(data) << CorrectionPlots(data);
  html << "<h2>Ground control residuals</h2>\n"
       << ResidualPlots(data) << GcpTable(data);
  html << "<h2>Reprojection residuals per camera</h2>\n"
       << CameraResidualSection(data);
  html << "<h2>Crossings</h2>\n" << ArrayTable(report["crossings"]);
  html << "<h2>Database crossings in view</h2>\n"
       << "<p>What became of each: matched, refused, gone from the street, "
          "occluded, not recognised, or not reconstructed and why.</p>\n"
       << ArrayTable(report.value("crossings_in_view", json::array()));
  html << "<p>Observations not matched, by reason:</p>\n"
       << ArrayTable(report["unmatched_reasons"]);
  html << "<h2>Database faults found</h2>\n"
       << "<p>Each with the evidence it rests on: a crossing or band is gone "
          "from the street only where the images show bare road at its "
          "place.</p>\n"
       << ArrayTable(report["database_faults"]);
  html << "<h2>Not recognised (not faults)</h2>\n"
       << "<p>Database crossings and bands in view that were not recognised "
          "while the images do not show them gone: paint seen at their "
          "place, or occluded or not told.</p>\n"
       << ArrayTable(report.value("not_recognised", json::array()));
  html << "<h2>Stretches without control</h2>\n"
       << ArrayTable(report["uncontrolled_stretches"]);
  html << "<h2>Stretches where one axis is held by no control</h2>\n"
       << "<p>The axis' posterior sd above the threshold (the database's "
          "accuracy): road lines hold cross-track and height, never "
          "along-track.</p>\n"
       << ArrayTable(report.value("weakly_held_stretches", json::array()));
  html << "<h2>Road lines</h2>\n"
       << RoadLineSection(report.value("road_lines", json()), data);
  html << "<h2>Counts</h2>\n" << KeyValueTable(report["counts"]);
  html << "<h2>Stage timings</h2>\n" << KeyValueTable(report["timings_s"], "s");
  if (report.contains("peak_memory_mb")) {
    html << "<p>Peak memory: "
         << FormatFixed(report["peak_memory_mb"].get<double>(), 0)
         << " MB.</p>\n";
  }
  if (report.contains("adjustment")) {
    html << "<h2>Adjustment</h2>\n" << KeyValueTable(report["adjustment"]);
  }
  if (report.contains("matching")) {
    html << "<h2>Matching</h2>\n" << KeyValueTable(report["matching"]);
  }
  html << "</body></html>\n";
  return html.str();
}

}  // namespace report_internal
}  // namespace zebrageo
