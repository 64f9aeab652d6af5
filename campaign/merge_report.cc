#include "campaign/merge_report.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "pipeline/svg_plot.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

using json = nlohmann::json;

// The database's accuracy at the crossings named (all of them if none).
void DatabaseSigmas(const RoadmarkDatabase& db,
                    const std::vector<std::string>& crossings, double* xy,
                    double* z) {
  const std::set<std::string> names(crossings.begin(), crossings.end());
  std::vector<double> sxy, sz;
  for (const RoadmarkBand& band : db.bands) {
    if (!names.empty() && !names.count(band.crossing_id)) continue;
    sxy.push_back(band.sigma_xy_m);
    sz.push_back(band.sigma_z_m);
  }
  *xy = Median(sxy);
  *z = Median(sz);
}

const MergedBlockView* ViewOf(const MergeReportInputs& inputs, int index) {
  for (const MergedBlockView& v : inputs.blocks) {
    if (v.block->index == index) return &v;
  }
  return nullptr;
}

std::string Cell(const json& value) {
  if (value.is_number_float()) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(3);
    s << value.get<double>();
    return s.str();
  }
  if (value.is_string()) return EscapeHtml(value.get<std::string>());
  return EscapeHtml(value.dump());
}

// An HTML table of an array of flat objects.
std::string Table(const json& rows) {
  if (!rows.is_array() || rows.empty()) return "<p>none</p>\n";
  std::ostringstream s;
  s << "<table><tr>";
  for (const auto& [key, value] : rows[0].items())
    s << "<th>" << EscapeHtml(key) << "</th>";
  s << "</tr>\n";
  for (const json& row : rows) {
    s << "<tr>";
    for (const auto& [key, value] : rows[0].items()) {
      s << "<td>" << (row.contains(key) ? Cell(row[key]) : "") << "</td>";
    }
    s << "</tr>\n";
  }
  s << "</table>\n";
  return s.str();
}

}  // namespace

json SeamFigures(const MergeReportInputs& inputs) {
  json seams = json::array();
  for (const CampaignOverlap& o : inputs.campaign->overlaps) {
    if (o.survey != inputs.survey_index) continue;
    const MergedBlockView* a = ViewOf(inputs, o.before);
    const MergedBlockView* b = ViewOf(inputs, o.after);
    if (a == nullptr || b == nullptr) continue;
    const int first = b->block->first_sample;
    const int last = a->block->last_sample;
    const double middle = 0.5 * (o.start_time + o.end_time);
    double max_h = 0.0, max_v = 0.0, max_att = 0.0;
    double mid_h = 0.0, mid_v = 0.0, mid_att = 0.0, mid_dt = 1e300;
    for (int i = first; i <= last; ++i) {
      const Pose& pa = a->corrected->poses()[i - a->block->first_sample];
      const Pose& pb = b->corrected->poses()[i - b->block->first_sample];
      const Eigen::Vector3d d = pa.p_enu - pb.p_enu;
      const double att = RadToDeg(pa.q_enu_body.angularDistance(pb.q_enu_body));
      max_h = std::max(max_h, d.head<2>().norm());
      max_v = std::max(max_v, std::abs(d.z()));
      max_att = std::max(max_att, att);
      const double dt =
          std::abs(inputs.survey->trajectory.samples()[i].time - middle);
      if (dt < mid_dt) {
        mid_dt = dt;
        mid_h = d.head<2>().norm();
        mid_v = std::abs(d.z());
        mid_att = att;
      }
    }
    double sigma_xy = 0.0, sigma_z = 0.0;
    DatabaseSigmas(inputs.survey->roadmarks, o.crossings, &sigma_xy, &sigma_z);
    seams.push_back(
        {{"before", o.before},
         {"after", o.after},
         {"start_m", o.start_m},
         {"end_m", o.end_m},
         {"crossings", o.crossings.size()},
         {"samples", last - first + 1},
         {"middle_horizontal_m", mid_h},
         {"middle_vertical_m", mid_v},
         {"middle_attitude_deg", mid_att},
         {"max_horizontal_m", max_h},
         {"max_vertical_m", max_v},
         {"max_attitude_deg", max_att},
         {"database_sigma_xy_m", sigma_xy},
         {"database_sigma_z_m", sigma_z},
         {"within_database_accuracy", mid_h <= sigma_xy && mid_v <= sigma_z}});
  }
  return seams;
}

