// What the adjust stage writes (pipeline/adjust_stage.h), from an
// adjustment's result: the records of the results files (survey/results*.h
// write them) and the control the adjustment kept.
#ifndef ZEBRAGEO_PIPELINE_ADJUST_OUTPUTS_H_
#define ZEBRAGEO_PIPELINE_ADJUST_OUTPUTS_H_

#include <set>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "pipeline/adjustment_pass.h"
#include "survey/colmap_model.h"
#include "survey/results.h"
#include "survey/results_adjustment.h"

namespace zebrageo {

inline constexpr char kColmapFolder[] = "colmap";

// adjustment.json's record of `result`; `ties` may be null (no tie points).
AdjustmentRecord AdjustmentRecordOf(const AdjustmentData& data,
                                    const AdjustmentOptions& options,
                                    const AdjustmentResult& result,
                                    const TiePointSummary* ties);

// gcp_residuals.csv's rows.
std::vector<GcpResidual> GcpResidualsOf(
    const std::vector<ControlPointResult>& points);

// The COLMAP text model of the adjusted cameras (colmap/): world = the
// survey's ENU frame, one FULL_OPENCV camera per rig camera (COLMAP's
// pixel centres are at +0.5: cx, cy and the 2D points are shifted by 0.5),
// points = control and tie points with their tracks.
ColmapModel ColmapModelOf(const AdjustmentData& data,
                          const AdjustmentResult& result);

// The vertex matches of `matches` that the adjustment did not reject: what
// matches.csv keeps, and what a user's control is made of.
std::vector<VertexMatch> MatchesKeptAsControl(
    const std::vector<VertexMatch>& matches, const AdjustmentResult& result);

// The crossings with a control point the adjustment rejected.
std::set<std::string> RejectedCrossings(const AdjustmentResult& result);

// matches.csv holds the vertices that became control points
// (SURVEY_FORMAT.md): the ones the adjustment rejected (a crossing
// inconsistent with the others, matched one band off; a blunder) are
// removed from *matches, and an observation left without any is refused in
// *decisions, with the reason. Returns the number of vertex matches
// removed; *rejected_crossings: their crossings, space-separated.
int RemoveRejectedMatches(const AdjustmentResult& result,
                          std::vector<VertexMatch>* matches,
                          std::vector<CrossingDecision>* decisions,
                          std::string* rejected_crossings);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_ADJUST_OUTPUTS_H_
