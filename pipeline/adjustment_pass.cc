#include "pipeline/adjustment_pass.h"

#include <filesystem>
#include <utility>

#include "pipeline/adjust_outputs.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/line_control_points.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// The images named in exposures.csv that are not on disk: counted, and a
// warning (no tie points in them).
void CountMissingImages(AdjustmentData* data) {
  for (const ExposureImage& image : data->exposures.images) {
    std::error_code error;
    if (!fs::is_regular_file(fs::path(data->survey_folder) / image.image,
                             error)) {
      ++data->missing_images;
    }
  }
  if (data->missing_images > 0 &&
      data->missing_images < static_cast<int>(data->exposures.images.size())) {
    data->warnings.push_back(std::to_string(data->missing_images) + " of " +
                             std::to_string(data->exposures.images.size()) +
                             " images are missing: no tie points in them");
  }
}

// The road lines registered on `result`'s trajectory.
LineRegistration RegisterLines(
    const AdjustmentData& data, const AdjustmentOptions& options,
    const LineRegistrationOptions& registration, const AdjustmentResult& result,
    const std::vector<ReconstructedLinePoint>& line_points) {
  return RegisterRoadLines(line_points,
                           LineRegistrationInputOf(data, options, result),
                           registration);
}

// The path of a stage output `command` writes; InputError when absent.
std::string RequiredStageFile(const std::string& results_folder,
                              const char* name, const char* command) {
  const std::string path = (fs::path(results_folder) / name).string();
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    throw InputError(name, 0,
                     std::string("not found in ") + results_folder +
                         ": run `zebrageo " + command + "` first");
  }
  return path;
}

}  // namespace

LineRegistrationInput LineRegistrationInputOf(const AdjustmentData& data,
                                              const AdjustmentOptions& options,
                                              const AdjustmentResult& result) {
  LineRegistrationInput input;
  input.roadmarks = &data.roadmarks;
  input.frame = &data.frame;
  input.exposures = &data.exposures;
  input.vertices = &data.vertices;
  input.matches = &data.matches;
  input.trajectory = {&result.corrected_samples, &result.corrected_poses,
                      result.summary.corrected};
  input.min_database_sigma_m = options.control.min_database_sigma_m;
  input.log_warnings = options.log_warnings;
  return input;
}

AdjustmentInput AdjustmentData::Input() const {
  AdjustmentInput input;
  input.rig = &rig;
  input.frame = &frame;
  input.trajectory = &trajectory;
  input.exposures = &exposures;
  input.roadmarks = &roadmarks;
  input.vertices = &vertices;
  input.matches = &matches;
  return input;
}

AdjustmentData AdjustmentDataOf(const Survey& survey,
                                std::vector<ReconstructedVertex> vertices,
                                std::vector<VertexMatch> matches) {
  AdjustmentData data;
  data.survey_folder = survey.folder;
  data.manifest = survey.manifest;
  data.rig = survey.rig;
  data.frame = survey.frame;
  data.trajectory = survey.trajectory;
  data.exposures = survey.exposures;
  data.roadmarks = survey.roadmarks;
  CountMissingImages(&data);
  data.vertices = std::move(vertices);
  data.matches = std::move(matches);
  return data;
}

AdjustmentData LoadAdjustmentData(const std::string& survey_folder,
                                  const std::string& results_folder,
                                  const SurveyPathOptions& paths) {
  AdjustmentData data;
  data.survey_folder = survey_folder;
  data.manifest = ReadManifest(survey_folder, paths);
  auto path_of = [&](const std::string& name) {
    return (fs::path(survey_folder) / name).string();
  };
  data.rig = ReadRig(path_of(data.manifest.rig), data.manifest.rig);
  std::vector<TrajectorySample> samples =
      ReadSurveyTrajectory(survey_folder, data.manifest);
  data.frame =
      LocalFrame(data.manifest.origin.value_or(samples.front().position));
  data.trajectory = Trajectory(std::move(samples), data.frame);
  data.exposures = ReadExposures(path_of(data.manifest.exposures),
                                 data.manifest.exposures, data.rig);
  for (const ExposureImage& image : data.exposures.images) {
    if (!data.trajectory.Covers(image.time)) {
      throw InputError(data.manifest.exposures, image.line,
                       "exposure " + std::to_string(image.exposure_id) +
                           " at time " + FormatDouble(image.time) +
                           " is outside the trajectory's span");
    }
  }
  data.roadmarks = ReadSurveyRoadmarks(survey_folder, data.manifest,
                                       data.trajectory.samples());
  CountMissingImages(&data);
  const std::string identity = SurveyIdentity(data.exposures);
  const std::string bands_path =
      RequiredStageFile(results_folder, kReconstructedBandsFile, "reconstruct");
  CheckStageFileSurvey(bands_path, identity);
  data.vertices = ReadReconstructedBands(bands_path, kReconstructedBandsFile);
  const std::string matches_path =
      RequiredStageFile(results_folder, kMatchesFile, "match");
  CheckStageFileSurvey(matches_path, identity);
  data.matches = ReadMatches(matches_path, kMatchesFile);
  return data;
}

