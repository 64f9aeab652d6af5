#include "tools/report/report.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/results.h"
#include "tools/report/svg_plot.h"
#include "tools/version.h"

namespace zebrageo {
namespace {

using nlohmann::json;

// `texts` in order, each once: a warning can reach the report by two ways
// (a stage's list and the file it wrote).
std::vector<std::string> WithoutRepeats(const std::vector<std::string>& texts) {
  std::vector<std::string> unique;
  std::set<std::string> seen;
  for (const std::string& text : texts) {
    if (seen.insert(text).second) unique.push_back(text);
  }
  return unique;
}

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// Everything the report shows, gathered once from the results folder.
struct ReportData {
  // Trajectory: input and corrected, sample by sample.
  std::vector<double> time_s;
  std::vector<Eigen::Vector3d> input_enu;
  std::vector<Eigen::Vector3d> correction_enu;  // corrected - input
  std::vector<double> heading_correction_deg;
  bool has_corrected = false;
  double length_m = 0.0;
  // Ground control.
  std::vector<GcpResidual> residuals;
  std::vector<Eigen::Vector3d> residual_positions_enu;  // database vertex
  std::vector<CrossingDecision> decisions;
  std::map<std::string, Eigen::Vector3d> crossing_centres_enu;
  json match_evidence;  // may be null
  json adjustment;      // may be null
  json reconstruction;  // may be null
  json line_control;    // may be null (no road lines used)
  int reconstructed_bands = 0;
  int matched_vertices = 0;
  std::vector<std::string> missing_files;
};

bool Exists(const std::string& path) {
  return std::filesystem::is_regular_file(path);
}

json ReadJsonFile(const std::string& path, const std::string& name) {
  std::ifstream in(path);
  try {
    return json::parse(in);
  } catch (const json::exception& error) {
    throw InputError(name, 0, std::string("malformed JSON: ") + error.what());
  }
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / values.size());
}

ReportData Collect(const ReportInputs& inputs) {
  const Survey& survey = *inputs.survey;
  const std::string folder = inputs.results_folder + "/";
  ReportData data;
  const Trajectory& trajectory = survey.trajectory;
  for (int i = 0; i < trajectory.size(); ++i) {
    data.time_s.push_back(trajectory.samples()[i].time);
    data.input_enu.push_back(trajectory.poses()[i].p_enu);
    if (i > 0) {
      data.length_m +=
          (trajectory.poses()[i].p_enu - trajectory.poses()[i - 1].p_enu)
              .norm();
    }
  }
  if (Exists(folder + kTrajectoryCorrectedFile)) {
    const std::vector<TrajectorySample> corrected = ReadTrajectorySamples(
        folder + kTrajectoryCorrectedFile, kTrajectoryCorrectedFile);
    if (static_cast<int>(corrected.size()) != trajectory.size()) {
      throw InputError(kTrajectoryCorrectedFile, 0,
                       "has " + std::to_string(corrected.size()) +
                           " samples, the input trajectory " +
                           std::to_string(trajectory.size()));
    }
    data.has_corrected = true;
    for (int i = 0; i < trajectory.size(); ++i) {
      const Eigen::Vector3d p =
          survey.frame.EnuFromGeodetic(corrected[i].position);
      data.correction_enu.push_back(p - data.input_enu[i]);
      data.heading_correction_deg.push_back(
          std::remainder(corrected[i].attitude.heading -
                             trajectory.samples()[i].attitude.heading,
                         2.0 * M_PI) *
          kRadToDeg);
    }
  } else {
    data.missing_files.push_back(kTrajectoryCorrectedFile);
  }

  // Database geometry for placing residuals and crossings.
  std::map<std::pair<std::string, int>, const RoadmarkBand*> db_bands;
  std::map<std::string, std::pair<Eigen::Vector3d, int>> sums;
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    db_bands[{band.crossing_id, band.band}] = &band;
    for (const Geodetic& corner : band.corners) {
      auto& sum = sums[band.crossing_id];
      sum.first += survey.frame.EnuFromGeodetic(corner);
      sum.second += 1;
    }
  }
  for (const auto& [id, sum] : sums) {
    data.crossing_centres_enu[id] = sum.first / sum.second;
  }

