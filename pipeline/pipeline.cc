#include "pipeline/pipeline.h"

#include <glog/logging.h>
#include <sys/resource.h>

#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "pipeline/exit_codes.h"
#include "pipeline/run_state.h"
#include "pipeline/stage_results.h"
#include "pipeline/stages.h"
#include "registration/match_stage.h"
#include "registration/paint_probe.h"
#include "survey/math_util.h"
#include "survey/output_crs.h"
#include "survey/results.h"

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
  nlohmann::json read = {{"lines", json["lines"]},
                         {"reconstruction", json["reconstruction"]},
                         {"road_lines", json["road_lines"]}};
  read["reconstruction"].erase("threads");
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

// reconstruct: the zebra bands, then the road lines on the road plane the
// zebra stage estimated.
std::vector<std::string> Reconstruct(
    const Survey& survey, StageResults* results, const RunOptions& options,
    const std::function<void(int, int)>& progress) {
  RoadPlane road_plane;
  std::vector<std::string> warnings = RunReconstructStage(
      survey, options.reconstruction, results, progress, &road_plane);
  if (options.lines) {
    for (const std::string& w :
         RunRoadLinesStage(survey, road_plane, options.road_lines,
                           options.threads, results, nullptr)) {
      warnings.push_back(w);
    }
  }
  return warnings;
}

std::vector<std::string> Match(const Survey& survey, StageResults* results,
                               const RunOptions& options,
                               const std::function<void(int, int)>& progress) {
  MatchResult result =
      RunMatchStage(survey, results->Vertices(), results->folder(),
                    options.matching, options.paint_probe, progress);
  if (!result.summary.IsUsable()) {
    throw StageFailedError("match: " + result.summary.message);
  }
  LOG(INFO) << "match: " << result.summary.BriefReport();
  results->SetMatches(std::move(result.matches), std::move(result.decisions));
  return {};
}

// The times of the line points of the last adjustment (AdjustWithRoadLines).
struct AdjustedLineTimes {
  std::vector<double> control;  // those that held the cross-track position
  std::vector<double> fitted;   // of them, those its trajectory fits
};

// The second registration pass on what the adjustment left in `results`.
// With too few crossings in it, on the trajectory the road lines alone
// correct: they hold the cross-track position, across which a zebra's band
// offsets lie, whatever the crossings' error model. When that adds
// nothing, on the adjustment's own trajectory near the line points it fits
// (`line_times.fitted`, RematchInput::across_from_fitted_lines): the lines
// matched on the trajectory the crossings corrected are more than the
// lines alone could place (geometry sweep 1-500: crossings matched 89.9 ->
// 93.7 %, 0 wrong).
RematchSummary Rematch(const Survey& survey, StageResults* results,
                       const RunOptions& options,
                       const AdjustedLineTimes& line_times) {
  RematchInput first;
  first.adjustment = results->Adjustment();
  first.vertices = &results->Vertices();
  first.matches = &results->Matches();
  first.decisions = &results->Decisions();
  first.adjusted_trajectory = &results->CorrectedTrajectory();
  // After road lines alone, the pass searches where they held the
  // cross-track position: line_matches.csv's exposures. After crossings
  // and lines, it searches no farther from those positions and the
  // crossings than RematchOptions::max_cross_track_control_gap_m, as the
  // geometry sweep does.
  std::vector<double> road_lines_times;
  first.line_control_times = &line_times.control;
  if (first.adjustment != nullptr && first.adjustment->road_lines_only &&
      options.lines) {
    road_lines_times = LineControlTimesIn(results->folder(), survey.exposures);
    first.line_control_times = &road_lines_times;
  }
  const std::set<std::string> rejected = RejectedCrossingsIn(results->folder());
  first.rejected_crossings = &rejected;
  ImagePaintProbe probe(survey, options.paint_probe);
  first.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                               const BandCornersEnu& band,
                               const std::vector<BandCornersEnu>& seen) {
    return probe.Classify(exposure_id, pose, band, seen);
  };
  std::optional<RoadLinesAdjustment> lines;
  if (first.adjustment != nullptr &&
      SecondPassOnRoadLines(*first.adjustment, results->Decisions(),
                            options.lines, options.second_pass)) {
    lines = AdjustByRoadLinesAlone(
        AdjustmentDataOf(survey, results->Vertices(), {}),
        results->LinePoints(), options.adjustment, options.line_registration);
    if (lines) {
      first.adjustment = &lines->record;
      first.adjusted_trajectory = &lines->trajectory;
      first.line_control_times = &lines->line_control_times;
    }
  }
  RematchSummary rematch = RematchWithAdjustedTrajectory(
      survey, first, options.matching, options.second_pass);
  if (lines) {
    rematch.message +=
        " (searched on the trajectory the road lines alone "
        "corrected: too few crossings for the adjustment's "
        "error model)";
    const AdjustmentRecord* record = results->Adjustment();
    if (rematch.added == 0 && rematch.dropped == 0 &&
        record->counts.control_crossings > 0 && !line_times.fitted.empty()) {
      first.adjustment = record;
      first.adjusted_trajectory = &results->CorrectedTrajectory();
      first.line_control_times = &line_times.fitted;
      first.across_from_fitted_lines = true;
      rematch = RematchWithAdjustedTrajectory(survey, first, options.matching,
                                              options.second_pass);
      rematch.message +=
          " (searched on the adjusted trajectory near the road lines it "
          "fits: too few crossings for its error model)";
    }
  }
  WriteRematchResults(rematch, results->folder());
  if (rematch.added > 0 || rematch.dropped > 0) {
    results->SetMatches(std::move(rematch.matches),
                        std::move(rematch.decisions));
  }
  return rematch;
}

