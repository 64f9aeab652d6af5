#include "pipeline/stage_results.h"

#include <Eigen/Core>
#include <filesystem>
#include <utility>

#include "survey/input_error.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

bool IsFile(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// A covariance as its file holds it: the writers keep the upper triangle,
// the readers mirror it. A product J C J^T may differ across the diagonal
// in its last bits; mirrored, a stage sees the same matrix whether it was
// handed over in memory or read back by a resumed run.
void MirrorUpperTriangle(Eigen::Matrix3d* c) {
  *c = c->selfadjointView<Eigen::Upper>();
}

}  // namespace

StageResults::StageResults(std::string folder, std::string survey_identity)
    : folder_(std::move(folder)),
      survey_identity_(std::move(survey_identity)) {}

std::string StageResults::SurveyFile(const std::string& path) const {
  CheckStageFileSurvey(path, survey_identity_);
  return path;
}

std::string StageResults::PathOf(const char* name) const {
  return (fs::path(folder_) / name).string();
}

namespace {

// The path of a stage file the caller cannot do without; InputError naming
// the command that writes it when absent.
std::string RequiredFile(const StageResults& results, const char* name,
                         const char* command) {
  const std::string path = results.PathOf(name);
  if (!IsFile(path)) {
    throw InputError(name, 0,
                     "not found in " + results.folder() + ": run `zebrageo " +
                         command + "` first");
  }
  return path;
}

}  // namespace

const std::vector<ReconstructedVertex>& StageResults::Vertices() {
  if (!vertices_) {
    vertices_ = ReadReconstructedBands(
        SurveyFile(RequiredFile(*this, kReconstructedBandsFile, "reconstruct")),
        kReconstructedBandsFile);
  }
  return *vertices_;
}

const std::vector<SkippedExposure>& StageResults::SkippedExposures() {
  if (!skipped_) {
    const std::string path = PathOf(kSkippedExposuresFile);
    skipped_ = IsFile(path) ? ReadSkippedExposures(path, kSkippedExposuresFile)
                            : std::vector<SkippedExposure>();
  }
  return *skipped_;
}

const std::vector<ReconstructedLinePoint>* StageResults::LinePoints() {
  if (!lines_) {
    const std::string path = PathOf(kReconstructedLinesFile);
    lines_.emplace();
    if (IsFile(path)) {
      *lines_ =
          ReadReconstructedLines(SurveyFile(path), kReconstructedLinesFile);
    }
  }
  return lines_->has_value() ? &**lines_ : nullptr;
}

const std::vector<VertexMatch>& StageResults::Matches() {
  if (!matches_) {
    matches_ = ReadMatches(
        SurveyFile(RequiredFile(*this, kMatchesFile, "match")), kMatchesFile);
  }
  return *matches_;
}

const std::vector<CrossingDecision>& StageResults::Decisions() {
  if (!decisions_) {
    const std::string path = PathOf(kCrossingDecisionsFile);
    decisions_ = IsFile(path) ? ReadCrossingDecisions(SurveyFile(path),
                                                      kCrossingDecisionsFile)
                              : std::vector<CrossingDecision>();
  }
  return *decisions_;
}

const std::vector<TrajectorySample>& StageResults::CorrectedTrajectory() {
  if (!corrected_) {
    corrected_ = ReadTrajectorySamples(
        RequiredFile(*this, kTrajectoryCorrectedFile, "adjust"),
        kTrajectoryCorrectedFile);
  }
  return *corrected_;
}

const AdjustmentRecord* StageResults::Adjustment() {
  if (!adjustment_) {
    adjustment_.emplace();
    const std::string path = PathOf(kAdjustmentJsonFile);
    if (IsFile(path)) {
      try {
        *adjustment_ = ReadAdjustmentRecord(path, kAdjustmentJsonFile);
      } catch (const InputError&) {
        // Unreadable: as absent (the callers say the record is missing).
      }
    }
  }
  return adjustment_->has_value() ? &**adjustment_ : nullptr;
}

void CheckStageFilesBelongTo(const std::string& folder,
                             const std::string& survey_identity) {
  for (const char* name : {kReconstructedBandsFile, kReconstructedLinesFile,
                           kMatchesFile, kCrossingDecisionsFile}) {
    const std::string path = (fs::path(folder) / name).string();
    if (IsFile(path)) CheckStageFileSurvey(path, survey_identity);
  }
}

void StageResults::SetReconstruction(std::vector<ReconstructedVertex> vertices,
                                     std::vector<SkippedExposure> skipped) {
  for (ReconstructedVertex& v : vertices) {
    MirrorUpperTriangle(&v.covariance_body);
  }
  vertices_ = std::move(vertices);
  skipped_ = std::move(skipped);
}

void StageResults::SetLinePoints(std::vector<ReconstructedLinePoint> points) {
  for (ReconstructedLinePoint& p : points) {
    MirrorUpperTriangle(&p.covariance_body);
  }
  lines_.emplace(std::move(points));
}

void StageResults::SetMatches(std::vector<VertexMatch> matches,
                              std::vector<CrossingDecision> decisions) {
  matches_ = std::move(matches);
  decisions_ = std::move(decisions);
}

void StageResults::SetAdjustment(std::vector<TrajectorySample> corrected,
                                 AdjustmentRecord record) {
  corrected_ = std::move(corrected);
  adjustment_.emplace(std::move(record));
}

}  // namespace zebrageo
