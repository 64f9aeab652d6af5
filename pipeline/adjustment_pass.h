// One adjustment of the adjust stage (pipeline/adjust_stage.h), in memory,
// in named steps:
//   adjust             the trajectory with the zebra crossings as control
//                      (adjustment/trajectory_adjuster.h)
//   road lines         the reconstructed road lines, dashes and crossing
//                      edges registered to the database on that trajectory
//                      (registration/line_registration.h)
//   adjust with lines  the adjustment again, with them as control
// and the trial the second registration pass may search on instead: the
// trajectory the road lines alone correct.
#ifndef ZEBRAGEO_PIPELINE_ADJUSTMENT_PASS_H_
#define ZEBRAGEO_PIPELINE_ADJUSTMENT_PASS_H_

#include <optional>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "pipeline/progress.h"
#include "registration/line_registration.h"
#include "registration/rematch.h"
#include "survey/cancellation.h"
#include "survey/results_adjustment.h"
#include "survey/results_lines.h"
#include "survey/survey.h"
#include "survey/tie_tracks.h"

namespace zebrageo {

// The survey as the adjustment reads it, with the reconstruction's bands
// and the control (the registration's vertex matches).
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

// From a survey already loaded and the stage outputs in memory (what
// reconstructed_bands.csv and matches.csv hold).
AdjustmentData AdjustmentDataOf(const Survey& survey,
                                std::vector<ReconstructedVertex> vertices,
                                std::vector<VertexMatch> matches);

// The same read from a survey folder without requiring its images (a
// geometry-only survey is adjustable; images only feed the tie points) and
// the results folder's reconstructed_bands.csv and matches.csv. Throws
// InputError: any survey file the readers reject, exposures outside the
// trajectory, a missing or malformed stage output (the message says which
// stage to run first).
AdjustmentData LoadAdjustmentData(const std::string& survey_folder,
                                  const std::string& results_folder,
                                  const SurveyPathOptions& paths = {});

// What the road lines' registration reads on `result`'s trajectory: the
// database, frame, exposures and zebra matches of `data`, the database sigma
// floor and logging of `options`. Pointers into `data` and `result`.
LineRegistrationInput LineRegistrationInputOf(const AdjustmentData& data,
                                              const AdjustmentOptions& options,
                                              const AdjustmentResult& result);

// What one adjustment gives: its result and, with road lines, their
// registration.
struct AdjustmentPass {
  AdjustmentResult result;
  // The registration of the last adjustment's trajectory (none without
  // line points or when the zebra adjustment was not usable).
  std::optional<LineRegistration> lines;
  // The times of its control points that held the cross-track position
  // (RematchInput::line_control_times), and of them those the returned
  // trajectory fits across their line within kFittedLineResidualM
  // (RematchInput::across_from_fitted_lines).
  std::vector<double> line_control_times;
  std::vector<double> fitted_line_times;
};
inline constexpr double kFittedLineResidualM = 0.1;

// The adjustment of `input` (zebra control), then, with `line_points`,
// again with the road lines registered on its trajectory. Progress steps
// "adjust" and "adjust with lines"; `progress` may be empty.
AdjustmentPass AdjustWithRoadLines(
    const AdjustmentData& data, AdjustmentInput input,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const std::vector<ReconstructedLinePoint>* line_points,
    const ProgressListener& progress = {},
    const CancellationToken& cancel = {});

// Whether the second registration pass should search on the trajectory the
// road lines alone correct (AdjustByRoadLinesAlone) rather than on the
// adjustment's (`record`): with road lines, an adjustment that had too few
// crossings to trust its error model (RematchOptions::
// min_control_crossings: the pass would be skipped) and observations left
// undecided.
bool SecondPassOnRoadLines(const AdjustmentRecord& record,
                           const std::vector<CrossingDecision>& decisions,
                           bool lines, const RematchOptions& rematch);

// The trajectory of `data` corrected by the road lines alone (its zebra
// matches left out: adjustment.json's road_lines_only), and what
// adjustment.json would hold of it; nullopt without line points or when
// no line could be control. A trial: its warnings are not logged.
struct RoadLinesAdjustment {
  std::vector<TrajectorySample> trajectory;
  AdjustmentRecord record;
  // Where the lines held the cross-track position (RematchInput::
  // line_control_times).
  std::vector<double> line_control_times;
};
std::optional<RoadLinesAdjustment> AdjustByRoadLinesAlone(
    const AdjustmentData& data,
    const std::vector<ReconstructedLinePoint>* line_points,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_ADJUSTMENT_PASS_H_
