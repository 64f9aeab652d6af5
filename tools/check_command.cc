// `zebrageo check SURVEY`: loads and validates a survey, prints a summary.
#include <glog/logging.h>

#include <iostream>

#include "survey/survey.h"
#include "tools/commands.h"

namespace zebrageo {

void PrintSurveySummary(const Survey& survey) {
  const Trajectory& trajectory = survey.trajectory;
  std::cout << "survey " << survey.manifest.name << ": "
            << survey.rig.cameras.size() << " cameras, "
            << survey.rig.stereo_pairs.size() << " stereo pairs, "
            << trajectory.size() << " trajectory samples over "
            << trajectory.end_time() - trajectory.start_time() << " s, "
            << survey.exposures.exposures.size() << " exposures, "
            << survey.exposures.images.size() << " images, "
            << survey.roadmarks.bands.size() << " database bands, "
            << survey.roadmarks.lines.size() << " database lines\n";
  for (const std::string& warning : survey.warnings) {
    std::cout << "warning: " << warning << "\n";
  }
}

void AddCheckCommand(CLI::App* app, std::vector<Command>* commands) {
  auto folder = std::make_shared<std::string>();
  auto allow_outside_paths = std::make_shared<bool>(false);
  CLI::App* sub = app->add_subcommand(
      "check",
      "Validate a survey folder against the data contract and print a "
      "summary (exit 1 with file:line: problem if it is invalid).");
  sub->add_option("survey", *folder, "survey folder")->required();
  AddAllowOutsidePathsFlag(sub, allow_outside_paths.get());
  commands->push_back({sub, [folder, allow_outside_paths] {
                         SurveyLoadOptions options;
                         options.paths.allow_outside_paths =
                             *allow_outside_paths;
                         PrintSurveySummary(LoadSurvey(*folder, options));
                       }});
}

}  // namespace zebrageo
