// `zebrageo simulate --preset NAME --seed N -o SURVEY`: writes a simulated
// survey with its ground truth (truth/).
#include <memory>
#include <string>

#include "tools/commands.h"
#include "tools/exit_codes.h"

namespace zebrageo {

void AddSimulateCommand(CLI::App* app, std::vector<Command>* commands) {
  auto output = std::make_shared<std::string>();
  CLI::App* sub = app->add_subcommand(
      "simulate", "Write a simulated survey with its ground truth in truth/.");
  sub->add_option("-o,--output", *output, "survey folder to write")->required();
  sub->allow_extras();
  commands->push_back({sub, [] {
                         throw NotImplementedError(
                             "the simulator is not implemented yet (issue 4)");
                       }});
}

}  // namespace zebrageo
