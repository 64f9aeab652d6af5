// `zebrageo reconstruct SURVEY -o RESULTS`: the zebra bands of every stereo
// pair in 3D (body frame), written to RESULTS/reconstructed_bands.csv
// (pipeline/reconstruct_stage.h).
#include <memory>
#include <string>
#include <vector>

#include "pipeline/exit_codes.h"
#include "pipeline/reconstruct_stage.h"
#include "pipeline/results_session.h"
#include "pipeline/run_options.h"
#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

struct ReconstructArguments {
  StageArguments stage;
  int threads = 0;
  std::string debug_images;
  double nominal_camera_height_m =
      RunOptions().reconstruction.search.nominal_camera_height_m;
  double ground_pixel_m =
      RunOptions().reconstruction.rectification.ground_pixel_m;
  double min_long_side_length_m =
      RunOptions().reconstruction.long_sides.min_long_side_length_m;
  bool lines = false;  // also the road lines (issue 9)
};

RunOptions OptionsFrom(const ReconstructArguments& args) {
  RunOptions options;
  options.lines = args.lines;
  options.threads = args.threads;
  ReconstructionOptions& reconstruction = options.reconstruction;
  reconstruction.threads = args.threads;
  reconstruction.debug_image_folder = args.debug_images;
  reconstruction.search.nominal_camera_height_m = args.nominal_camera_height_m;
  reconstruction.rectification.ground_pixel_m = args.ground_pixel_m;
  reconstruction.long_sides.min_long_side_length_m =
      args.min_long_side_length_m;
  const std::string error = options.Check();
  if (!error.empty()) throw UsageError(error);
  return options;
}

void RunReconstruct(const ReconstructArguments& args) {
  const RunOptions options = OptionsFrom(args);
  ResultsSession session(args.stage.results,
                         ResultsSession::OnError::kKeepOutputs);
  SurveyLoadOptions load_options = LoadOptionsOf(args.stage);
  load_options.load_roadmarks = false;
  const Survey survey = LoadSurvey(args.stage.survey, load_options);
  session.Open();
  ProgressBar bar("reconstruct");
  StageResults results(args.stage.results);
  RunReconstructStage(survey, &results, options, bar.Callback(), ProgressBars(),
                      CancelOnSignal());
  bar.Finish();
  session.Succeeded();
}

}  // namespace

void AddReconstructCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<ReconstructArguments>();
  CLI::App* sub =
      AddStageSubcommand(app, "reconstruct",
                         "Reconstruct the zebra bands of every stereo pair in "
                         "3D; writes reconstructed_bands.csv (and "
                         "reconstructed_lines.csv with --lines).",
                         &args->stage);
  AddThreadsOption(sub, &args->threads);
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
