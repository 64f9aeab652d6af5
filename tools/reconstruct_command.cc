// `zebrageo reconstruct SURVEY -o RESULTS`.
#include <memory>

#include "tools/commands.h"

namespace zebrageo {

void AddReconstructCommand(CLI::App* app, std::vector<Command>* commands) {
  auto args = std::make_shared<StageArguments>();
  CLI::App* sub =
      AddStageSubcommand(app, "reconstruct",
                         "Reconstruct the zebra bands of every stereo pair in "
                         "3D; writes reconstructed_bands.csv.",
                         args.get());
  commands->push_back(
      {sub, NotImplementedStage(args, "reconstruct", "issue 5")});
}

}  // namespace zebrageo
