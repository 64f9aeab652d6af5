#include "pipeline/pipeline.h"

#include <glog/logging.h>
#include <sys/resource.h>

#include <sstream>

#include "pipeline/exit_codes.h"
#include "pipeline/run_state.h"
#include "pipeline/stages.h"
#include "registration/match_stage.h"
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

std::vector<std::string> SurveyInputFiles(const Survey& survey) {
  std::vector<std::string> files = {survey.PathOf("survey.yaml")};
  for (const std::string* file :
       {&survey.manifest.rig, &survey.manifest.trajectory,
        &survey.manifest.exposures, &survey.manifest.roadmarks}) {
    files.push_back(survey.PathOf(*file));
  }
  for (const ExposureImage& image : survey.exposures.images) {
    files.push_back(survey.PathOf(image.image));
  }
  return files;
}

// reconstruct: the zebra bands, then the road lines on the road plane the
// zebra stage estimated.
std::vector<std::string> Reconstruct(
    const Survey& survey, const std::string& results, const RunOptions& options,
    const std::function<void(int, int)>& progress) {
  RoadPlane road_plane;
  std::vector<std::string> warnings = RunReconstructStage(
      survey, options.reconstruction, results, progress, &road_plane);
  if (options.lines) {
    for (const std::string& w :
         RunRoadLinesStage(survey, road_plane, RoadLineOptions(),
                           options.threads, results, nullptr)) {
      warnings.push_back(w);
    }
  }
  return warnings;
}

std::vector<std::string> Match(const Survey& survey, const std::string& results,
                               const RunOptions& options,
                               const std::function<void(int, int)>& progress) {
  const MatchResult result =
      RunMatchStage(survey, results, options.matching, progress);
  if (!result.summary.IsUsable()) {
    throw StageFailedError("match: " + result.summary.message);
  }
  LOG(INFO) << "match: " << result.summary.BriefReport();
  return {};
}

// adjust (with road lines: line matching and a second adjustment inside
// RunAdjustStage), then the second registration pass and, if it added
// matches, the adjustment again.
std::vector<std::string> Adjust(const Survey& survey,
                                const std::string& results,
                                const RunOptions& options,
                                const ProgressListener& progress) {
  std::vector<std::string> warnings =
      RunAdjustStage(survey, results, options.adjustment, options.tie_points,
                     options.lines, progress);
  if (!options.rematch) return warnings;
  // Crossings the first pass could not decide, matched again with the
  // adjusted trajectory.
  const RematchSummary rematch = RematchWithAdjustedTrajectory(
      survey, results, options.matching, RematchOptions());
  LOG(INFO) << rematch.message;
  // Refused for contradicting the first pass: logged as a warning, so
  // listed in report.json too.
  if (rematch.disagreements > 0) warnings.push_back(rematch.message);
  if (rematch.added == 0) {
    // The rematch rewrote matches.csv: its output_crs columns again.
    AddOutputCrs(survey, results);
    return warnings;
  }
  return RunAdjustStage(survey, results, options.adjustment, options.tie_points,
                        options.lines, progress);
}

}  // namespace

std::string RunOptions::Check() const {
  if (threads < 0) {
    return "threads = " + std::to_string(threads) + ": must be >= 0";
  }
  for (const std::string& problem : {reconstruction.Check(), matching.Check(),
                                     adjustment.Check(), report.Check()}) {
    if (!problem.empty()) return problem;
  }
  return "";
}

RunSummary RunSurveyPipeline(const Survey& survey,
                             const std::string& results_folder,
                             const RunOptions& options,
                             const ProgressListener& progress) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError(problem);
  const std::string& results = results_folder;

  std::vector<PipelineStage> stages;
  std::vector<std::string> reconstruct_outputs = {kReconstructedBandsFile,
                                                  kSkippedExposuresFile};
  if (options.lines) reconstruct_outputs.push_back(kReconstructedLinesFile);
  stages.push_back({"reconstruct", reconstruct_outputs,
                    [&](const std::function<void(int, int)>& step) {
                      return Reconstruct(survey, results, options, step);
                    }});
  stages.push_back({"match",
                    {kMatchesFile, kCrossingDecisionsFile},
                    [&](const std::function<void(int, int)>& step) {
                      return Match(survey, results, options, step);
                    }});
  stages.push_back({"adjust",
                    {kTrajectoryCorrectedFile, kPosesFile, kGcpResidualsFile,
                     kBandsGeoJsonFile},
                    [&](const std::function<void(int, int)>&) {
                      return Adjust(survey, results, options, progress);
                    }});
  std::ostringstream settings;
  settings << "threads-independent;ties=" << options.tie_points
           << ";lines=" << options.lines
           << ";sideslip=" << RadToDeg(options.adjustment.sideslip_sigma_rad)
           << ";rematch=" << options.rematch;
  const PipelineRun run = RunPipeline(
      results, InputFingerprint(SurveyInputFiles(survey), settings.str()),
      stages, PipelineOptions{options.from_stage}, progress);

  ReportInputs inputs;
  inputs.survey = &survey;
  inputs.results_folder = results;
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
