#include "pipeline/report_stage.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "pipeline/report_data.h"
#include "pipeline/version.h"
#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"
#include "survey/results.h"
#include "survey/results_adjustment.h"
#include "survey/results_report.h"

namespace zebrageo {
using report_internal::Collect;
using report_internal::RenderHtml;
using report_internal::ReportData;

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

// Whether road lines (whole lane-line dashes, crossing edges) held the
// along-track position in a stretch of line_control.json overlapping
// [t0, t1].
bool AlongTrackLinesControl(const json& road_lines, double t0, double t1) {
  if (!road_lines.is_object()) return false;
  const double length = road_lines.value("stretch_s", 0.0);
  for (const json& s : road_lines.value("stretches", json::array())) {
    const double a = s.value("time0", 0.0);
    if (a + length > t0 && a < t1 && s.value("along_track_points", 0) > 0) {
      return true;
    }
  }
  return false;
}

// Warnings: the survey's, the stages' (those the match and adjust stages
// recorded in their files too, so that every warning they logged is here,
// resumed stages included), and what the figures show. Marks the
// uncontrolled stretches the road lines control.
std::vector<std::string> ReportWarnings(const ReportInputs& inputs,
                                        const ReportOptions& options,
                                        const ReportData& data, int matched,
                                        json* report) {
  const Survey& survey = *inputs.survey;
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
    const bool lines_only = data.adjustment.is_object() &&
                            data.adjustment.value("road_lines_only", false);
    // Along the track: the edges of crossings seen in part, if any.
    const bool along =
        lines_only &&
        AlongTrackLinesControl(report->value("road_lines", json()),
                               -std::numeric_limits<double>::infinity(),
                               std::numeric_limits<double>::infinity());
    warnings.push_back(
        !lines_only ? "no zebra crossing was matched: the trajectory is not "
                      "controlled anywhere"
        : along     ? "no zebra crossing was matched: road lines alone "
                      "control the trajectory across them and in height, and "
                      "the edges of crossings seen in part along the track "
                      "(line_matches.csv, constrains along)"
                    : "no zebra crossing was matched: road lines alone "
                      "control the trajectory, across them and in height; "
                      "along-track it is the input's");
  }
  for (json& s : (*report)["uncontrolled_stretches"]) {
    const bool lines = RoadLinesControl(report->value("road_lines", json()),
                                        s["start_time_s"].get<double>(),
                                        s["end_time_s"].get<double>());
    s["road_lines_control_cross_track_and_height"] = lines;
    // The stretches of line_control.json are coarser than this one: dashes
    // there may lie outside it.
    const bool along =
        lines && AlongTrackLinesControl(report->value("road_lines", json()),
                                        s["start_time_s"].get<double>(),
                                        s["end_time_s"].get<double>());
    std::ostringstream text;
    text.precision(0);
    text << std::fixed << "no control over " << s["length_m"].get<double>()
         << " m of trajectory (t = " << s["start_time_s"].get<double>()
         << " to " << s["end_time_s"].get<double>() << " s) by zebra crossings"
         << (!lines  ? ""
             : along ? "; road lines control cross-track and height there, "
                       "along-track only where whole dashes or crossing "
                       "edges were matched (line_matches.csv, constrains "
                       "along)"
                     : "; road lines control cross-track and height there, "
                       "along-track is not controlled");
    warnings.push_back(text.str());
  }
  if (data.adjustment.is_object() && data.adjustment.contains("sigma0") &&
      data.adjustment["sigma0"].is_number() &&
      data.adjustment["sigma0"].get<double>() > options.max_sigma0) {
    warnings.push_back("high sigma0 (" + data.adjustment["sigma0"].dump() +
                       "): observations fit worse than their stated weights");
  }
  if (report->contains("road_lines")) {
    for (const json& line :
         (*report)["road_lines"].value("rejected_lines", json::array())) {
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
  for (const json& fault : (*report)["database_faults"]) {
    if (fault.contains("description")) {
      warnings.push_back(
          "database: " + fault["description"].get<std::string>() +
          (fault.contains("evidence")
               ? " (evidence: " + fault["evidence"].get<std::string>() + ")"
               : std::string()));
    }
  }
  // Whole crossings not recognised: the user should look, not delete.
  for (const json& mark : (*report)["not_recognised"]) {
    if (!mark.contains("band") && mark.contains("description")) {
      warnings.push_back(mark["description"].get<std::string>());
    }
  }
  return warnings;
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
      {"database_bands", survey.roadmarks.bands.size()},
      {"output_crs", data.output_crs.empty() ? "WGS84" : data.output_crs}};

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
  // Every database crossing in view and what became of it (issue 51), as
  // the first registration pass left it; crossing_decisions.csv holds the
  // second pass' matches too.
  report["crossings_in_view"] =
      data.match_evidence.is_object()
          ? data.match_evidence.value("crossings_in_view", json::array())
          : json::array();
  for (json& c : report["crossings_in_view"]) {
    const std::string status = c.value("status", std::string());
    if (status != "matched" &&
        matched_crossings.count(c.value("crossing_id", std::string()))) {
      c["reason"] =
          "by the second pass, on the adjusted trajectory (the "
          "first: " +
          status + ")";
      c["status"] = "matched";
    }
  }
  // Database crossings and bands in view that were not recognised, with no
  // image evidence that they are gone: apart from the faults (issue 52).
  report["not_recognised"] =
      data.match_evidence.is_object()
          ? data.match_evidence.value("not_recognised", json::array())
          : json::array();
  report["uncontrolled_stretches"] = UncontrolledStretches(data, options);
  // Stretches where one axis is held by no control (the adjustment's
  // posterior sd; its warnings say so too).
  report["weakly_held_stretches"] =
      data.adjustment.is_object()
          ? data.adjustment.value("weakly_held_stretches", json::array())
          : json::array();
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
  if (!inputs.boresight.is_null()) report["boresight"] = inputs.boresight;

  report["warnings"] =
      WithoutRepeats(ReportWarnings(inputs, options, data, matched, &report));
  return report;
}

}  // namespace

std::string ReportOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_uncontrolled_stretch_m, 0.0);
  OPTION_GT(check, control_radius_m, 0.0);
  OPTION_GT(check, max_sigma0, 0.0);
  return check.problem();
}

json BuildReport(const ReportInputs& inputs, const ReportOptions& options) {
  CHECK(inputs.survey != nullptr);
  return BuildFromData(inputs, options, Collect(inputs));
}

std::string RenderReportHtml(const json& report, const ReportInputs& inputs) {
  return RenderHtml(report, Collect(inputs));
}

json RunReportStage(const ReportInputs& inputs, const ReportOptions& options) {
  CHECK(inputs.survey != nullptr);
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument("ReportOptions: " + error);
  const ReportData data = Collect(inputs);
  const json report = BuildFromData(inputs, options, data);
  const std::string html = RenderHtml(report, data);
  const std::string folder = inputs.results_folder + "/";
  WriteReportJson(report, folder + kReportJsonFile);
  WriteReportHtml(html, folder + kReportHtmlFile);
  return report;
}

}  // namespace zebrageo