json SurveyMergeReport(const MergeReportInputs& inputs,
                       const std::vector<GcpResidual>& residuals) {
  const CampaignSurvey& entry = inputs.campaign->surveys[inputs.survey_index];
  const Survey& survey = *inputs.survey;
  json report;
  report["campaign"] = inputs.campaign->name;
  report["survey"] = {{"name", entry.name},
                      {"folder", entry.folder},
                      {"length_m", entry.length_m}};
  std::set<std::string> control;
  for (const GcpResidual& r : residuals) {
    if (r.role == GcpRole::kControl) control.insert(r.crossing_id);
  }
  report["counts"] = {{"blocks", inputs.blocks.size()},
                      {"exposures", survey.exposures.exposures.size()},
                      {"images", survey.exposures.images.size()},
                      {"trajectory_samples", survey.trajectory.size()},
                      {"database_crossings_on_road", entry.crossings},
                      {"matched_crossings", control.size()}};
  for (GcpRole role : {GcpRole::kControl, GcpRole::kCheck}) {
    std::vector<double> h, v;
    for (const GcpResidual& r : residuals) {
      if (r.role != role) continue;
      h.push_back(r.d_enu.head<2>().norm());
      v.push_back(r.d_enu.z());
    }
    report["gcp"][role == GcpRole::kControl ? "control" : "check"] = {
        {"points", h.size()},
        {"rmse_horizontal_m", Rms(h)},
        {"rmse_vertical_m", Rms(v)}};
  }
  // Corrections and the merged trajectory's continuity: the largest change
  // of the correction from one sample to the next.
  std::vector<double> corrections;
  double max_step = 0.0;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int i = 0; i < survey.trajectory.size(); ++i) {
    const Eigen::Vector3d c =
        inputs.merged.poses()[i].p_enu - survey.trajectory.poses()[i].p_enu;
    corrections.push_back(c.head<2>().norm());
    if (i > 0) max_step = std::max(max_step, (c - previous).norm());
    previous = c;
  }
  report["corrections"] = {{"rms_horizontal_m", Rms(corrections)},
                           {"max_step_between_samples_m", max_step}};
  json blocks = json::array();
  json stretches = json::array();
  json warnings = json::array();
  std::set<std::string> faults_seen;
  json faults = json::array();
  for (const MergedBlockView& v : inputs.blocks) {
    const json& r = *v.report;
    const json& done = *v.done;
    json b = {{"index", v.block->index},
              {"start_m", v.block->start_m},
              {"end_m", v.block->end_m},
              {"exposures", v.block->exposures},
              {"planned_crossings", v.block->crossings},
              {"matched_crossings",
               r.value("counts", json::object()).value("matched_crossings", 0)},
              {"wall_s", done.value("wall_s", 0.0)},
              {"cpu_s", done.value("cpu_s", 0.0)},
              {"estimated_cpu_s", v.block->estimated_cpu_s},
              {"peak_memory_mb", done.value("peak_memory_mb", 0.0)},
              {"estimated_memory_mb", v.block->estimated_memory_mb},
              {"warnings", r.value("warnings", json::array()).size()}};
    const json gcp = r.value("gcp", json::object());
    for (const char* role : {"control", "check"}) {
      const json g = gcp.value(role, json::object());
      if (g.contains("rmse_horizontal_m") &&
          g["rmse_horizontal_m"].is_number()) {
        b[std::string(role) + "_rmse_horizontal_m"] = g["rmse_horizontal_m"];
      }
    }
    blocks.push_back(b);
    for (const json& s : r.value("uncontrolled_stretches", json::array())) {
      const double middle =
          0.5 * (s.value("start_time_s", 0.0) + s.value("end_time_s", 0.0));
      // Reported by the block that owns the stretch's middle.
      if (v.weight(middle) < 0.5) continue;
      json stretch = s;
      stretch["block"] = v.block->index;
      stretches.push_back(stretch);
    }
    for (const json& f : r.value("database_faults", json::array())) {
      if (faults_seen.insert(f.dump()).second) faults.push_back(f);
    }
    for (const json& w : r.value("warnings", json::array())) {
      warnings.push_back("block " + std::to_string(v.block->index) + ": " +
                         w.get<std::string>());
    }
  }
  report["blocks"] = blocks;
  report["seams"] = SeamFigures(inputs);
  for (const json& seam : report["seams"]) {
    if (!seam["within_database_accuracy"].get<bool>()) {
      warnings.push_back(
          "blocks " + std::to_string(seam["before"].get<int>()) + " and " +
          std::to_string(seam["after"].get<int>()) +
          " disagree by more than the database's accuracy in their overlap");
    }
  }
  report["uncontrolled_stretches"] = stretches;
  report["database_faults"] = faults;
  report["warnings"] = warnings;
  return report;
}

std::string MergeReportHtml(const nlohmann::json& report) {
  std::ostringstream s;
  const std::string name = report["survey"]["name"].get<std::string>();
  s << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>zebrageo "
       "campaign: "
    << EscapeHtml(name)
    << "</title><style>table{border-collapse:collapse}td,th{border:1px solid "
       "#999;padding:2px 6px}</style></head><body>\n"
    << "<h1>Campaign " << EscapeHtml(report["campaign"].get<std::string>())
    << ": " << EscapeHtml(name) << "</h1>\n"
    << "<h2>Counts</h2>" << Table(json::array({report["counts"]}))
    << "<h2>Control and check points</h2>"
    << Table(json::array({report["gcp"]["control"]}))
    << Table(json::array({report["gcp"]["check"]})) << "<h2>Blocks</h2>"
    << Table(report["blocks"])
    << "<h2>Seams (the blocks compared over their overlaps)</h2>"
    << Table(report["seams"]) << "<h2>Uncontrolled stretches</h2>"
    << Table(report["uncontrolled_stretches"]) << "<h2>Database faults</h2>"
    << Table(report["database_faults"]) << "<h2>Warnings</h2><ul>";
  for (const json& w : report["warnings"]) {
    s << "<li>" << EscapeHtml(w.get<std::string>()) << "</li>";
  }
  s << "</ul></body></html>\n";
  return s.str();
}

}  // namespace zebrageo
