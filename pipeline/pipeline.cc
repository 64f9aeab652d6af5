#include "pipeline/pipeline.h"

#include <glog/logging.h>
#include <sys/resource.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/adjust_stage.h"
#include "pipeline/boresight_check.h"
#include "pipeline/exit_codes.h"
#include "pipeline/match_stage.h"
#include "pipeline/reconstruct_stage.h"
#include "pipeline/run_state.h"
#include "pipeline/stage_results.h"
#include "survey/results.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

double PeakMemoryMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

// The options a stage reads, as JSON, without those no result depends on
// (threads).
nlohmann::json ReconstructOptionsJson(const RunOptions& options) {
  nlohmann::json json = RunOptionsToJson(options);
  nlohmann::json read = {{"boresight", json["boresight"]},
                         {"lines", json["lines"]},
                         {"reconstruction", json["reconstruction"]},
                         {"road_lines", json["road_lines"]}};
  read["reconstruction"].erase("threads");
  read["boresight"].erase("attitude");  // read by the adjust stage
  return read;
}
nlohmann::json MatchOptionsJson(const RunOptions& options) {
  nlohmann::json json = RunOptionsToJson(options);
  return {{"matching", json["matching"]}, {"paint_probe", json["paint_probe"]}};
}
nlohmann::json AdjustOptionsJson(const RunOptions& options) {
  nlohmann::json json = RunOptionsToJson(options);
  nlohmann::json read;
  for (const char* key :
       {"tie_points", "lines", "rematch", "tie_point_matching",
        "line_registration", "adjustment", "second_pass", "paint_probe"}) {
    read[key] = json[key];
  }
  // The boresight's second look is made in the adjust stage.
  read["boresight_attitude"] = json["boresight"]["attitude"];
  read["adjustment"]["solver"].erase("num_threads");
  read["adjustment"]["solver"].erase("minimizer_progress_to_stdout");
  return read;
}

// What each stage's result depends on (pipeline/run_state.h): the survey
// files it reads, its options, and the stage before it.
std::vector<std::string> StageFingerprints(const Survey& survey,
                                           const RunOptions& options) {
  StageFingerprint reconstruct;
  reconstruct.Add("reconstruct").Add(ReconstructOptionsJson(options).dump());
  reconstruct.AddFileContents(survey.PathOf("survey.yaml"));
  for (const std::string* file :
       {&survey.manifest.rig, &survey.manifest.trajectory,
        &survey.manifest.exposures}) {
    reconstruct.AddFileContents(survey.PathOf(*file));
  }
  for (const ExposureImage& image : survey.exposures.images) {
    reconstruct.AddFileStamp(survey.PathOf(image.image));
  }
  StageFingerprint match;
  match.Add("match").Add(reconstruct.Hex());
  match.Add(MatchOptionsJson(options).dump());
  match.AddFileContents(survey.PathOf(survey.manifest.roadmarks));
  StageFingerprint adjust;
  adjust.Add("adjust").Add(match.Hex()).Add(AdjustOptionsJson(options).dump());
  return {reconstruct.Hex(), match.Hex(), adjust.Hex()};
}

}  // namespace

RunSummary RunSurveyPipeline(const Survey& input_survey,
                             const std::string& results_folder,
                             const RunOptions& requested_options,
                             const RunContext& context) {
  // This thread's lines, and those of the workers the stages start, go to
  // the run's own log too.
  const ScopedRunLog log_scope(context.log);
  const std::string problem = requested_options.Check();
  if (!problem.empty()) throw UsageError(problem);
  LOG(INFO) << "run: " << input_survey.folder << " -> " << results_folder;
  const ProgressListener& progress = context.progress;
  const CancellationToken& cancel = context.cancel;
  // The rig's mount against the images', before anything depends on it:
  // every stage works with the mount the check leaves. It is deterministic
  // in rig.yaml, the trajectory and the images, which the stages'
  // fingerprints hold, so a resumed run finds the same (and repeats the
  // check: a few seconds).
  const BoresightCheck boresight = CheckBoresight(
      input_survey, requested_options.boresight, progress, cancel);
  RunOptions options = requested_options;
  Survey corrected;
  const bool turned = !boresight.applied_rad.isZero();
  if (turned) {
    corrected = input_survey;
    corrected.rig = RotateRigMount(input_survey.rig, boresight.applied_rad);
    // What the estimate leaves (its sd) the adjustment calibrates, the
    // estimate its prior: amiens-short with the mount angles lost,
    // attitude 0.180 -> 0.074 deg, H 7.2 -> 6.4 cm (0 wrong matches
    // either way).
    RigCalibrationOptions& calibration = options.adjustment.rig_calibration;
    if (requested_options.boresight.self_calibrate_after &&
        !calibration.self_calibrate_rig) {
      calibration.self_calibrate_rig = true;
      calibration.boresight_sigma_rad =
          std::max(boresight.estimate.sd_rad.maxCoeff(), 1e-4);
    }
  }
  const Survey& survey = turned ? corrected : input_survey;
  // The stage outputs, handed from stage to stage in memory; what a
  // resumed run skips is read from the folder on first use.
  StageResults stage_results(results_folder, SurveyIdentity(survey.exposures));
  StageResults* results = &stage_results;

  const std::vector<std::string> fingerprints =
      StageFingerprints(survey, options);
  std::vector<PipelineStage> stages(3);
  stages[0].name = "reconstruct";
  stages[0].outputs = {kReconstructedBandsFile, kSkippedExposuresFile};
  if (options.lines) stages[0].outputs.push_back(kReconstructedLinesFile);
  stages[0].run = [&](const std::function<void(int, int)>& step) {
    return RunReconstructStage(survey, results, options, step, progress,
                               cancel);
  };
  stages[1].name = "match";
  stages[1].outputs = {kMatchesFile, kCrossingDecisionsFile};
  stages[1].run = [&](const std::function<void(int, int)>& step) {
    RunMatchStage(survey, results, options, step, cancel);
    return std::vector<std::string>();
  };
  stages[2].name = "adjust";
  stages[2].outputs = {kTrajectoryCorrectedFile, kPosesFile, kGcpResidualsFile,
                       kBandsGeoJsonFile};
  // matches.csv and crossing_decisions.csv: the control the adjustment
  // kept and what the second registration pass added.
  stages[2].rewrites = {"match"};
  stages[2].run = [&](const std::function<void(int, int)>&) {
    return RunAdjustStage(survey, results, options, progress, cancel);
  };
  for (size_t i = 0; i < stages.size(); ++i) {
    stages[i].fingerprint = fingerprints[i];
  }
  const PipelineRun run =
      RunPipeline(results_folder, stages, PipelineOptions{context.from_stage},
                  progress, cancel);

  ReportInputs inputs;
  inputs.survey = &survey;
  inputs.results_folder = results_folder;
  inputs.timings = run.timings;
  inputs.warnings = run.warnings;
  if (!boresight.message.empty()) {
    inputs.warnings.insert(inputs.warnings.begin(), boresight.message);
  }
  if (options.boresight.enabled) {
    inputs.boresight = BoresightCheckJson(boresight);
  }
  inputs.peak_memory_mb = PeakMemoryMb();
  RunSummary summary;
  summary.timings = run.timings;
  summary.warnings = inputs.warnings;
  summary.report = RunReportStage(inputs, options.report);
  return summary;
}

}  // namespace zebrageo