  if (Exists(folder + kGcpResidualsFile)) {
    data.residuals =
        ReadGcpResiduals(folder + kGcpResidualsFile, kGcpResidualsFile);
    for (const GcpResidual& r : data.residuals) {
      const auto it = db_bands.find({r.crossing_id, r.band});
      data.residual_positions_enu.push_back(
          it == db_bands.end()
              ? Eigen::Vector3d::Constant(NAN)
              : survey.frame.EnuFromGeodetic(it->second->corners[r.vertex]));
    }
  } else {
    data.missing_files.push_back(kGcpResidualsFile);
  }
  if (Exists(folder + kCrossingDecisionsFile)) {
    data.decisions = ReadCrossingDecisions(folder + kCrossingDecisionsFile,
                                           kCrossingDecisionsFile);
  } else {
    data.missing_files.push_back(kCrossingDecisionsFile);
  }
  if (Exists(folder + kMatchesFile)) {
    data.matched_vertices = static_cast<int>(
        ReadMatches(folder + kMatchesFile, kMatchesFile).size());
  }
  if (Exists(folder + kReconstructedBandsFile)) {
    std::set<int64_t> bands;
    for (const ReconstructedVertex& v : ReadReconstructedBands(
             folder + kReconstructedBandsFile, kReconstructedBandsFile)) {
      bands.insert(v.band_id);
    }
    data.reconstructed_bands = static_cast<int>(bands.size());
  } else {
    data.missing_files.push_back(kReconstructedBandsFile);
  }
  if (Exists(folder + "match_evidence.json")) {
    data.match_evidence =
        ReadJsonFile(folder + "match_evidence.json", "match_evidence.json");
  }
  if (Exists(folder + "adjustment.json")) {
    data.adjustment =
        ReadJsonFile(folder + "adjustment.json", "adjustment.json");
  }
  if (Exists(folder + "reconstruction.json")) {
    data.reconstruction =
        ReadJsonFile(folder + "reconstruction.json", "reconstruction.json");
  }
  // Written by the adjustment only when road lines were used: not missing
  // otherwise.
  if (Exists(folder + "line_control.json")) {
    data.line_control =
        ReadJsonFile(folder + "line_control.json", "line_control.json");
  }
  return data;
}

json GcpStatistics(const ReportData& data, GcpRole role) {
  std::vector<double> h, v, d3;
  std::set<std::string> crossings;
  for (const GcpResidual& r : data.residuals) {
    if (r.role != role) continue;
    h.push_back(r.d_enu.head<2>().norm());
    v.push_back(r.d_enu.z());
    d3.push_back(r.d_enu.norm());
    crossings.insert(r.crossing_id);
  }
  json j = {{"vertices", h.size()}, {"crossings", crossings.size()}};
  if (!h.empty()) {
    j["rmse_horizontal_m"] = Rms(h);
    j["rmse_vertical_m"] = Rms(v);
    j["rmse_3d_m"] = Rms(d3);
    j["max_3d_m"] = *std::max_element(d3.begin(), d3.end());
  }
  return j;
}

// Per database crossing: what happened to it.
json CrossingTable(const ReportData& data) {
  struct Row {
    int matched_exposures = 0;
    std::vector<double> control_d3d, check_d3d;
  };
  std::map<std::string, Row> rows;
  for (const CrossingDecision& d : data.decisions) {
    if (d.decision == Decision::kMatched)
      ++rows[d.crossing_id].matched_exposures;
  }
  for (const GcpResidual& r : data.residuals) {
    Row& row = rows[r.crossing_id];
    (r.role == GcpRole::kControl ? row.control_d3d : row.check_d3d)
        .push_back(r.d_enu.norm());
  }
  json table = json::array();
  for (const auto& [id, row] : rows) {
    json entry = {
        {"crossing_id", id},
        {"matched_exposures", row.matched_exposures},
        {"role", !row.check_d3d.empty()     ? "check"
                 : !row.control_d3d.empty() ? "control"
                                            : "matched, not adjusted"}};
    if (!row.control_d3d.empty())
      entry["control_rms_3d_m"] = Rms(row.control_d3d);
    if (!row.check_d3d.empty()) entry["check_rms_3d_m"] = Rms(row.check_d3d);
    table.push_back(entry);
  }
  return table;
}

// Decisions that did not match, grouped by reason.
json RefusalReasons(const ReportData& data) {
  std::map<std::string, int> counts;
  for (const CrossingDecision& d : data.decisions) {
    if (d.decision == Decision::kMatched) continue;
    counts[std::string(DecisionName(d.decision)) + ": " + d.reason] += 1;
  }
  json out = json::array();
  for (const auto& [reason, count] : counts) {
    out.push_back({{"reason", reason}, {"observations", count}});
  }
  return out;
}

