// `zebrageo run SURVEY -o RESULTS` and `zebrageo report SURVEY -o RESULTS`.
#include <glog/logging.h>

#include <filesystem>
#include <iostream>
#include <memory>

#include "pipeline/exit_codes.h"
#include "pipeline/pipeline.h"
#include "pipeline/report_stage.h"
#include "pipeline/results_session.h"
#include "pipeline/run_options.h"
#include "survey/math_util.h"
#include "survey/results.h"
#include "survey/results_survey.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

struct RunArguments {
  StageArguments stage;
  std::string from_stage;
  std::string options_file;
  bool print_options = false;
  // Flags that override the options file when given (each Option's
  // count()).
  int threads = 0;
  bool tie_points = true;
  bool lines = true;  // road lines as control beside the zebras (issue 9)
  double sideslip_sigma_deg =
      RadToDeg(AdjustmentOptions().vehicle_motion.sideslip_sigma_rad);
  // Second registration pass with the adjusted trajectory.
  bool rematch = true;
  CLI::App* command = nullptr;
};

bool Given(const RunArguments& args, const std::string& flag) {
  return args.command->get_option(flag)->count() > 0;
}

// The defaults, then --options FILE, then the flags given.
RunOptions OptionsOf(const RunArguments& args) {
  RunOptions options;
  if (!args.options_file.empty()) options = ReadRunOptions(args.options_file);
  if (Given(args, "--threads")) {
    options.threads = args.threads;
    options.reconstruction.threads = args.threads;
    if (args.threads > 0) options.adjustment.solver.num_threads = args.threads;
  }
  if (Given(args, "--no-tie-points")) options.tie_points = args.tie_points;
  if (Given(args, "--no-lines")) options.lines = args.lines;
  if (Given(args, "--no-rematch")) options.rematch = args.rematch;
  if (Given(args, "--sideslip-sigma")) {
    options.adjustment.vehicle_motion.sideslip_sigma_rad =
        DegToRad(args.sideslip_sigma_deg);
  }
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError(problem);
  return options;
}

void Run(const RunArguments& args) {
  const RunOptions options = OptionsOf(args);
  if (args.print_options) {
    std::cout << RunOptionsToJson(options).dump(2) << "\n";
    return;
  }
  if (args.stage.survey.empty() || args.stage.results.empty()) {
    throw UsageError("run: SURVEY and -o RESULTS are required");
  }
  // One run at a time in a results folder; on any error, no output of the
  // contract is left (pipeline/results_session.h).
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kRemoveContractOutputs);
  // Validate everything before the first output is written: a survey that
  // cannot be processed leaves a new results folder uncreated.
  const Survey survey =
      LoadSurvey(args.stage.survey, LoadOptionsOf(args.stage));
  session.Open();
  RunContext context;
  context.progress = ProgressBars();
  context.from_stage = args.from_stage;
  context.cancel = CancelOnSignal();
  const RunSummary run =
      RunSurveyPipeline(survey, args.stage.results, options, context);
  for (const auto& warning : run.report["warnings"]) {
    LOG(WARNING) << warning.get<std::string>();
  }
  session.Succeeded();
  std::cout << "report: " << args.stage.results << "/" << kReportHtmlFile
            << "\n";
}

// `report` reads a results folder: one without a stage's output (a typo, a
// run that never started) is refused, not reported as an empty run.
void CheckHasStageOutputs(const std::string& results) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(results, error)) {
    throw UsageError(results +
                     " is not a results folder (run `zebrageo run "
                     "SURVEY -o " +
                     results + "` first)");
  }
  for (const char* file :
       {kReconstructedBandsFile, kMatchesFile, kTrajectoryCorrectedFile}) {
    if (fs::exists(fs::path(results) / file, error)) return;
  }
  throw UsageError(results + " holds no stage output (" +
                   kReconstructedBandsFile + ", " + kMatchesFile + ", " +
                   kTrajectoryCorrectedFile +
                   "): nothing to report; run `zebrageo run SURVEY -o " +
                   results + "` first");
}

}  // namespace

void AddRunCommands(CLI::App* app, std::vector<Command>* commands) {
  auto run_args = std::make_shared<RunArguments>();
  CLI::App* run = AddStageSubcommand(
      app, "run",
      "All stages (reconstruct, match, adjust), then report.json and "
      "report.html. A rerun resumes every stage whose inputs and options "
      "did not change.",
      &run_args->stage);
  run_args->command = run;
  // Not needed to print the options.
  run->get_option("survey")->required(false);
  run->get_option("--output")->required(false);
  run->add_option("--options", run_args->options_file,
                  "JSON file of options (`--print-options` prints them all); "
                  "members left out keep their defaults, the flags below "
                  "override it")
      ->check(CLI::ExistingFile);
  run->add_flag("--print-options", run_args->print_options,
                "print the options as JSON (the defaults, with --options and "
                "the flags applied) and exit");
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
  commands->push_back(
      {report, [report_args] {
         CheckHasStageOutputs(report_args->results);
         ResultsSession session(
             report_args->results,
             ResultsSession::OnError::kRemoveContractOutputs);
         const Survey survey =
             LoadSurvey(report_args->survey, LoadOptionsOf(*report_args));
         session.RefuseAnotherSurvey(SurveyIdentity(survey.exposures));
         session.Open();
         ReportInputs inputs;
         inputs.survey = &survey;
         inputs.results_folder = report_args->results;
         RunReportStage(inputs, ReportOptions());
         session.Succeeded();
         std::cout << "report: " << report_args->results << "/"
                   << kReportHtmlFile << "\n";
       }});
}

}  // namespace zebrageo
