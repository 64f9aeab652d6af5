// The stage outputs of one results folder, passed from stage to stage in
// memory (the results contract's types, survey/results*.h).
//
// A stage that runs in this process writes its files through the contract
// and leaves what it wrote here, so the next stage does not read it back.
// What an earlier run (a resumed `zebrageo run`) or another command
// (`zebrageo match` after `zebrageo reconstruct`) wrote is read from the
// folder, through the same readers, on first use. The contract writes every
// double exactly (survey/csv.h), so a stage sees the same data either way:
// a resumed run gives the results of an uninterrupted one.
#ifndef ZEBRAGEO_PIPELINE_STAGE_RESULTS_H_
#define ZEBRAGEO_PIPELINE_STAGE_RESULTS_H_

#include <optional>
#include <string>
#include <vector>

#include "survey/results.h"
#include "survey/results_adjustment.h"
#include "survey/results_lines.h"
#include "survey/trajectory.h"

namespace zebrageo {

class StageResults {
 public:
  // `survey_identity` (survey/results_survey.h): the survey the stage
  // files read from the folder must belong to (InputError naming the file
  // otherwise); "" reads them unchecked.
  explicit StageResults(std::string folder, std::string survey_identity = "");

  const std::string& folder() const { return folder_; }
  // folder/name.
  std::string PathOf(const char* name) const;

  // reconstructed_bands.csv. Throws InputError when absent (naming the
  // command to run first) or malformed.
  const std::vector<ReconstructedVertex>& Vertices();
  // skipped_exposures.csv; empty when absent (results of an older version).
  const std::vector<SkippedExposure>& SkippedExposures();
  // reconstructed_lines.csv; null when absent (reconstructed without lines).
  const std::vector<ReconstructedLinePoint>* LinePoints();
  // matches.csv. Throws InputError when absent or malformed.
  const std::vector<VertexMatch>& Matches();
  // crossing_decisions.csv; empty when absent.
  const std::vector<CrossingDecision>& Decisions();
  // trajectory_corrected.csv. Throws InputError when absent or malformed.
  const std::vector<TrajectorySample>& CorrectedTrajectory();
  // adjustment.json; null when absent or unreadable (the second
  // registration pass says why it does not run).
  const AdjustmentRecord* Adjustment();

  // What a stage of this process wrote.
  void SetReconstruction(std::vector<ReconstructedVertex> vertices,
                         std::vector<SkippedExposure> skipped);
  void SetLinePoints(std::vector<ReconstructedLinePoint> points);
  void SetMatches(std::vector<VertexMatch> matches,
                  std::vector<CrossingDecision> decisions);
  void SetAdjustment(std::vector<TrajectorySample> corrected,
                     AdjustmentRecord record);

 private:
  // `path`, checked to belong to the survey.
  std::string SurveyFile(const std::string& path) const;

  std::string folder_;
  std::string survey_identity_;
  std::optional<std::vector<ReconstructedVertex>> vertices_;
  std::optional<std::vector<SkippedExposure>> skipped_;
  // Outer optional: looked up; inner: the file exists.
  std::optional<std::optional<std::vector<ReconstructedLinePoint>>> lines_;
  std::optional<std::vector<VertexMatch>> matches_;
  std::optional<std::vector<CrossingDecision>> decisions_;
  std::optional<std::vector<TrajectorySample>> corrected_;
  std::optional<std::optional<AdjustmentRecord>> adjustment_;
};

// Throws InputError naming the first stage file of `folder` that belongs
// to a survey other than `survey_identity`'s (`zebrageo report`, which
// reads them all).
void CheckStageFilesBelongTo(const std::string& folder,
                             const std::string& survey_identity);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_STAGE_RESULTS_H_