// Stretches of trajectory farther than control_radius_m from every control
// crossing, longer than max_uncontrolled_stretch_m.
json UncontrolledStretches(const ReportData& data,
                           const ReportOptions& options) {
  std::vector<Eigen::Vector3d> control;
  std::set<std::string> seen;
  for (const GcpResidual& r : data.residuals) {
    if (r.role != GcpRole::kControl || !seen.insert(r.crossing_id).second) {
      continue;
    }
    const auto it = data.crossing_centres_enu.find(r.crossing_id);
    if (it != data.crossing_centres_enu.end()) control.push_back(it->second);
  }
  json stretches = json::array();
  double start_distance = 0.0, distance = 0.0;
  int start = -1;
  const int n = static_cast<int>(data.input_enu.size());
  for (int i = 0; i <= n; ++i) {
    bool controlled = i == n;
    if (i < n) {
      if (i > 0) distance += (data.input_enu[i] - data.input_enu[i - 1]).norm();
      for (const Eigen::Vector3d& c : control) {
        if ((c - data.input_enu[i]).head<2>().norm() <
            options.control_radius_m) {
          controlled = true;
          break;
        }
      }
    }
    if (!controlled && start < 0) {
      start = i;
      start_distance = distance;
    } else if (controlled && start >= 0) {
      const double length = distance - start_distance;
      if (length > options.max_uncontrolled_stretch_m) {
        stretches.push_back({{"start_time_s", data.time_s[start]},
                             {"end_time_s", data.time_s[i - 1]},
                             {"length_m", length}});
      }
      start = -1;
    }
  }
  return stretches;
}

// True when road-line points controlled cross-track over most of the
// 30 s stretches overlapping [t0, t1] (absolute times).
bool RoadLinesControl(const json& road_lines, double t0, double t1) {
  if (!road_lines.is_object()) return false;
  const double length = road_lines.value("stretch_s", 0.0);
  int overlapping = 0, controlled = 0;
  for (const json& s : road_lines.value("stretches", json::array())) {
    const double a = s.value("time0", 0.0);
    if (a + length <= t0 || a >= t1) continue;
    ++overlapping;
    if (s.value("cross_track_points", 0) > 0) ++controlled;
  }
  return overlapping > 0 && 2 * controlled > overlapping;
}

