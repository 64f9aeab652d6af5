// `zebrageo run SURVEY -o RESULTS` and `zebrageo report SURVEY -o RESULTS`.
#include <glog/logging.h>
#include <sys/resource.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "registration/match_stage.h"
#include "survey/output_crs.h"
#include "survey/results.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/exit_codes.h"
#include "tools/pipeline.h"
#include "tools/report/report.h"
#include "tools/results_session.h"
#include "tools/stages.h"

namespace zebrageo {
namespace {

struct RunArguments {
  StageArguments stage;
  std::string from_stage;
  int threads = 0;
  bool tie_points = true;
  bool lines = true;  // road lines as control beside the zebras (issue 9)
  double sideslip_sigma_deg = RadToDeg(AdjustmentOptions().sideslip_sigma_rad);
  // Second registration pass with the adjusted trajectory.
  bool rematch = true;
};

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

void Run(const RunArguments& args) {
  // One run at a time in a results folder; on any error, no output of the
  // contract is left (tools/results_session.h).
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kRemoveContractOutputs);
  // Validate everything before the first output is written: a survey that
  // cannot be processed leaves a new results folder uncreated.
  const Survey survey =
      LoadSurvey(args.stage.survey, LoadOptionsOf(args.stage));
  ReconstructionOptions reconstruction;
  reconstruction.threads = args.threads;
  MatchOptions matching;
  AdjustmentOptions adjustment;
  if (args.threads > 0) adjustment.solver.num_threads = args.threads;
  adjustment.sideslip_sigma_rad = DegToRad(args.sideslip_sigma_deg);
  for (const std::string& problem :
       {reconstruction.Check(), matching.Check(), adjustment.Check()}) {
    if (!problem.empty()) throw UsageError(problem);
  }
  const std::string results = args.stage.results;
  session.Open();

  std::vector<PipelineStage> stages;
  std::vector<std::string> reconstruct_outputs = {kReconstructedBandsFile,
                                                  kSkippedExposuresFile};
  if (args.lines) reconstruct_outputs.push_back(kReconstructedLinesFile);
  stages.push_back({"reconstruct", reconstruct_outputs,
                    [&](const std::function<void(int, int)>& progress) {
                      RoadPlane road_plane;
                      std::vector<std::string> warnings =
                          RunReconstructStage(survey, reconstruction, results,
                                              progress, &road_plane);
                      if (args.lines) {
                        for (const std::string& w : RunRoadLinesStage(
                                 survey, road_plane, RoadLineOptions(),
                                 args.threads, results, nullptr)) {
                          warnings.push_back(w);
                        }
                      }
                      return warnings;
                    }});
  stages.push_back({"match",
                    {kMatchesFile, kCrossingDecisionsFile},
                    [&](const std::function<void(int, int)>& progress) {
                      const MatchResult result =
                          RunMatchStage(survey, results, matching, progress);
                      if (!result.summary.IsUsable()) {
                        throw StageFailedError("match: " +
                                               result.summary.message);
                      }
                      LOG(INFO) << "match: " << result.summary.BriefReport();
                      return std::vector<std::string>();
                    }});
  stages.push_back({"adjust",
                    {kTrajectoryCorrectedFile, kPosesFile, kGcpResidualsFile,
                     kBandsGeoJsonFile},
                    [&](const std::function<void(int, int)>&) {
                      std::vector<std::string> warnings =
                          RunAdjustStage(survey, results, adjustment,
                                         args.tie_points, args.lines);
                      if (!args.rematch) return warnings;
                      // Crossings the first pass could not decide, matched
                      // again with the adjusted trajectory; if any is
                      // added, the adjustment is made again with them.
                      const RematchSummary rematch =
                          RematchWithAdjustedTrajectory(
                              survey, results, matching, RematchOptions());
                      LOG(INFO) << rematch.message;
                      // Refused for contradicting the first pass: logged as
                      // a warning, so listed in report.json too.
                      if (rematch.disagreements > 0) {
                        warnings.push_back(rematch.message);
                      }
                      if (rematch.added == 0) {
                        // The rematch rewrote matches.csv: its output_crs
                        // columns again.
                        AddOutputCrs(survey, results);
                        return warnings;
                      }
                      return RunAdjustStage(survey, results, adjustment,
                                            args.tie_points, args.lines);
                    }});
  std::ostringstream settings;
  settings << "threads-independent;ties=" << args.tie_points
           << ";lines=" << args.lines << ";sideslip=" << args.sideslip_sigma_deg
           << ";rematch=" << args.rematch;
  const PipelineRun run = RunPipeline(
      results, InputFingerprint(SurveyInputFiles(survey), settings.str()),
      stages, PipelineOptions{args.from_stage});

  ReportInputs inputs;
  inputs.survey = &survey;
  inputs.results_folder = results;
  inputs.timings = run.timings;
  inputs.warnings = run.warnings;
  inputs.peak_memory_mb = PeakMemoryMb();
  const nlohmann::json report = WriteReport(inputs, ReportOptions());
  for (const auto& warning : report["warnings"]) {
    LOG(WARNING) << warning.get<std::string>();
  }
  session.Succeeded();
  std::cout << "report: " << results << "/" << kReportHtmlFile << "\n";
}

}  // namespace

void AddRunCommands(CLI::App* app, std::vector<Command>* commands) {
  auto run_args = std::make_shared<RunArguments>();
  CLI::App* run = AddStageSubcommand(
      app, "run",
      "All stages (reconstruct, match, adjust), then report.json and "
      "report.html. A rerun resumes after the last completed stage.",
      &run_args->stage);
  // Checked while parsing: a typo is a usage error before anything runs.
  run->add_option("--from", run_args->from_stage,
                  "redo from this stage: reconstruct, match or adjust")
      ->check(CLI::IsMember({"reconstruct", "match", "adjust"}));
  run->add_option("--threads", run_args->threads,
                  "worker threads (0: one per hardware thread)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  run->add_flag("!--no-tie-points", run_args->tie_points,
                "do not match image features between exposures");
  run->add_flag("!--no-lines", run_args->lines,
                "zebra crossings alone as control: no road lines");
  AddSideslipOption(run, &run_args->sideslip_sigma_deg);
  run->add_flag("!--no-rematch", run_args->rematch,
                "no second registration pass with the adjusted trajectory");
  commands->push_back({run, [run_args] { Run(*run_args); }});

  auto report_args = std::make_shared<StageArguments>();
  CLI::App* report = AddStageSubcommand(
      app, "report",
      "Write report.json and report.html from an existing results folder.",
      report_args.get());
  commands->push_back({report, [report_args] {
                         ResultsSession session(
                             report_args->results,
                             ResultsSession::OnError::kRemoveContractOutputs);
                         const Survey survey = LoadSurvey(
                             report_args->survey, LoadOptionsOf(*report_args));
                         session.Open();
                         ReportInputs inputs;
                         inputs.survey = &survey;
                         inputs.results_folder = report_args->results;
                         WriteReport(inputs, ReportOptions());
                         session.Succeeded();
                         std::cout << "report: " << report_args->results << "/"
                                   << kReportHtmlFile << "\n";
                       }});
}

}  // namespace zebrageo
