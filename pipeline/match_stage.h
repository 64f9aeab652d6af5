// The match stage (SURVEY_FORMAT.md "Stage outputs"): the reconstruction's
// bands grouped into observations (registration/observations.h), matched to
// the survey's road-mark database (registration/band_matcher.h), the images
// probed for paint where a database band was not seen
// (registration/paint_probe.h). Writes, each once and atomically:
//   matches.csv             reconstructed vertex <-> database vertex
//   crossing_decisions.csv  one row per (exposure, group): matched, refused
//                           or no_candidate, and why
//   match_evidence.json     the evidence behind each decision, the database
//                           faults found, the options and the summary
//   matches.geojson         the vertex matches as lines, for QGIS
//   matched_bands.geojson   the matched bands corrected, as polygons
//   database_faults.geojson the database faults found, as points
// (survey/results.h, survey/results_match.h).
#ifndef ZEBRAGEO_PIPELINE_MATCH_STAGE_H_
#define ZEBRAGEO_PIPELINE_MATCH_STAGE_H_

#include <functional>

#include "pipeline/run_options.h"
#include "pipeline/stage_results.h"
#include "survey/cancellation.h"
#include "survey/results_match.h"
#include "survey/survey.h"

namespace zebrageo {

// Reads the bands from `results` (reconstructed_bands.csv when this
// process did not reconstruct them), leaves the matches there. Returns the
// matcher's summary. Throws InputError for inconsistent inputs,
// StageFailedError when the matcher cannot run (bad options),
// CancelledError.
MatchSummary RunMatchStage(const Survey& survey, StageResults* results,
                           const RunOptions& options,
                           const std::function<void(int, int)>& progress = {},
                           const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_MATCH_STAGE_H_
