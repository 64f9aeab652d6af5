// report.json and report.html (SURVEY_FORMAT.md "Outputs"): their writers,
// which the report stage calls (pipeline/report_stage.h builds and renders
// them).
#ifndef ZEBRAGEO_SURVEY_RESULTS_REPORT_H_
#define ZEBRAGEO_SURVEY_RESULTS_REPORT_H_

#include <nlohmann/json.hpp>
#include <string>

namespace zebrageo {

// report.json, atomically.
void WriteReportJson(const nlohmann::json& report, const std::string& path);
// report.html (a self-contained page), atomically.
void WriteReportHtml(const std::string& html, const std::string& path);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_REPORT_H_
