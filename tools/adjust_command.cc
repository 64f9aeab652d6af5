// `zebrageo adjust SURVEY -o RESULTS`: reads reconstructed_bands.csv and
// matches.csv, adjusts the trajectory (adjustment/trajectory_adjuster.h) and
// writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv,
// bands.geojson, adjustment.json, a minimal report.json and colmap/.
#include <glog/logging.h>

#include <memory>

#include "adjustment/adjustment_io.h"
#include "adjustment/tie_points.h"
#include "adjustment/trajectory_adjuster.h"
#include "survey/atomic_file.h"
#include "tools/commands.h"
#include "tools/exit_codes.h"
#include "tools/progress.h"
#include "tools/stages.h"

namespace zebrageo {
namespace {

struct AdjustArguments {
  StageArguments stage;
  bool tie_points = true;
  bool lines = true;
  bool self_calibrate = false;
  double check_share = AdjustmentOptions().check_crossing_share;
  int threads = AdjustmentOptions().solver.num_threads;
  double sideslip_sigma_deg = AdjustmentOptions().sideslip_sigma_deg;
};

void RunAdjust(const AdjustArguments& args) {
  AdjustmentOptions options;
  options.check_crossing_share = args.check_share;
  options.self_calibrate_rig = args.self_calibrate;
  options.solver.num_threads = args.threads;
  options.sideslip_sigma_deg = args.sideslip_sigma_deg;
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError("adjust: " + problem);
  RunAdjustStage(args.stage.survey, args.stage.results, options,
                 args.tie_points, args.lines);
}

}  // namespace

std::vector<std::string> RunAdjustStage(const std::string& survey_folder,
                                        const std::string& results_folder,
                                        const AdjustmentOptions& options,
                                        bool tie_points, bool lines) {
  const AdjustmentData data = LoadAdjustmentData(survey_folder, results_folder);
  LOG(INFO) << "adjust: " << data.vertices.size() << " reconstructed vertices, "
            << data.matches.size() << " matches, "
            << data.exposures.exposures.size() << " exposures";

  std::vector<TieTrack> tracks;
  TiePointSummary tie_summary;
  const bool use_ties =
      tie_points &&
      data.missing_images < static_cast<int>(data.exposures.images.size());
  if (use_ties) {
    ProgressBar bar("tie points");
    tracks = BuildTieTracks(TiePointOptions(), data.survey_folder, data.rig,
                            data.trajectory, data.exposures, &tie_summary,
                            bar.Callback());
    bar.Finish();
  }
  AdjustmentInput input = data.Input();
  if (use_ties) input.tie_tracks = &tracks;

  ProgressBar bar("adjust");
  AdjustmentResult result = AdjustTrajectory(options, input, bar.Callback());
  bar.Finish();
  std::vector<std::string> warnings = data.warnings;
  if (lines && result.summary.IsUsable()) {
    const std::vector<LineControlPoint> line_points = MatchLinesForAdjustment(
        data, options, result, results_folder, &warnings);
    if (!line_points.empty()) {
      input.line_points = &line_points;
      ProgressBar line_bar("adjust with lines");
      result = AdjustTrajectory(options, input, line_bar.Callback());
      line_bar.Finish();
    }
  }
  if (!result.summary.IsUsable()) {
    throw StageFailedError("adjust: " + result.summary.message +
                           "; no results were written");
  }
  RemoveStaleTemporaries(results_folder);
  WriteAdjustmentResults(data, options, result,
                         use_ties ? &tie_summary : nullptr, results_folder);
  const int removed = RemoveRejectedMatches(data, result, results_folder);
  if (removed > 0) {
    LOG(INFO) << "adjust: " << removed
              << " vertex matches rejected by the adjustment removed from "
              << kMatchesFile;
  }
  LOG(INFO) << "adjust: " << result.summary.BriefReport();
  return warnings;
}

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
