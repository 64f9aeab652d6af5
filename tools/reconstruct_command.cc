// `zebrageo reconstruct SURVEY -o RESULTS`: the zebra bands of every stereo
// pair in 3D (body frame), written to RESULTS/reconstructed_bands.csv.
#include <glog/logging.h>

#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "reconstruction/reconstruction.h"
#include "survey/input_error.h"
#include "survey/results.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/exit_codes.h"
#include "tools/progress.h"
#include "tools/results_session.h"
#include "tools/stages.h"

namespace zebrageo {
namespace {

struct ReconstructArguments {
  StageArguments stage;
  int threads = 0;
  std::string debug_images;
  double nominal_camera_height_m =
      ReconstructionOptions().search.nominal_camera_height_m;
  double ground_pixel_m = ReconstructionOptions().rectification.ground_pixel_m;
  double min_long_side_length_m =
      ReconstructionOptions().long_sides.min_long_side_length_m;
  bool lines = false;  // also the road lines (issue 9)
};

ReconstructionOptions OptionsFrom(const ReconstructArguments& args) {
  ReconstructionOptions options;
  options.threads = args.threads;
  options.debug_image_folder = args.debug_images;
  options.search.nominal_camera_height_m = args.nominal_camera_height_m;
  options.rectification.ground_pixel_m = args.ground_pixel_m;
  options.long_sides.min_long_side_length_m = args.min_long_side_length_m;
  const std::string error = options.Check();
  if (!error.empty()) throw UsageError(error);
  return options;
}

void RunReconstruct(const ReconstructArguments& args) {
  const ReconstructionOptions options = OptionsFrom(args);
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kKeepOutputs);
  SurveyLoadOptions load_options = LoadOptionsOf(args.stage);
  load_options.load_roadmarks = false;
  const Survey survey = LoadSurvey(args.stage.survey, load_options);
  session.Open();
  ProgressBar bar("reconstruct");
  RoadPlane road_plane;
  RunReconstructStage(survey, options, args.stage.results, bar.Callback(),
                      &road_plane);
  bar.Finish();
  if (args.lines) {
    ProgressBar lines_bar("road lines");
    RunRoadLinesStage(survey, road_plane, RoadLineOptions(), args.threads,
                      args.stage.results, lines_bar.Callback());
    lines_bar.Finish();
  }
  session.Succeeded();
}

}  // namespace

void ThrowIfTooManyUnreadable(const Survey& survey,
                              const ReconstructionSummary& summary) {
  // Images that exist but cannot be decoded are only found here (loading
  // checks existence); the same share as for missing images makes the survey
  // invalid rather than quietly thin.
  const int total = static_cast<int>(survey.exposures.exposures.size());
  const double max_fraction = SurveyLoadOptions().max_missing_image_fraction;
  if (summary.exposures_skipped == 0 ||
      summary.exposures_skipped <= max_fraction * total) {
    return;
  }
  // The skipped exposures' warnings name the image and the problem.
  std::string first = "?";
  for (const std::string& warning : summary.warnings) {
    if (warning.find("skipped") != std::string::npos) {
      first = warning;
      break;
    }
  }
  std::ostringstream problem;
  problem << summary.exposures_skipped << " of " << total
          << " exposures have an unreadable image (more than "
          << max_fraction * 100 << "%); first: " << first;
  throw InputError(survey.manifest.exposures, 0, problem.str());
}

std::vector<std::string> RunReconstructStage(
    const Survey& survey, const ReconstructionOptions& options,
    const std::string& results_folder,
    const std::function<void(int, int)>& progress, RoadPlane* road_plane) {
  std::filesystem::create_directories(results_folder);
  std::vector<ReconstructedVertex> vertices;
  const ReconstructionSummary summary =
      ReconstructSurvey(survey, options, &vertices, progress);
  ThrowIfTooManyUnreadable(survey, summary);
  if (!summary.IsUsable()) throw StageFailedError(summary.message);
  if (road_plane != nullptr) *road_plane = summary.final_road_plane;

  StepTimings mean = summary.timings;
  const double n = std::max(1, summary.pairs_processed);
  mean.read_images_s /= n;
  mean.rectify_s /= n;
  mean.edges_s /= n;
  mean.matching_s /= n;
  mean.road_plane_s /= n;
  mean.long_sides_s /= n;
  mean.bands_s /= n;
  mean.debug_images_s /= n;
  std::vector<std::string> comments = {
      "zebrageo reconstruct: " + summary.BriefReport(),
      "per stereo pair: " + mean.Report()};
  for (const std::string& warning : summary.warnings) {
    comments.push_back("warning: " + warning);
  }
  std::vector<SkippedExposure> skipped;
  for (const auto& [exposure_id, reason] : summary.skipped_exposures) {
    skipped.push_back({exposure_id, reason});
  }
  WriteSkippedExposures(
      skipped,
      (std::filesystem::path(results_folder) / kSkippedExposuresFile).string());
  WriteReconstructedBands(
      vertices, comments,
      (std::filesystem::path(results_folder) / kReconstructedBandsFile)
          .string());
  LOG(INFO) << "reconstruct: " << summary.BriefReport() << " in "
            << summary.wall_time_s << " s";
  LOG(INFO) << "reconstruct: " << comments[1];
  return summary.warnings;
}

void AddReconstructCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<ReconstructArguments>();
  CLI::App* sub =
      AddStageSubcommand(app, "reconstruct",
                         "Reconstruct the zebra bands of every stereo pair in "
                         "3D; writes reconstructed_bands.csv (and "
                         "reconstructed_lines.csv with --lines).",
                         &args->stage);
  sub->add_option("--threads", args->threads,
                  "worker threads (0: one per hardware thread)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--debug-images", args->debug_images,
                  "write images with edges, candidates and bands to DIR");
  sub->add_option("--camera-height", args->nominal_camera_height_m,
                  "nominal height of the cameras over the road, metres (a "
                  "starting point: the road plane is estimated)")
      ->capture_default_str();
  sub->add_option("--ground-pixel", args->ground_pixel_m,
                  "ground sample distance of the rectified road images, m")
      ->capture_default_str();
  sub->add_option("--min-side-length", args->min_long_side_length_m,
                  "L_min: shortest long side of a band kept, metres")
      ->capture_default_str();
  sub->add_flag("--lines", args->lines,
                "also extract the lane and stop lines in 3D "
                "(reconstructed_lines.csv)");
  commands->push_back({sub, [args] { RunReconstruct(*args); }});
}

}  // namespace zebrageo
