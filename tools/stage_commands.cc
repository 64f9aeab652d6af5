// What the stage commands share.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "pipeline/exit_codes.h"
#include "pipeline/run_options.h"
#include "survey/survey.h"
#include "tools/commands.h"

namespace zebrageo {

CLI::App* AddStageSubcommand(CLI::App* app, const std::string& name,
                             const std::string& description,
                             StageArguments* args) {
  CLI::App* sub = app->add_subcommand(name, description);
  sub->add_option("survey", args->survey, "survey folder")->required();
  // A results path that names a file is a mistake on the command line.
  const CLI::Validator not_a_file(
      [](std::string& path) -> std::string {
        std::error_code error;
        const auto status = std::filesystem::status(path, error);
        if (std::filesystem::exists(status) &&
            !std::filesystem::is_directory(status)) {
          return path + " is a file, not a results folder";
        }
        return "";
      },
      "FOLDER");
  sub->add_option("-o,--output", args->results, "results folder")
      ->required()
      ->check(not_a_file);
  AddAllowOutsidePathsFlag(sub, &args->allow_outside_paths);
  return sub;
}

void AddAllowOutsidePathsFlag(CLI::App* subcommand, bool* allow) {
  subcommand->add_flag(
      "--allow-outside-paths", *allow,
      "read survey files named with an absolute path or resolving outside "
      "the survey folder (symbolic links included): for your own surveys "
      "only, never for surveys from others");
}

SurveyLoadOptions LoadOptionsOf(const StageArguments& args) {
  SurveyLoadOptions options;
  options.paths.allow_outside_paths = args.allow_outside_paths;
  return options;
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

CLI::Option* AddThreadsOption(CLI::App* subcommand, int* threads) {
  return subcommand
      ->add_option("--threads", *threads,
                   "worker threads of each stage (0: one per hardware "
                   "thread); unset: the options' (run --print-options)")
      ->check(CLI::NonNegativeNumber);
}

void ApplyThreadsOption(const CLI::Option& option, int threads,
                        RunOptions* options) {
  if (option.count() == 0) return;
  options->threads = threads;
  options->reconstruction.threads = threads;
  options->adjustment.solver.num_threads =
      threads > 0
          ? threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

namespace {

// The flag SIGINT and SIGTERM set (a lock-free atomic store is
// async-signal-safe); a second signal ends the process at once.
std::atomic<bool>* signal_flag = nullptr;

extern "C" void OnCancelSignal(int signal_number) {
  if (signal_flag->exchange(true)) {
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
  }
}

}  // namespace

CancellationToken CancelOnSignal() {
  static const CancellationToken token = [] {
    CancellationToken t = CancellationToken::Cancellable();
    signal_flag = t.flag();
    struct sigaction action {};
    action.sa_handler = OnCancelSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return t;
  }();
  return token;
}

std::function<void()> NotImplementedStage(std::shared_ptr<StageArguments> args,
                                          const std::string& stage,
                                          const std::string& issue) {
  return [args, stage, issue] {
    LoadSurvey(args->survey, LoadOptionsOf(*args));
    throw NotImplementedError("the " + stage +
                              " stage is not implemented yet (" + issue +
                              "); no results were written");
  };
}

}  // namespace zebrageo
