// zebrageo: georeferences mobile-mapping surveys with zebra crossings as
// ground control. `zebrageo --help` lists the commands.
#include <glog/logging.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "pipeline/exit_codes.h"
#include "pipeline/version.h"
#include "survey/cancellation.h"
#include "survey/input_error.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

void ConfigureLogging(const std::string& level, int verbosity) {
  // Lines on their own, never glued to a progress bar; glog's prefix with
  // the source file and line for debug only.
  LogToConsole(level == "debug");
  FLAGS_colorlogtostderr = false;
  if (level == "error") FLAGS_minloglevel = google::GLOG_ERROR;
  if (level == "warning") FLAGS_minloglevel = google::GLOG_WARNING;
  if (level == "info" || level == "debug")
    FLAGS_minloglevel = google::GLOG_INFO;
  FLAGS_v = level == "debug" ? std::max(1, verbosity) : verbosity;
}

int Fail(ExitCode code, const std::string& message) {
  std::cerr << "zebrageo: error: " << message << std::endl;
  return code;
}

// The command the arguments name when it is not one of `app`'s ("" when
// they name a known one, or none): the first argument that is neither an
// option of zebrageo itself nor the value of one.
std::string UnknownCommand(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--log-level" || arg == "-v" || arg == "--verbosity") {
      ++i;
      continue;
    }
    if (arg.empty() || arg[0] == '-') continue;
    try {
      app.get_subcommand(arg);
      return "";
    } catch (const CLI::OptionNotFound&) {
      return arg;
    }
  }
  return "";
}

std::string CommandNames(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub :
       app.get_subcommands([](const CLI::App*) { return true; })) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  return names;
}

int Main(int argc, char** argv) {
  CLI::App app{
      "zebrageo " ZEBRAGEO_VERSION_STRING
      ": centimetre georeferencing of mobile-mapping surveys, with zebra "
      "crossings as ground control points."};
  app.set_version_flag("--version", "zebrageo " ZEBRAGEO_VERSION_STRING);
  app.require_subcommand(1);
  // Options of zebrageo itself (--log-level, -v) after the command's name
  // too: the subcommands, which inherit this, pass them up.
  app.fallthrough();
  std::string log_level = "info";
  int verbosity = 0;
  app.add_option("--log-level", log_level, "error, warning, info or debug")
      ->check(CLI::IsMember({"error", "warning", "info", "debug"}))
      ->capture_default_str();
  app.add_option("-v,--verbosity", verbosity, "detail of debug logging (VLOG)")
      ->check(CLI::Range(0, 3));
  app.footer(
      "Exit status: 0 success (warnings in report.json), 1 invalid input, "
      "2 usage, 3 stage failed, 4 not implemented, 5 internal error, "
      "6 cancelled.");

  std::vector<Command> commands;
  AddSimulateCommand(&app, &commands);
  AddCheckCommand(&app, &commands);
  AddReconstructCommand(&app, &commands);
  AddMatchCommand(&app, &commands);
  AddAdjustCommand(&app, &commands);
  AddRunCommands(&app, &commands);
  AddImportOpenCvStereoCommand(&app, &commands);
  AddImportCalibrationCommands(&app, &commands);
  AddImportTrajectoryCommand(&app, &commands);
  AddInitCommand(&app, &commands);
  AddExportGcpCommand(&app, &commands);
  AddServeCommand(&app, &commands);
  AddCampaignCommands(&app, &commands);

  const std::string unknown = UnknownCommand(app, argc, argv);
  if (!unknown.empty()) {
    return Fail(kExitUsage, "unknown command '" + unknown +
                                "'; the commands are: " + CommandNames(app) +
                                " (zebrageo --help describes them)");
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? kExitOk : kExitUsage;
  }
  ConfigureLogging(log_level, verbosity);

  try {
    for (const Command& command : commands) {
      if (command.subcommand->parsed()) command.run();
    }
  } catch (const InputError& error) {
    return Fail(kExitBadInput, error.what());
  } catch (const UsageError& error) {
    return Fail(kExitUsage, error.what());
  } catch (const NotImplementedError& error) {
    return Fail(kExitNotImplemented, error.what());
  } catch (const StageFailedError& error) {
    return Fail(kExitStageFailed, error.what());
  } catch (const CancelledError&) {
    return Fail(kExitCancelled,
                "cancelled: the stage in progress wrote nothing; run the "
                "command again to resume");
  } catch (const std::bad_alloc&) {
    return Fail(kExitInternalError, "out of memory");
  } catch (const std::exception& error) {
    return Fail(kExitInternalError, error.what());
  }
  return kExitOk;
}

}  // namespace
}  // namespace zebrageo

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  // Every stage runs its own workers over exposures (--threads); OpenCV's
  // pool parallelising each call inside them only oversubscribes the cores
  // (its workers spin while ours wait): about 9 % more CPU and 10 % more
  // wall time for the zebra stage on 2 cores (issue 46).
  cv::setNumThreads(1);
  return zebrageo::Main(argc, argv);
}