// adjust (with road lines: line matching and a second adjustment inside
// RunAdjustStage), then the second registration pass and, while it adds
// or removes matches, the adjustment and the pass again. A pass on the
// road lines' trajectory (too few crossings to trust their error model)
// that matched crossings across the track leaves a trajectory the
// crossings corrected along it too: the next pass searches with that one.
constexpr int kMaxRematchPasses = 3;
std::vector<std::string> Adjust(const Survey& survey, StageResults* results,
                                const RunOptions& options,
                                const ProgressListener& progress) {
  // With the second pass, the first adjustment may not be the result: its
  // warnings go to the report (and stderr, tools/run_command.cc) only if
  // it is.
  RunOptions first = options;
  first.adjustment.log_warnings = !options.rematch;
  AdjustedLineTimes line_times;
  std::vector<std::string> warnings =
      RunAdjustStage(survey, results, first, progress, &line_times.control,
                     &line_times.fitted);
  if (!options.rematch) return warnings;
  // Crossings the first pass could not decide, matched again with the
  // adjusted trajectory. A pass that refused first-pass crossings it
  // contradicts adds nothing: the adjustment without them is another
  // trajectory, searched again, as is one with more crossings.
  std::vector<std::string> refusals;
  for (int pass = 0; pass < kMaxRematchPasses; ++pass) {
    const RematchSummary rematch =
        Rematch(survey, results, options, line_times);
    LOG(INFO) << rematch.message;
    // Logged as a warning, so listed in report.json too.
    if (rematch.disagreements > 0) refusals.push_back(rematch.message);
    if (rematch.added == 0 && rematch.dropped == 0) {
      // The rematch rewrote matches.csv: its output_crs columns again.
      AddOutputCrs(survey, results->folder());
      break;
    }
    const bool again = pass + 1 < kMaxRematchPasses;
    warnings =
        RunAdjustStage(survey, results, again ? first : options, progress,
                       &line_times.control, &line_times.fitted);
    if (!again) break;
  }
  warnings.insert(warnings.end(), refusals.begin(), refusals.end());
  return warnings;
}

}  // namespace

RunSummary RunSurveyPipeline(const Survey& survey,
                             const std::string& results_folder,
                             const RunOptions& options,
                             const RunContext& context) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError(problem);
  const ProgressListener& progress = context.progress;
  // The stage outputs, handed from stage to stage in memory; what a
  // resumed run skips is read from the folder on first use.
  StageResults stage_results(results_folder);
  StageResults* results = &stage_results;

  const std::vector<std::string> fingerprints =
      StageFingerprints(survey, options);
  std::vector<PipelineStage> stages(3);
  stages[0].name = "reconstruct";
  stages[0].outputs = {kReconstructedBandsFile, kSkippedExposuresFile};
  if (options.lines) stages[0].outputs.push_back(kReconstructedLinesFile);
  stages[0].run = [&](const std::function<void(int, int)>& step) {
    return Reconstruct(survey, results, options, step);
  };
  stages[1].name = "match";
  stages[1].outputs = {kMatchesFile, kCrossingDecisionsFile};
  stages[1].run = [&](const std::function<void(int, int)>& step) {
    return Match(survey, results, options, step);
  };
  stages[2].name = "adjust";
  stages[2].outputs = {kTrajectoryCorrectedFile, kPosesFile, kGcpResidualsFile,
                       kBandsGeoJsonFile};
  // matches.csv and crossing_decisions.csv: the control the adjustment
  // kept and what the second registration pass added.
  stages[2].rewrites = {"match"};
  stages[2].run = [&](const std::function<void(int, int)>&) {
    return Adjust(survey, results, options, progress);
  };
  for (size_t i = 0; i < stages.size(); ++i) {
    stages[i].fingerprint = fingerprints[i];
  }
  const PipelineRun run = RunPipeline(
      results_folder, stages, PipelineOptions{context.from_stage}, progress);

  ReportInputs inputs;
  inputs.survey = &survey;
  inputs.results_folder = results_folder;
  inputs.timings = run.timings;
  inputs.warnings = run.warnings;
  inputs.peak_memory_mb = PeakMemoryMb();
  RunSummary summary;
  summary.timings = run.timings;
  summary.warnings = run.warnings;
  summary.report = WriteReport(inputs, options.report);
  return summary;
}

}  // namespace zebrageo
