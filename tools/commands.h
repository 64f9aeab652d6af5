// The subcommands of `zebrageo`. Each adds itself to the CLI11 app and, when
// chosen, runs by calling the libraries: no algorithm lives in tools/.
#ifndef ZEBRAGEO_TOOLS_COMMANDS_H_
#define ZEBRAGEO_TOOLS_COMMANDS_H_

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "survey/cancellation.h"
#include "survey/survey.h"

namespace zebrageo {

struct RunOptions;

struct Command {
  CLI::App* subcommand = nullptr;
  // Runs the command after parsing. Throws InputError, NotImplementedError
  // or StageFailedError; main maps them to exit codes.
  std::function<void()> run;
};

void AddSimulateCommand(CLI::App* app, std::vector<Command>* commands);
void AddCheckCommand(CLI::App* app, std::vector<Command>* commands);
// One file per stage command: tools/<stage>_command.cc.
void AddReconstructCommand(CLI::App* app, std::vector<Command>* commands);
void AddMatchCommand(CLI::App* app, std::vector<Command>* commands);
void AddAdjustCommand(CLI::App* app, std::vector<Command>* commands);
// run and report.
void AddRunCommands(CLI::App* app, std::vector<Command>* commands);

// The arguments every stage command takes: SURVEY -o RESULTS
// [--allow-outside-paths].
struct StageArguments {
  std::string survey;
  std::string results;
  // Accept survey files outside the survey folder (survey/survey_paths.h).
  bool allow_outside_paths = false;
};
// Adds a stage subcommand with its arguments bound to `args`. A RESULTS
// that is an existing file is a usage error (exit 2).
CLI::App* AddStageSubcommand(CLI::App* app, const std::string& name,
                             const std::string& description,
                             StageArguments* args);
// Adds --allow-outside-paths to `subcommand`.
void AddAllowOutsidePathsFlag(CLI::App* subcommand, bool* allow);
// How a stage command loads its survey.
SurveyLoadOptions LoadOptionsOf(const StageArguments& args);
// A token SIGINT and SIGTERM cancel (the handlers are installed on the first
// call): the stage in progress stops at its next checkpoint and writes
// nothing; main exits with kExitCancelled. A second signal ends the process
// at once.
CancellationToken CancelOnSignal();
// --sideslip-sigma of adjust and run (AdjustmentOptions::sideslip_sigma_rad, in
// degrees here).
void AddSideslipOption(CLI::App* subcommand, double* sideslip_sigma_deg);
// --threads of run, reconstruct and adjust: one meaning in all three.
CLI::Option* AddThreadsOption(CLI::App* subcommand, int* threads);
// When --threads was given: every stage's threads, 0 one per hardware
// thread (the solver's too); else the options' own (RunOptions defaults).
void ApplyThreadsOption(const CLI::Option& option, int threads,
                        RunOptions* options);
// A runner for a stage that is not built yet: it validates the survey (so
// the user learns whether it is readable), then throws NotImplementedError.
std::function<void()> NotImplementedStage(std::shared_ptr<StageArguments> args,
                                          const std::string& stage,
                                          const std::string& issue);
void AddImportOpenCvStereoCommand(CLI::App* app,
                                  std::vector<Command>* commands);
// import-kalibr, import-ros-camera-info.
void AddImportCalibrationCommands(CLI::App* app,
                                  std::vector<Command>* commands);
void AddImportTrajectoryCommand(CLI::App* app, std::vector<Command>* commands);
// init (tools/init_command.cc).
void AddInitCommand(CLI::App* app, std::vector<Command>* commands);
// What `check` prints about a loaded survey (tools/check_command.cc).
void PrintSurveySummary(const Survey& survey);
// export-gcp (tools/export_command.cc).
void AddExportGcpCommand(CLI::App* app, std::vector<Command>* commands);
// plan, run-block, merge (tools/campaign_commands.cc).
void AddCampaignCommands(CLI::App* app, std::vector<Command>* commands);
// serve (tools/serve_command.cc).
void AddServeCommand(CLI::App* app, std::vector<Command>* commands);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TOOLS_COMMANDS_H_
