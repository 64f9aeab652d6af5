// The report stage: report.json for programs and a self-contained
// report.html (inline SVG plots, no network) for the mapping engineer.
//
// It is built from a results folder alone (plus the survey): the stage
// outputs that exist there (trajectory_corrected.csv, gcp_residuals.csv,
// crossing_decisions.csv, matches.csv, match_evidence.json,
// adjustment.json, reconstruction.json) and the run's stage timings.
// Missing files only remove sections; they are listed as warnings.
#ifndef ZEBRAGEO_PIPELINE_REPORT_STAGE_H_
#define ZEBRAGEO_PIPELINE_REPORT_STAGE_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "survey/survey.h"

namespace zebrageo {

struct StageTiming {
  std::string stage;
  double seconds = 0.0;
  bool resumed = false;  // taken from a previous run's complete output
};

struct ReportOptions {
  // A stretch of trajectory longer than this with no control crossing
  // within `control_radius_m` is reported as a warning.
  double max_uncontrolled_stretch_m = 150.0;
  double control_radius_m = 30.0;
  // sigma0 above this is reported as a warning (weights too optimistic or
  // blunders left).
  double max_sigma0 = 2.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_uncontrolled_stretch_m", max_uncontrolled_stretch_m);
    v("control_radius_m", control_radius_m);
    v("max_sigma0", max_sigma0);
  }
};

struct ReportInputs {
  const Survey* survey = nullptr;
  std::string results_folder;
  std::vector<StageTiming> timings;
  double peak_memory_mb = 0.0;
  std::vector<std::string> warnings;  // from the stages
  // The boresight check's verdict (pipeline/boresight_check.h), or null.
  nlohmann::json boresight;
};

// Builds the report JSON (SURVEY_FORMAT.md: counts, RMS before and after,
// per stage timings, warnings). Throws InputError when a present results
// file is malformed.
nlohmann::json BuildReport(const ReportInputs& inputs,
                           const ReportOptions& options);
// Renders the HTML page of a report built by BuildReport.
std::string RenderReportHtml(const nlohmann::json& report,
                             const ReportInputs& inputs);
// The report stage: BuildReport, then report.json and report.html written
// into the results folder (survey/results_report.h). Returns the report.
nlohmann::json RunReportStage(const ReportInputs& inputs,
                              const ReportOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_REPORT_STAGE_H_
