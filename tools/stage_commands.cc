// What the stage commands share.
#include <memory>
#include <string>

#include "survey/survey.h"
#include "tools/commands.h"
#include "tools/exit_codes.h"

namespace zebrageo {

CLI::App* AddStageSubcommand(CLI::App* app, const std::string& name,
                             const std::string& description,
                             StageArguments* args) {
  CLI::App* sub = app->add_subcommand(name, description);
  sub->add_option("survey", args->survey, "survey folder")->required();
  sub->add_option("-o,--output", args->results, "results folder")->required();
  return sub;
}

void AddSideslipOption(CLI::App* subcommand, double* sideslip_sigma_deg) {
  subcommand
      ->add_option("--sideslip-sigma", *sideslip_sigma_deg,
                   "degrees: how far the vehicle's direction of travel may "
                   "depart from its heading (body oscillations); it holds "
                   "the heading between crossings. 0: not used")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
}

std::function<void()> NotImplementedStage(std::shared_ptr<StageArguments> args,
                                          const std::string& stage,
                                          const std::string& issue) {
  return [args, stage, issue] {
    LoadSurvey(args->survey);
    throw NotImplementedError("the " + stage +
                              " stage is not implemented yet (" + issue +
                              "); no results were written");
  };
}

}  // namespace zebrageo
