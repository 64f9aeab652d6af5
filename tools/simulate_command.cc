// `zebrageo simulate --preset NAME --seed N -o SURVEY`: writes a simulated
// survey with its ground truth (truth/).
#include <glog/logging.h>

#include <memory>
#include <string>
#include <vector>

#include "pipeline/exit_codes.h"
#include "simulator/bad_survey.h"
#include "simulator/simulator.h"
#include "survey/input_error.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

struct SimulateArguments {
  std::string preset = "demo";
  uint64_t seed = 1;
  std::string output;
  std::vector<std::string> overrides;
  bool no_images = false;
  std::string bad;
  double max_road_length_m = RandomPresetLimits().max_road_length_m;
  int junctions = RandomPresetLimits().junctions;
  int avenues = RandomPresetLimits().avenues;
};

}  // namespace

void AddSimulateCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<SimulateArguments>();
  CLI::App* sub = app->add_subcommand(
      "simulate",
      "Write a simulated survey (images, trajectory with GNSS/INS drift, "
      "road-mark database) with its ground truth in truth/.");
  sub->add_option("--preset", args->preset,
                  "demo, urban, outage, sparse, ambiguity, large, junctions, "
                  "avenue or random (every knob drawn from the seed)")
      ->capture_default_str();
  sub->add_option("--seed", args->seed, "random seed")->capture_default_str();
  sub->add_option("-o,--output", args->output, "survey folder to write")
      ->required();
  sub->add_option("--set", args->overrides,
                  "override a knob of the preset, e.g. --set road_length_m=300 "
                  "(repeatable; see datasets/README.md)");
  sub->add_option("--bad", args->bad,
                  "write a small broken survey of this kind for the "
                  "bad-input suite (truth/meta.json says what to expect; "
                  "kinds in docs/input-checks.md)");
  sub->add_option("--max-road-length", args->max_road_length_m,
                  "random preset: the longest road drawn, metres (from 60)")
      ->capture_default_str();
  sub->add_option("--junctions", args->junctions,
                  "random preset: this many junctions (side streets with "
                  "crossings across them, drawn as the preset draws them); "
                  "-1 drawn (half the surveys)")
      ->capture_default_str();
  sub->add_option("--avenues", args->avenues,
                  "random preset: 1 an avenue (median, refuge islands "
                  "splitting the crossings, lanes; issue 52), 0 none, -1 "
                  "drawn (one survey in five); default none")
      ->capture_default_str()
      ->check(CLI::Range(-1, 1));
  sub->add_flag("--no-images", args->no_images,
                "write only the geometry (no rendering)");
  commands->push_back(
      {sub, [args] {
         SimulationOptions options;
         // The random preset draws from the seed: set it first.
         options.seed = args->seed;
         std::string error;
         if (args->preset == "random") {
           RandomPresetLimits limits;
           limits.max_road_length_m = args->max_road_length_m;
           limits.junctions = args->junctions;
           limits.avenues = args->avenues;
           error = DrawRandomOptions(args->seed, limits, &options);
         } else {
           error = ApplyPreset(args->preset, &options);
         }
         if (!error.empty()) throw UsageError(error);
         if (!args->bad.empty()) {
           error = ApplyBadSurveySettings(args->bad, &options);
           if (!error.empty()) throw UsageError(error);
         }
         for (const std::string& item : args->overrides) {
           error = SetOption(item, &options);
           if (!error.empty()) throw UsageError("--set " + item + ": " + error);
         }
         if (args->no_images) options.render_images = false;
         error = options.Check();
         if (!error.empty()) throw UsageError(error);
         ProgressBar progress("simulate");
         SimulateSurvey(options, args->output, progress.Callback());
         progress.Finish();
         if (!args->bad.empty()) BreakSurvey(args->bad, args->output);
         LOG(INFO) << "wrote survey " << args->output;
       }});
}

}  // namespace zebrageo
