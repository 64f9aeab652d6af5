// `zebrageo adjust SURVEY -o RESULTS`.
#include <memory>

#include "tools/commands.h"

namespace zebrageo {

void AddAdjustCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<StageArguments>();
  CLI::App* sub = AddStageSubcommand(
      app, "adjust",
      "Bundle-adjust the trajectory with the matched band vertices as ground "
      "control; writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv.",
      args.get());
  commands->push_back({sub, NotImplementedStage(args, "adjust", "issue 7")});
}

}  // namespace zebrageo
