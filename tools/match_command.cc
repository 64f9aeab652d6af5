// `zebrageo match SURVEY -o RESULTS`: reads RESULTS/reconstructed_bands.csv,
// writes matches.csv, crossing_decisions.csv, match_evidence.json and
// matches.geojson (pipeline/match_stage.h). With --second-pass, after
// `zebrageo adjust`: the second registration pass of `zebrageo run`
// (pipeline/rematch_stage.h) on the results folder's files.
#include <iostream>
#include <memory>

#include "pipeline/exit_codes.h"
#include "pipeline/match_stage.h"
#include "pipeline/rematch_stage.h"
#include "pipeline/results_session.h"
#include "pipeline/run_options.h"
#include "survey/results_survey.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

void RunMatch(const StageArguments& args, const RunOptions& options,
              bool second_pass) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError("match: " + problem);
  ResultsSession session(args.results, ResultsSession::OnError::kKeepOutputs);
  const Survey survey = LoadSurvey(args.survey, LoadOptionsOf(args));
  // Every stage file the command may read, checked once.
  session.RefuseAnotherSurvey(SurveyIdentity(survey.exposures));
  session.Open();
  StageResults results(args.results);
  if (second_pass) {
    const RematchSummary summary =
        RunRematchStage(survey, &results, options, CancelOnSignal());
    std::cout << summary.message << "\n";
    session.Succeeded();
    return;
  }
  ProgressBar bar("match");
  const MatchSummary summary = RunMatchStage(survey, &results, options,
                                             bar.Callback(), CancelOnSignal());
  bar.Finish();
  std::cout << summary.BriefReport() << "\n";
  session.Succeeded();
}

}  // namespace

void AddMatchCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<StageArguments>();
  auto options = std::make_shared<RunOptions>();
  auto second_pass = std::make_shared<bool>(false);
  MatchOptions* matching = &options->matching;
  CLI::App* sub = AddStageSubcommand(
      app, "match",
      "Match reconstructed bands to the road-mark database; writes "
      "matches.csv, crossing_decisions.csv, match_evidence.json, "
      "matches.geojson, matched_bands.geojson and database_faults.geojson.",
      args.get());
  sub->add_option("--max-drift-m", matching->max_drift_m,
                  "horizontal trajectory error the search allows (m)")
      ->capture_default_str();
  sub->add_option("--max-heading-error-rad", matching->max_heading_error_rad,
                  "heading error the search allows (rad)")
      ->capture_default_str();
  sub->add_option("--min-margin", matching->min_margin,
                  "score margin over the best alternative needed to match")
      ->capture_default_str();
  sub->add_option("--missing-band-weight", matching->missing_band_weight,
                  "score penalty of a database band the cameras should have "
                  "seen but did not")
      ->capture_default_str();
  sub->add_option("--vertex-tolerance-m", matching->vertex_tolerance_m,
                  "largest corner residual of a matched band (m)")
      ->capture_default_str();
  sub->add_option("--drift-rate-m-per-s", matching->drift_rate_m_per_s,
                  "how fast the trajectory error may change (m/s)")
      ->capture_default_str();
  sub->add_flag("--require-both-ends", matching->require_both_ends,
                "resolve the band period only when both ends of a crossing "
                "agree (immune to a database fault at one end)");
  sub->add_flag("--refuse-shifted-crossings",
                matching->refuse_shifted_crossings,
                "refuse matches to database crossings that look shifted");
  sub->add_flag("--second-pass", *second_pass,
                "after `zebrageo adjust`: the second registration pass of "
                "`zebrageo run` with RESULTS/trajectory_corrected.csv "
                "(rewrites matches.csv and crossing_decisions.csv)");
  commands->push_back({sub, [args, options, second_pass] {
                         RunMatch(*args, *options, *second_pass);
                       }});
}

}  // namespace zebrageo
