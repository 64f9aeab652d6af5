// Stage outputs of a results folder (SURVEY_FORMAT.md, "Outputs" and "Stage
// outputs"): plain structs, and one reader and one writer per file. Writers
// are atomic (temporary name, then rename). Readers throw InputError like
// every survey reader, so a stage can be run alone on another stage's files.
#ifndef ZEBRAGEO_SURVEY_RESULTS_H_
#define ZEBRAGEO_SURVEY_RESULTS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "survey/geodesy.h"

namespace zebrageo {

class OutputCrs;

// File names inside a results folder.
inline constexpr char kReconstructedBandsFile[] = "reconstructed_bands.csv";
inline constexpr char kMatchesFile[] = "matches.csv";
inline constexpr char kCrossingDecisionsFile[] = "crossing_decisions.csv";
inline constexpr char kTrajectoryCorrectedFile[] = "trajectory_corrected.csv";
inline constexpr char kPosesFile[] = "poses.csv";
inline constexpr char kBandsGeoJsonFile[] = "bands.geojson";
inline constexpr char kGcpResidualsFile[] = "gcp_residuals.csv";
inline constexpr char kReportJsonFile[] = "report.json";
inline constexpr char kReportHtmlFile[] = "report.html";
inline constexpr char kSkippedExposuresFile[] = "skipped_exposures.csv";

// reconstructed_bands.csv: one row per band vertex seen in one stereo pair.
struct ReconstructedVertex {
  int64_t exposure_id = 0;
  int pair = 0;          // index in Rig::stereo_pairs
  int64_t band_id = 0;   // unique within the file
  int64_t group_id = 0;  // the crossing the band was grouped into
  int vertex = 0;        // 0..3 around the band
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();  // metres, body frame
  Eigen::Matrix3d covariance_body = Eigen::Matrix3d::Zero();  // m^2
  Eigen::Vector2d uv_left = Eigen::Vector2d::Zero();  // distorted image px
  Eigen::Vector2d uv_right = Eigen::Vector2d::Zero();
  double score = 0.0;  // 0..1
  // What placed the vertex's end of the band (issue 52; an extra trailing
  // column): "paint_end" (its own edge), "ladder_bar" (a ladder bar's inner
  // edge) or "crossing_line" (the line of its crossing's other ends).
  std::string end_evidence = "paint_end";
};
void WriteReconstructedBands(const std::vector<ReconstructedVertex>& vertices,
                             const std::vector<std::string>& comments,
                             const std::string& path);
std::vector<ReconstructedVertex> ReadReconstructedBands(
    const std::string& path, const std::string& display_name);

// matches.csv: a reconstructed band vertex that became a control point.
struct VertexMatch {
  int64_t exposure_id = 0;
  int64_t band_id = 0;
  int vertex = 0;
  std::string crossing_id;
  int band = 0;       // 1-based band of the database crossing
  int db_vertex = 0;  // index 0..3 in the database polygon's ring
};
// With `crs` (survey/output_crs.h): columns crs_x, crs_y, crs_z of the
// matched database vertex.
void WriteMatches(const std::vector<VertexMatch>& matches,
                  const std::vector<std::string>& comments,
                  const std::string& path, const OutputCrs* crs = nullptr);
std::vector<VertexMatch> ReadMatches(const std::string& path,
                                     const std::string& display_name);

// crossing_decisions.csv: one row per reconstructed crossing group and
// exposure.
enum class Decision { kMatched, kRefused, kNoCandidate };
const char* DecisionName(Decision decision);  // matched|refused|no_candidate
struct CrossingDecision {
  int64_t exposure_id = 0;
  int64_t group_id = 0;
  Decision decision = Decision::kNoCandidate;
  std::string crossing_id;  // empty unless matched
  std::string reason;       // free text, commas replaced by ';'
};
void WriteCrossingDecisions(const std::vector<CrossingDecision>& decisions,
                            const std::vector<std::string>& comments,
                            const std::string& path);
std::vector<CrossingDecision> ReadCrossingDecisions(
    const std::string& path, const std::string& display_name);

// skipped_exposures.csv (written by reconstruct): the exposures whose
// images could not be read (missing, undecodable, the wrong size). They get
// no row in poses.csv: SURVEY_FORMAT.md lets only those be left out.
struct SkippedExposure {
  int64_t exposure_id = 0;
  std::string reason;  // free text, commas replaced by ';'
};
void WriteSkippedExposures(const std::vector<SkippedExposure>& skipped,
                           const std::string& path);
std::vector<SkippedExposure> ReadSkippedExposures(
    const std::string& path, const std::string& display_name);

// poses.csv: one row per image, the camera's projection centre and the
// camera-to-ENU rotation (Hamilton, written w, x, y, z).
struct CameraPose {
  int64_t exposure_id = 0;
  std::string camera;
  double time = 0.0;
  Geodetic position;
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_enu_cam = Eigen::Quaterniond::Identity();
};
// With `crs`: columns crs_x, crs_y, crs_z of lat, lon, h.
void WriteCameraPoses(const std::vector<CameraPose>& poses,
                      const std::string& path, const OutputCrs* crs = nullptr);
std::vector<CameraPose> ReadCameraPoses(const std::string& path,
                                        const std::string& display_name);

// gcp_residuals.csv: adjusted (control) or image-only (check, rejected)
// minus database, metres, ENU; written with 0.1 mm, 0.001 px and 0.01
// (normalized residual) resolution.
enum class GcpRole { kControl, kCheck };
// control | check | rejected (a blunder, removed from the adjustment).
enum class GcpStatus { kControl, kCheck, kRejected };
const char* GcpStatusName(GcpStatus status);
struct GcpResidual {
  std::string crossing_id;
  int band = 0;
  int vertex = 0;  // db_vertex
  GcpRole role = GcpRole::kControl;
  Eigen::Vector3d d_enu = Eigen::Vector3d::Zero();
  double rms_px = 0.0;
  int n_images = 0;
  // Files of older versions have no status column: the role's then.
  GcpStatus status = GcpStatus::kControl;
  double normalized_residual = 0.0;  // residual / its sd (blunder test)
};
// With `crs`: columns crs_x, crs_y, crs_z of the database vertex plus
// the written de, dn, du.
void WriteGcpResiduals(const std::vector<GcpResidual>& residuals,
                       const std::string& path, const OutputCrs* crs = nullptr);
std::vector<GcpResidual> ReadGcpResiduals(const std::string& path,
                                          const std::string& display_name);

// bands.geojson: reconstructed bands after adjustment.
struct AdjustedBand {
  std::array<Geodetic, 4> corners;
  std::optional<std::string> crossing_id;
  std::optional<int> band;
  int64_t band_id = 0;
  int64_t exposure_id = 0;
};
// With `crs`: coordinates in the output CRS and a top-level "crs" member.
void WriteAdjustedBands(const std::vector<AdjustedBand>& bands,
                        const std::string& path,
                        const OutputCrs* crs = nullptr);
// Reads bands.geojson back (scoring tools, tests). Throws InputError naming
// the line of a bad feature.
std::vector<AdjustedBand> ReadAdjustedBands(const std::string& path,
                                            const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_H_