json BuildFromData(const ReportInputs& inputs, const ReportOptions& options,
                   const ReportData& data) {
  const Survey& survey = *inputs.survey;
  json report;
  report["zebrageo_version"] = ZEBRAGEO_VERSION_STRING;
  report["survey"] = {
      {"name", survey.manifest.name},
      {"folder", survey.folder},
      {"origin",
       {survey.frame.origin().lat_deg, survey.frame.origin().lon_deg,
        survey.frame.origin().h_m}},
      {"exposures", survey.exposures.exposures.size()},
      {"images", survey.exposures.images.size()},
      {"trajectory_samples", survey.trajectory.size()},
      {"duration_s",
       survey.trajectory.end_time() - survey.trajectory.start_time()},
      {"length_m", data.length_m},
      {"database_bands", survey.roadmarks.bands.size()}};

  int matched = 0, refused = 0, no_candidate = 0;
  std::set<std::string> matched_crossings;
  for (const CrossingDecision& d : data.decisions) {
    if (d.decision == Decision::kMatched) {
      ++matched;
      matched_crossings.insert(d.crossing_id);
    }
    if (d.decision == Decision::kRefused) ++refused;
    if (d.decision == Decision::kNoCandidate) ++no_candidate;
  }
  report["counts"] = {{"reconstructed_bands", data.reconstructed_bands},
                      {"crossing_observations", data.decisions.size()},
                      {"matched_observations", matched},
                      {"refused_observations", refused},
                      {"no_candidate_observations", no_candidate},
                      {"matched_crossings", matched_crossings.size()},
                      {"matched_vertices", data.matched_vertices}};

  report["gcp"] = {{"control", GcpStatistics(data, GcpRole::kControl)},
                   {"check", GcpStatistics(data, GcpRole::kCheck)}};
  if (data.has_corrected) {
    std::vector<double> h, v;
    double max_h = 0.0, max_v = 0.0, max_heading = 0.0;
    for (size_t i = 0; i < data.correction_enu.size(); ++i) {
      h.push_back(data.correction_enu[i].head<2>().norm());
      v.push_back(data.correction_enu[i].z());
      max_h = std::max(max_h, h.back());
      max_v = std::max(max_v, std::abs(v.back()));
      max_heading =
          std::max(max_heading, std::abs(data.heading_correction_deg[i]));
    }
    report["corrections"] = {{"rms_horizontal_m", Rms(h)},
                             {"max_horizontal_m", max_h},
                             {"rms_vertical_m", Rms(v)},
                             {"max_vertical_m", max_v},
                             {"max_heading_deg", max_heading}};
  }
  json rms_before = json::object(), rms_after = json::object();
  if (data.adjustment.is_object()) {
    report["adjustment"] = data.adjustment;
    if (data.adjustment.contains("rms")) {
      for (const auto& [type, values] : data.adjustment["rms"].items()) {
        if (values.contains("before")) rms_before[type] = values["before"];
        if (values.contains("after")) rms_after[type] = values["after"];
      }
    }
  }
  report["rms_before"] = rms_before;
  report["rms_after"] = rms_after;
  if (data.match_evidence.is_object() &&
      data.match_evidence.contains("summary")) {
    report["matching"] = data.match_evidence["summary"];
  }
  if (data.reconstruction.is_object())
    report["reconstruction"] = data.reconstruction;
  report["crossings"] = CrossingTable(data);
  report["unmatched_reasons"] = RefusalReasons(data);
  report["database_faults"] =
      data.match_evidence.is_object() && data.match_evidence.contains("faults")
          ? data.match_evidence["faults"]
          : json::array();
  report["uncontrolled_stretches"] = UncontrolledStretches(data, options);
  if (data.line_control.is_object()) report["road_lines"] = data.line_control;

  json timings = json::object();
  double total = 0.0;
  for (const StageTiming& t : inputs.timings) {
    timings[t.stage] = t.seconds;
    total += t.seconds;
  }
  if (!inputs.timings.empty()) timings["total"] = total;
  report["timings_s"] = timings;
  report["resumed_stages"] = json::array();
  for (const StageTiming& t : inputs.timings) {
    if (t.resumed) report["resumed_stages"].push_back(t.stage);
  }
  if (inputs.peak_memory_mb > 0.0)
    report["peak_memory_mb"] = inputs.peak_memory_mb;

  // Warnings: the survey's, the stages' (those the match and adjust stages
  // recorded in their files too, so that every warning they logged is
  // here, resumed stages included), and what the figures show.
  std::vector<std::string> warnings = survey.warnings;
  warnings.insert(warnings.end(), inputs.warnings.begin(),
                  inputs.warnings.end());
  for (const json* stage_file : {&data.match_evidence, &data.adjustment}) {
    if (!stage_file->is_object()) continue;
    for (const json& w : stage_file->value("warnings", json::array())) {
      if (w.is_string()) warnings.push_back(w.get<std::string>());
    }
  }
  for (const std::string& file : data.missing_files) {
    warnings.push_back("no " + file + " in the results folder");
  }
  if (survey.roadmarks.bands.empty()) {
    warnings.push_back("the road-mark database (" + survey.manifest.roadmarks +
                       ") holds no zebra band: nothing can control the "
                       "trajectory");
  }
  if (data.decisions.empty() || matched == 0) {
    warnings.push_back(
        "no zebra crossing was matched: the trajectory is not "
        "controlled anywhere");
  }
  for (json& s : report["uncontrolled_stretches"]) {
    const bool lines = RoadLinesControl(report.value("road_lines", json()),
                                        s["start_time_s"].get<double>(),
                                        s["end_time_s"].get<double>());
    s["road_lines_control_cross_track_and_height"] = lines;
    std::ostringstream text;
    text.precision(0);
    text << std::fixed << "no control over " << s["length_m"].get<double>()
         << " m of trajectory (t = " << s["start_time_s"].get<double>()
         << " to " << s["end_time_s"].get<double>() << " s) by zebra crossings"
         << (lines ? "; road lines control cross-track and height there, "
                     "along-track is not controlled"
                   : "");
    warnings.push_back(text.str());
  }
  if (data.adjustment.is_object() && data.adjustment.contains("sigma0") &&
      data.adjustment["sigma0"].is_number() &&
      data.adjustment["sigma0"].get<double>() > options.max_sigma0) {
    warnings.push_back("high sigma0 (" + data.adjustment["sigma0"].dump() +
                       "): observations fit worse than their stated weights");
  }
  if (report.contains("road_lines")) {
    for (const json& line :
         report["road_lines"].value("rejected_lines", json::array())) {
      std::ostringstream text;
      text.precision(2);
      text << std::fixed << "database: road line "
           << line.value("db_line", std::string()) << " ("
           << line.value("type", std::string()) << ") lies "
           << std::abs(line.value("offset_m", 0.0))
           << " m across from where the other lines put it: repainted or "
              "stale, not used as control";
      warnings.push_back(text.str());
    }
  }
  for (const json& fault : report["database_faults"]) {
    if (fault.contains("description")) {
      warnings.push_back("database: " +
                         fault["description"].get<std::string>());
    }
  }
  report["warnings"] = WithoutRepeats(warnings);
  return report;
}

