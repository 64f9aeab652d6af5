// `zebrageo match SURVEY -o RESULTS`: reads RESULTS/reconstructed_bands.csv,
// writes matches.csv, crossing_decisions.csv, match_evidence.json and
// matches.geojson (registration/match_stage.h). With --second-pass, after
// `zebrageo adjust`: matches what the first pass left undecided with the
// adjusted trajectory (what `zebrageo run` does, then adjusts again).
#include <glog/logging.h>

#include <iostream>
#include <memory>

#include "pipeline/exit_codes.h"
#include "pipeline/results_session.h"
#include "registration/match_stage.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/progress.h"

namespace zebrageo {

void AddMatchCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<StageArguments>();
  auto options = std::make_shared<MatchOptions>();
  auto second_pass = std::make_shared<bool>(false);
  CLI::App* sub = AddStageSubcommand(
      app, "match",
      "Match reconstructed bands to the road-mark database; writes "
      "matches.csv, crossing_decisions.csv, match_evidence.json and "
      "matches.geojson.",
      args.get());
  sub->add_option("--max-drift-m", options->max_drift_m,
                  "horizontal trajectory error the search allows (m)")
      ->capture_default_str();
  sub->add_option("--max-heading-error-rad", options->max_heading_error_rad,
                  "heading error the search allows (rad)")
      ->capture_default_str();
  sub->add_option("--min-margin", options->min_margin,
                  "score margin over the best alternative needed to match")
      ->capture_default_str();
  sub->add_option("--missing-band-weight", options->missing_band_weight,
                  "score penalty of a database band the cameras should have "
                  "seen but did not")
      ->capture_default_str();
  sub->add_option("--vertex-tolerance-m", options->vertex_tolerance_m,
                  "largest corner residual of a matched band (m)")
      ->capture_default_str();
  sub->add_option("--drift-rate-m-per-s", options->drift_rate_m_per_s,
                  "how fast the trajectory error may change (m/s)")
      ->capture_default_str();
  sub->add_flag("--require-both-ends", options->require_both_ends,
                "resolve the band period only when both ends of a crossing "
                "agree (immune to a database fault at one end)");
  sub->add_flag("--refuse-shifted-crossings", options->refuse_shifted_crossings,
                "refuse matches to database crossings that look shifted");
  sub->add_flag("--second-pass", *second_pass,
                "after `zebrageo adjust`: match the observations the first "
                "pass left undecided with RESULTS/trajectory_corrected.csv "
                "(rewrites matches.csv and crossing_decisions.csv)");
  commands->push_back(
      {sub, [args, options, second_pass] {
         const std::string problem = options->Check();
         if (!problem.empty()) {
           throw UsageError("match: " + problem);
         }
         ResultsSession session(args->results,
                                ResultsSession::OnError::kKeepOutputs);
         const Survey survey = LoadSurvey(args->survey, LoadOptionsOf(*args));
         session.Open();
         if (*second_pass) {
           const RematchSummary summary = RematchWithAdjustedTrajectory(
               survey, args->results, *options, RematchOptions());
           std::cout << summary.message << "\n";
           session.Succeeded();
           return;
         }
         ProgressBar bar("match");
         const MatchResult result =
             RunMatchStage(survey, args->results, *options, PaintProbeOptions(),
                           bar.Callback());
         bar.Finish();
         if (!result.summary.IsUsable()) {
           throw StageFailedError(result.summary.message);
         }
         std::cout << result.summary.BriefReport() << "\n";
         session.Succeeded();
       }});
}

}  // namespace zebrageo
