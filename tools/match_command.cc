// `zebrageo match SURVEY -o RESULTS`.
#include <memory>

#include "tools/commands.h"

namespace zebrageo {

void AddMatchCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<StageArguments>();
  CLI::App* sub = AddStageSubcommand(
      app, "match",
      "Match reconstructed bands to the road-mark database; writes "
      "matches.csv and crossing_decisions.csv.",
      args.get());
  commands->push_back({sub, NotImplementedStage(args, "match", "issue 6")});
}

}  // namespace zebrageo
