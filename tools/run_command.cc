// `zebrageo run SURVEY -o RESULTS` and `zebrageo report SURVEY -o RESULTS`.
#include <memory>

#include "tools/commands.h"

namespace zebrageo {

void AddRunCommands(CLI::App* app, std::vector<Command>* commands) {
  auto run_args = std::make_shared<StageArguments>();
  CLI::App* run = AddStageSubcommand(
      app, "run", "All stages (reconstruct, match, adjust), then the report.",
      run_args.get());
  commands->push_back({run, NotImplementedStage(run_args, "run", "issue 8")});
  auto report_args = std::make_shared<StageArguments>();
  CLI::App* report = AddStageSubcommand(
      app, "report",
      "Write report.json and report.html from an existing results folder.",
      report_args.get());
  commands->push_back(
      {report, NotImplementedStage(report_args, "report", "issue 8")});
}

}  // namespace zebrageo
