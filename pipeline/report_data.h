// What the report shows, gathered once from a results folder and the survey
// (pipeline/report_stage.h); shared by the report's JSON (report_stage.cc) and
// its HTML page (report_html.cc). Internal to the pipeline library.
#ifndef ZEBRAGEO_PIPELINE_REPORT_DATA_H_
#define ZEBRAGEO_PIPELINE_REPORT_DATA_H_

#include <Eigen/Core>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pipeline/report_stage.h"
#include "survey/results.h"

namespace zebrageo {
namespace report_internal {

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
  nlohmann::json match_evidence;  // may be null
  nlohmann::json adjustment;      // may be null
  nlohmann::json reconstruction;  // may be null
  nlohmann::json line_control;    // may be null (no road lines used)
  int reconstructed_bands = 0;
  int matched_vertices = 0;
  std::vector<std::string> missing_files;
};

// Reads the results folder's files (typed, through survey/results*.h).
// Throws InputError when a present file is malformed.
ReportData Collect(const ReportInputs& inputs);

// The page of report.html.
std::string RenderHtml(const nlohmann::json& report, const ReportData& data);

}  // namespace report_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_REPORT_DATA_H_
