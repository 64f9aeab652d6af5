// The report's tables for people (report.html): headers in words with their
// units, figures in the units a surveyor reads (cm, px), one row per
// control point and per camera. Internal to the pipeline library.
#ifndef ZEBRAGEO_PIPELINE_REPORT_TABLES_H_
#define ZEBRAGEO_PIPELINE_REPORT_TABLES_H_

#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "pipeline/report_data.h"

namespace zebrageo {
namespace report_internal {

// A column header from a report.json key: words, and the unit its suffix
// names in brackets ("rmse_horizontal_m" -> "RMSE horizontal (m)").
std::string HumanKey(const std::string& key);
// A key's stem and the unit its suffix names ("max_3d_m" -> "max_3d", "m");
// no unit: the key and "".
std::pair<std::string, std::string> SplitUnit(const std::string& key);

// The comparison with the input trajectory (report.json adjustment.guard
// crossings): per crossing, both misfits in cm and the evidence in sd.
std::string GuardTable(const nlohmann::json& crossings);

// Control and check points side by side: crossings, vertices, RMSE
// horizontal, vertical and 3D and the largest residual, in cm.
std::string AccuracyTable(const nlohmann::json& gcp);

// One row per control, check or rejected point: crossing, band, vertex,
// residual east, north, up in cm, its images and their RMS in px.
std::string GcpTable(const ReportData& data);

// Reprojection of the control and check points per camera and per
// exposure (RMS, median, 95th percentile, worst, in px), with histograms.
std::string CameraResidualSection(const ReportData& data);

// The RMS of each observation type before and after the adjustment: a
// table, and one bar chart per unit (px, m, deg: never two in one chart).
std::string ObservationRmsSection(const nlohmann::json& adjustment);

// The coordinate systems of the outputs and of the report's figures.
std::string CrsParagraph(const ReportData& data, const nlohmann::json& report);

}  // namespace report_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_REPORT_TABLES_H_