// --- HTML ---------------------------------------------------------------

std::string Fixed(double value, int decimals) {
  std::ostringstream text;
  text.precision(decimals);
  text << std::fixed << value;
  return text.str();
}

std::string JsonCell(const json& value) {
  if (value.is_number_float()) return Fixed(value.get<double>(), 3);
  if (value.is_string()) return EscapeHtml(value.get<std::string>());
  if (value.is_null()) return "";
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
    html << "<th>" << EscapeHtml(c) << "</th>";
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

std::string KeyValueTable(const json& object) {
  std::ostringstream html;
  html << "<table>";
  for (const auto& [key, value] : object.items()) {
    if (value.is_object()) {
      for (const auto& [sub_key, sub_value] : value.items()) {
        if (sub_value.is_object() || sub_value.is_array()) continue;
        html << "<tr><th>" << EscapeHtml(key + " " + sub_key) << "</th><td>"
             << JsonCell(sub_value) << "</td></tr>";
      }
      continue;
    }
    if (value.is_array()) continue;
    html << "<tr><th>" << EscapeHtml(key) << "</th><td>" << JsonCell(value)
         << "</td></tr>";
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
  plot.AddSeries(track);
  PlotSeries crossings;
  crossings.label = "database crossings";
  crossings.colour = "#d62728";
  crossings.markers = true;
  for (const auto& [id, centre] : data.crossing_centres_enu) {
    crossings.x.push_back(centre.x());
    crossings.y.push_back(centre.y());
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
                   "time since start (s)", "metres");
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
  SvgPlot heading("Heading correction", "time since start (s)", "degrees");
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
  vectors.SetNote("arrows exaggerated x" + Fixed(scale, 0) +
                  "; blue = control, red = check");
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
  html += RenderHistogram("Control points: 3D residual", "cm", control, 20,
                          "#1f77b4");
  if (!check.empty()) {
    html += RenderHistogram("Check points: 3D residual", "cm", check, 20,
                            "#d62728");
  }
  html += "</div>";
  return html;
}

// Before/after figure of the adjustment: per observation type, the RMS of
// the residuals before (grey) and after (blue) as bars scaled to the larger
// of the two (the types differ by orders of magnitude and in units).
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
               "matched line points");
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

std::string BeforeAfterFigure(const json& adjustment) {
  if (!adjustment.is_object() || !adjustment.contains("rms")) return "";
  constexpr int kRowPx = 44, kLabelPx = 230, kBarPx = 420, kWidthPx = 860;
  std::ostringstream rows;
  int n = 0;
  for (const auto& [type, values] : adjustment["rms"].items()) {
    if (!values.is_object() || !values.contains("before") ||
        !values.contains("after") || !values["before"].is_number() ||
        !values["after"].is_number()) {
      continue;
    }
    const double before = values["before"].get<double>();
    const double after = values["after"].get<double>();
    const std::string unit = values.value("unit", "");
    const double top = std::max({before, after, 1e-12});
    const int y = 40 + n * kRowPx;
    rows << "<text x='0' y='" << y + 16 << "'>" << EscapeHtml(type)
         << "</text>";
    int row = 0;
    for (const auto& [value, colour, name] :
         {std::tuple<double, const char*, const char*>{before, "#aaa",
                                                       "before"},
          {after, "#1f77b4", "after"}}) {
      const int bar_y = y + row++ * 18;
      const double w = std::max(1.0, kBarPx * value / top);
      rows << "<rect x='" << kLabelPx << "' y='" << bar_y << "' width='"
           << Fixed(w, 1) << "' height='14' fill='" << colour << "'/><text x='"
           << kLabelPx + w + 6 << "' y='" << bar_y + 11 << "'>" << name << " "
           << Fixed(value, 3) << " " << EscapeHtml(unit) << "</text>";
    }
    rows << "\n";
    ++n;
  }
  if (n == 0) return "";
  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidthPx
      << "' height='" << 50 + n * kRowPx << "' viewBox='0 0 " << kWidthPx << " "
      << 50 + n * kRowPx << "' font-family='sans-serif' font-size='11'>\n"
      << "<text x='" << kWidthPx / 2
      << "' y='16' text-anchor='middle' font-size='14' font-weight='bold'>"
      << "Residual RMS before and after the adjustment</text>\n"
      << rows.str() << "</svg>\n";
  return svg.str();
}

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
       << "</style></head><body>\n";
  html << "<h1>zebrageo report: " << EscapeHtml(name) << "</h1>\n";
  html << "<p>zebrageo " << ZEBRAGEO_VERSION_STRING << ". Survey "
       << EscapeHtml(report["survey"]["folder"].get<std::string>()) << ": "
       << report["survey"]["exposures"] << " exposures, "
       << Fixed(report["survey"]["length_m"].get<double>(), 0) << " m, "
       << Fixed(report["survey"]["duration_s"].get<double>(), 1) << " s.</p>\n";

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
  json accuracy = json::array();
  for (const char* role : {"control", "check"}) {
    json row = report["gcp"][role];
    row["role"] = role;
    accuracy.push_back(row);
  }
  html << ArrayTable(accuracy);
  if (!report["rms_before"].empty()) {
    json rms = json::array();
    for (const auto& [type, before] : report["rms_before"].items()) {
      rms.push_back({{"observation", type},
                     {"rms before", before},
                     {"rms after", report["rms_after"].value(type, json())}});
    }
    html << "<p>RMS of the residuals per observation type, before and after "
            "the adjustment:</p>\n"
         << ArrayTable(rms) << BeforeAfterFigure(report["adjustment"]);
  }
  if (report.contains("corrections")) {
    html << "<p>Corrections applied to the trajectory:</p>\n"
         << KeyValueTable(report["corrections"]);
  }

  html << "<h2>Trajectory</h2>\n"
       << TrajectoryMap(data) << CorrectionPlots(data);
  html << "<h2>Ground control residuals</h2>\n" << ResidualPlots(data);
  html << "<h2>Crossings</h2>\n" << ArrayTable(report["crossings"]);
  html << "<p>Observations not matched, by reason:</p>\n"
       << ArrayTable(report["unmatched_reasons"]);
  html << "<h2>Database faults found</h2>\n"
       << ArrayTable(report["database_faults"]);
  html << "<h2>Stretches without control</h2>\n"
       << ArrayTable(report["uncontrolled_stretches"]);
  html << "<h2>Road lines</h2>\n"
       << RoadLineSection(report.value("road_lines", json()), data);
  html << "<h2>Counts</h2>\n" << KeyValueTable(report["counts"]);
  html << "<h2>Stage timings</h2>\n" << KeyValueTable(report["timings_s"]);
  if (report.contains("peak_memory_mb")) {
    html << "<p>Peak memory: "
         << Fixed(report["peak_memory_mb"].get<double>(), 0) << " MB.</p>\n";
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

}  // namespace

std::string ReportOptions::Check() const {
  if (!(max_uncontrolled_stretch_m > 0.0)) {
    return "max_uncontrolled_stretch_m = " +
           std::to_string(max_uncontrolled_stretch_m) + ": must be > 0";
  }
  if (!(control_radius_m > 0.0)) {
    return "control_radius_m = " + std::to_string(control_radius_m) +
           ": must be > 0";
  }
  if (!(max_sigma0 > 0.0)) {
    return "max_sigma0 = " + std::to_string(max_sigma0) + ": must be > 0";
  }
  return "";
}

json BuildReport(const ReportInputs& inputs, const ReportOptions& options) {
  CHECK(inputs.survey != nullptr);
  return BuildFromData(inputs, options, Collect(inputs));
}

std::string RenderReportHtml(const json& report, const ReportInputs& inputs) {
  return RenderHtml(report, Collect(inputs));
}

json WriteReport(const ReportInputs& inputs, const ReportOptions& options) {
  CHECK(inputs.survey != nullptr);
  const std::string error = options.Check();
  CHECK(error.empty()) << error;
  const ReportData data = Collect(inputs);
  const json report = BuildFromData(inputs, options, data);
  const std::string html = RenderHtml(report, data);
  const std::string folder = inputs.results_folder + "/";
  WriteFileAtomically(folder + kReportJsonFile, [&](std::ostream& out) {
    out << report.dump(1) << "\n";
  });
  WriteFileAtomically(folder + kReportHtmlFile,
                      [&](std::ostream& out) { out << html; });
  return report;
}

}  // namespace zebrageo
