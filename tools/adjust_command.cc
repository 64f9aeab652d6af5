// `zebrageo adjust SURVEY -o RESULTS`: reads reconstructed_bands.csv and
// matches.csv, adjusts the trajectory (pipeline/adjust_stage.h) and writes
// trajectory_corrected.csv, poses.csv, gcp_residuals.csv, bands.geojson,
// adjustment.json and colmap/, then the report (report.json, report.html).
#include <chrono>
#include <memory>

#include "pipeline/adjust_stage.h"
#include "pipeline/exit_codes.h"
#include "pipeline/report_stage.h"
#include "pipeline/results_session.h"
#include "pipeline/run_options.h"
#include "survey/math_util.h"
#include "survey/results_survey.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

struct AdjustArguments {
  StageArguments stage;
  bool tie_points = true;
  bool lines = true;
  bool self_calibrate = false;
  double check_share = RunOptions().adjustment.control.check_crossing_share;
  int threads = RunOptions().adjustment.solver.num_threads;
  double sideslip_sigma_deg =
      RadToDeg(RunOptions().adjustment.vehicle_motion.sideslip_sigma_rad);
};

void RunAdjust(const AdjustArguments& args) {
  RunOptions options;
  options.tie_points = args.tie_points;
  options.lines = args.lines;
  // The second registration pass is `zebrageo match --second-pass`.
  options.rematch = false;
  AdjustmentOptions& adjustment = options.adjustment;
  adjustment.control.check_crossing_share = args.check_share;
  adjustment.rig_calibration.self_calibrate_rig = args.self_calibrate;
  adjustment.solver.num_threads = args.threads;
  adjustment.vehicle_motion.sideslip_sigma_rad =
      DegToRad(args.sideslip_sigma_deg);
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError("adjust: " + problem);
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kRemoveContractOutputs);
  // The adjustment needs the geometry, not the images (they only feed tie
  // points), but the survey passes every other check of `run`.
  SurveyLoadOptions load_options = LoadOptionsOf(args.stage);
  load_options.require_images = false;
  const Survey survey = LoadSurvey(args.stage.survey, load_options);
  // Every stage file the command may read, checked once.
  session.RefuseAnotherSurvey(SurveyIdentity(survey.exposures));
  session.Open();
  StageResults results(args.stage.results);
  const auto start = std::chrono::steady_clock::now();
  ReportInputs inputs;
  inputs.warnings = RunAdjustStage(survey, &results, options, ProgressBars(),
                                   CancelOnSignal());
  inputs.timings = {
      {"adjust",
       std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
           .count(),
       false}};
  inputs.survey = &survey;
  inputs.results_folder = args.stage.results;
  RunReportStage(inputs, options.report);
  session.Succeeded();
}

}  // namespace

void AddAdjustCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<AdjustArguments>();
  CLI::App* sub = AddStageSubcommand(
      app, "adjust",
      "Bundle-adjust the trajectory with the matched band vertices as ground "
      "control; writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv, "
      "bands.geojson, adjustment.json and a COLMAP model in colmap/.",
      &args->stage);
  sub->add_flag("!--no-tie-points", args->tie_points,
                "do not match image features between exposures");
  sub->add_flag("!--no-lines", args->lines,
                "zebra crossings alone: do not use reconstructed_lines.csv");
  sub->add_flag("--self-calibrate", args->self_calibrate,
                "estimate each camera's boresight and lever arm");
  sub->add_option("--check-share", args->check_share,
                  "share of matched crossings held out as check points")
      ->capture_default_str();
  sub->add_option("--threads", args->threads, "solver threads")
      ->capture_default_str();
  AddSideslipOption(sub, &args->sideslip_sigma_deg);
  commands->push_back({sub, [args] { RunAdjust(*args); }});
}

}  // namespace zebrageo
