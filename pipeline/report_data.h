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

// One image observation of a control or check point, reprojected: the
// point's adjusted position (database vertex plus its residual) through the
// adjusted camera pose of poses.csv into the camera, against where the
// reconstruction measured it (reconstructed_bands.csv, distorted pixels).
struct ImageResidual {
  std::string camera;
  int64_t exposure_id = 0;
  GcpRole role = GcpRole::kControl;
  double error_px = 0.0;  // |projected - measured|, both axes
};

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
  // Reprojection of the control and check points (empty without
  // poses.csv, matches.csv or reconstructed_bands.csv).
  std::vector<ImageResidual> image_residuals;
  // The output CRS (survey.yaml's output_crs; empty: WGS84 only) and
  // PROJ's description of it ("" when PROJ cannot build it).
  std::string output_crs;
  std::string output_crs_description;
};

// Reads the results folder's files (typed, through survey/results*.h).
// Throws InputError when a present file is malformed.
ReportData Collect(const ReportInputs& inputs);

// The image residuals of the control and check points (ImageResidual).
std::vector<ImageResidual> ReprojectControl(
    const Survey& survey, const std::vector<GcpResidual>& residuals,
    const std::vector<VertexMatch>& matches,
    const std::vector<ReconstructedVertex>& vertices,
    const std::vector<CameraPose>& poses);

// The page of report.html.
std::string RenderHtml(const nlohmann::json& report, const ReportData& data);

}  // namespace report_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_REPORT_DATA_H_
