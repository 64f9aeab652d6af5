// `zebrageo adjust SURVEY -o RESULTS`: reads reconstructed_bands.csv and
// matches.csv, adjusts the trajectory (adjustment/trajectory_adjuster.h) and
// writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv,
// bands.geojson, adjustment.json, a minimal report.json and colmap/.
#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <set>

#include "adjustment/adjustment_io.h"
#include "adjustment/trajectory_adjuster.h"
#include "survey/atomic_file.h"
#include "survey/output_crs.h"
#include "survey/results.h"
#include "tiepoints/tie_points.h"
#include "tools/commands.h"
#include "tools/exit_codes.h"
#include "tools/progress.h"
#include "tools/results_session.h"
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
  double sideslip_sigma_deg = RadToDeg(AdjustmentOptions().sideslip_sigma_rad);
};

void RunAdjust(const AdjustArguments& args) {
  AdjustmentOptions options;
  options.check_crossing_share = args.check_share;
  options.self_calibrate_rig = args.self_calibrate;
  options.solver.num_threads = args.threads;
  options.sideslip_sigma_rad = DegToRad(args.sideslip_sigma_deg);
  const std::string problem = options.Check();
  if (!problem.empty()) throw UsageError("adjust: " + problem);
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kRemoveContractOutputs);
  // The adjustment needs the geometry, not the images (they only feed tie
  // points), but the survey passes every other check of `run`.
  SurveyLoadOptions load_options = LoadOptionsOf(args.stage);
  load_options.require_images = false;
  const Survey survey = LoadSurvey(args.stage.survey, load_options);
  session.Open();
  RunAdjustStage(survey, args.stage.results, options, args.tie_points,
                 args.lines);
  session.Succeeded();
}

// Exposures the reconstruction skipped (their images could not be read):
// they get no pose (SURVEY_FORMAT.md). Empty without skipped_exposures.csv
// (results of an older version).
std::set<int64_t> SkippedExposureIds(const std::string& results_folder) {
  std::set<int64_t> ids;
  const std::string path =
      (std::filesystem::path(results_folder) / kSkippedExposuresFile).string();
  if (!std::filesystem::exists(path)) return ids;
  for (const SkippedExposure& s :
       ReadSkippedExposures(path, kSkippedExposuresFile)) {
    ids.insert(s.exposure_id);
  }
  return ids;
}

}  // namespace

std::vector<std::string> RunAdjustStage(const Survey& survey,
                                        const std::string& results_folder,
                                        const AdjustmentOptions& options,
                                        bool tie_points, bool lines) {
  AdjustmentData data =
      LoadAdjustmentData(survey.folder, results_folder, survey.paths);
  // The survey's warnings first: adjustment.json and the adjust command's
  // report.json list them too.
  data.warnings.insert(data.warnings.begin(), survey.warnings.begin(),
                       survey.warnings.end());
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
    // A solver's message ("Ceres failed: ...") names no input: the survey's
    // warnings (gaps, rates, with their lines and times) may.
    std::string context;
    for (size_t i = 0; i < survey.warnings.size() && i < 3; ++i) {
      context +=
          (i == 0 ? "; the survey's warnings: " : "; ") + survey.warnings[i];
    }
    throw StageFailedError("adjust: " + result.summary.message +
                           "; no results were written" + context);
  }
  const std::set<int64_t> skipped = SkippedExposureIds(results_folder);
  result.camera_poses.erase(
      std::remove_if(result.camera_poses.begin(), result.camera_poses.end(),
                     [&skipped](const CameraPose& pose) {
                       return skipped.count(pose.exposure_id) > 0;
                     }),
      result.camera_poses.end());
  RemoveStaleTemporaries(results_folder);
  WriteAdjustmentResults(data, options, result,
                         use_ties ? &tie_summary : nullptr, results_folder);
  const int removed = RemoveRejectedMatches(data, result, results_folder);
  if (removed > 0) {
    LOG(INFO) << "adjust: " << removed
              << " vertex matches rejected by the adjustment removed from "
              << kMatchesFile;
  }
  // survey.yaml's output_crs, beside the contract's WGS84 and ENU columns.
  AddOutputCrs(survey, results_folder);
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
