// The second registration pass (registration/rematch.h) as the pipeline
// runs it: a step of the adjust stage (`zebrageo run`, in memory, after
// each adjustment) and `zebrageo match --second-pass` (after `zebrageo
// adjust`, from the results folder), both through RematchStep.
//
// With too few crossings in the adjustment to trust its error model, the
// pass searches on the trajectory the road lines alone correct: they hold
// the cross-track position, across which a zebra's band offsets lie,
// whatever the crossings' error model. When that adds nothing, it searches
// on the adjustment's own trajectory near the line points it fits
// (RematchInput::across_from_fitted_lines): the lines matched on the
// trajectory the crossings corrected are more than the lines alone could
// place (geometry sweep 1-500: crossings matched 89.9 -> 93.7 %, 0 wrong).
#ifndef ZEBRAGEO_PIPELINE_REMATCH_STAGE_H_
#define ZEBRAGEO_PIPELINE_REMATCH_STAGE_H_

#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pipeline/run_options.h"
#include "pipeline/stage_results.h"
#include "registration/rematch.h"
#include "survey/cancellation.h"
#include "survey/results_adjustment.h"
#include "survey/results_lines.h"
#include "survey/survey.h"

namespace zebrageo {

// The adjustment the pass searches with. Pointers, not owned.
struct AdjustedTrajectory {
  // adjustment.json's record; null: none (the pass is skipped).
  const AdjustmentRecord* record = nullptr;
  // trajectory_corrected.csv's samples.
  const std::vector<TrajectorySample>* trajectory = nullptr;
  // The times of the road-line points that held the cross-track position
  // (line_matches.csv's, RematchInput::line_control_times).
  std::vector<double> line_control_times;
  // Of them, those the adjusted trajectory fits (RematchInput::
  // across_from_fitted_lines): known in the adjustment's process only; the
  // search near them is not made without.
  std::optional<std::vector<double>> fitted_line_times;
  // Crossings the adjustment rejected (gcp_residuals.csv's rejected).
  std::set<std::string> rejected_crossings;
};

// The pass on the control so far. Writes nothing. `paint_probe`: what the
// images show where a database band is predicted (MatchInput::paint_probe);
// empty: the survey's images (ImagePaintProbe, RunOptions::paint_probe).
RematchSummary RematchStep(
    const Survey& survey, const RunOptions& options,
    const AdjustedTrajectory& adjusted,
    const std::vector<ReconstructedVertex>& vertices,
    const std::vector<VertexMatch>& matches,
    const std::vector<CrossingDecision>& decisions,
    const std::vector<ReconstructedLinePoint>* lines,
    const CancellationToken& cancel = {},
    const decltype(MatchInput::paint_probe)& paint_probe = {});

// `zebrageo match --second-pass`: the pass on the results folder's files
// (adjustment.json, trajectory_corrected.csv, line_matches.csv,
// gcp_residuals.csv, matches.csv, crossing_decisions.csv,
// reconstructed_bands.csv and reconstructed_lines.csv), matches.csv and
// crossing_decisions.csv rewritten when it changed them. Throws InputError
// for unreadable inputs.
RematchSummary RunRematchStage(const Survey& survey, StageResults* results,
                               const RunOptions& options,
                               const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_REMATCH_STAGE_H_