AdjustmentPass AdjustWithRoadLines(
    const AdjustmentData& data, AdjustmentInput input,
    const AdjustmentOptions& options,
    const LineRegistrationOptions& registration,
    const std::vector<ReconstructedLinePoint>* line_points,
    const ProgressListener& progress, const CancellationToken& cancel) {
  AdjustmentPass pass;
  StepProgress step(progress, "adjust");
  pass.result = AdjustTrajectory(options, input, step.Callback(), cancel);
  step.Finish();
  if (line_points == nullptr || !pass.result.summary.IsUsable()) return pass;
  cancel.ThrowIfCancelled();
  pass.lines =
      RegisterLines(data, options, registration, pass.result, *line_points);
  const std::vector<LineControlPoint>& control = pass.lines->control;
  if (control.empty()) return pass;
  pass.line_control_times = CrossTrackTimes(control);
  input.line_points = &control;
  StepProgress line_step(progress, "adjust with lines");
  pass.result = AdjustTrajectory(options, input, line_step.Callback(), cancel);
  line_step.Finish();
  if (pass.result.summary.IsUsable()) {
    const CorrectedTrajectory corrected{&pass.result.corrected_samples,
                                        &pass.result.corrected_poses,
                                        pass.result.summary.corrected};
    pass.fitted_line_times =
        FittedCrossTrackTimes(control, corrected, kFittedLineResidualM);
  }
  return pass;
}

bool SecondPassOnRoadLines(const AdjustmentRecord& record,
                           const std::vector<CrossingDecision>& decisions,
                           bool lines, const RematchOptions& rematch) {
  if (!lines || record.road_lines_only) return false;
  const int crossings =
      record.counts.control_crossings + record.counts.check_crossings;
  if (crossings >= rematch.min_control_crossings) return false;
  for (const CrossingDecision& d : decisions) {
    if (d.decision != Decision::kMatched) return true;
  }
  return false;
}

std::optional<RoadLinesAdjustment> AdjustByRoadLinesAlone(
    const AdjustmentData& data,
    const std::vector<ReconstructedLinePoint>* line_points,
    const AdjustmentOptions& user_options,
    const LineRegistrationOptions& registration,
    const CancellationToken& cancel) {
  if (line_points == nullptr || line_points->empty() ||
      !user_options.road_lines.line_control_without_crossings) {
    return std::nullopt;
  }
  AdjustmentOptions options = user_options;
  options.log_warnings = false;  // a trial: the user gets another result
  AdjustmentInput input = data.Input();
  const std::vector<VertexMatch> no_matches;
  input.matches = &no_matches;
  // Without control the first adjustment keeps the input trajectory; the
  // lines are then placed by the cross-track offsets they agree on.
  AdjustmentPass pass = AdjustWithRoadLines(data, input, options, registration,
                                            line_points, {}, cancel);
  if (!pass.result.summary.IsUsable() ||
      !pass.result.summary.line_control_only) {
    return std::nullopt;
  }
  RoadLinesAdjustment out;
  out.line_control_times = std::move(pass.line_control_times);
  out.record = AdjustmentRecordOf(data, options, pass.result, nullptr);
  out.trajectory = std::move(pass.result.corrected_samples);
  return out;
}

}  // namespace zebrageo
