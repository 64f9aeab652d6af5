// What `zebrageo adjust` reads and writes (SURVEY_FORMAT.md "Outputs").
//
// Reads the survey without requiring its images (a geometry-only survey is
// adjustable; images only feed the tie points), plus RESULTS/
// reconstructed_bands.csv and RESULTS/matches.csv. Writes, each atomically:
//   trajectory_corrected.csv  the input's columns and times, corrected
//   poses.csv                 one row per exposures.csv row
//   gcp_residuals.csv         the contract's columns, then status
//                             (control|check|rejected) and
//                             normalized_residual
//   bands.geojson             reconstructed bands placed with the corrected
//                             trajectory
//   adjustment.json           the adjustment's part of report.json
//   report.json               a minimal report with the same figures (the
//                             report stage replaces it with the full one)
//   colmap/cameras.txt, images.txt, points3D.txt
//                             COLMAP text model of the adjusted cameras:
//                             world = the survey's ENU frame, one
//                             FULL_OPENCV camera per rig camera (COLMAP's
//                             pixel centres are at +0.5: cx, cy and the 2D
//                             points are shifted by 0.5), points = control
//                             and tie points with their tracks.
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_IO_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_IO_H_

#include <set>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "survey/results_adjustment.h"
#include "survey/survey.h"
#include "survey/tie_tracks.h"

namespace zebrageo {

inline constexpr char kColmapFolder[] = "colmap";

struct AdjustmentData {
  std::string survey_folder;
  SurveyManifest manifest;
  Rig rig;
  LocalFrame frame{Geodetic{}};
  Trajectory trajectory;
  ExposureTable exposures;
  RoadmarkDatabase roadmarks;
  std::vector<ReconstructedVertex> vertices;
  std::vector<VertexMatch> matches;
  // Images named in exposures.csv that are not on disk.
  int missing_images = 0;
  std::vector<std::string> warnings;

  AdjustmentInput Input() const;
};

// Throws InputError: any survey file the readers reject (survey.yaml's
// files confined to the survey folder as `paths` says), exposures outside
// the trajectory, a missing or malformed reconstructed_bands.csv or
// matches.csv (the message says which stage to run first).
AdjustmentData LoadAdjustmentData(const std::string& survey_folder,
                                  const std::string& results_folder,
                                  const SurveyPathOptions& paths = {});
// The same from a survey already loaded (LoadSurvey reads its files as
// LoadAdjustmentData does) and the stage outputs in memory (what
// reconstructed_bands.csv and matches.csv hold).
AdjustmentData AdjustmentDataOf(const Survey& survey,
                                std::vector<ReconstructedVertex> vertices,
                                std::vector<VertexMatch> matches);

// What adjustment.json holds of `result` (WriteAdjustmentResults writes
// it); `ties` may be null (no tie points).
AdjustmentRecord AdjustmentRecordOf(const AdjustmentData& data,
                                    const AdjustmentOptions& options,
                                    const AdjustmentResult& result,
                                    const TiePointSummary* ties);

// Writes every output listed above into `results_folder` (created if
// needed). `tie_summary` may be null (no tie points). Throws
// std::runtime_error when a file cannot be written. Returns what
// adjustment.json holds.
AdjustmentRecord WriteAdjustmentResults(const AdjustmentData& data,
                                        const AdjustmentOptions& options,
                                        const AdjustmentResult& result,
                                        const TiePointSummary* tie_summary,
                                        const std::string& results_folder);

// The vertex matches of `matches` that the adjustment did not reject: what
// matches.csv keeps (below), and what a user's control is made of.
std::vector<VertexMatch> MatchesKeptAsControl(
    const std::vector<VertexMatch>& matches, const AdjustmentResult& result);

// The crossings with a control point the adjustment rejected.
std::set<std::string> RejectedCrossings(const AdjustmentResult& result);

// matches.csv holds the vertices that became control points
// (SURVEY_FORMAT.md): the ones the adjustment rejected (a crossing
// inconsistent with the others, matched one band off; a blunder) are
// removed from it, and an observation left without any is refused in
// crossing_decisions.csv, with the reason. Both rewritten atomically, only
// when something was rejected. Returns the number of vertex matches
// removed.
// *matches and *decisions (the stage outputs in memory; decisions empty:
// none to rewrite) are updated as the files.
int RemoveRejectedMatches(const AdjustmentResult& result,
                          const std::string& results_folder,
                          std::vector<VertexMatch>* matches,
                          std::vector<CrossingDecision>* decisions);
// The same in memory only; *rejected_crossings: their ids, space-separated.
int RemoveRejectedMatches(const AdjustmentResult& result,
                          std::vector<VertexMatch>* matches,
                          std::vector<CrossingDecision>* decisions,
                          std::string* rejected_crossings);

// The gcp_residuals.csv rows of `points` (survey/results.h writes them).
std::vector<GcpResidual> GcpResidualsOf(
    const std::vector<ControlPointResult>& points);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_IO_H_
