// The command line itself (issue 47, point 6): an unknown command named as
// such with the list of commands, zebrageo's own options after the command
// too, and --threads meaning the same in every stage command.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

TEST(Cli, UnknownCommandIsNamedWithTheCommands) {
  TemporaryFolder folder;
  const std::string out = folder.Path("out"), err = folder.Path("err");
  EXPECT_EQ(RunZebrageo("bogus", out, err), 2);
  const std::string text = ReadWholeFile(err);
  EXPECT_NE(text.find("unknown command 'bogus'"), std::string::npos) << text;
  for (const char* command : {"simulate", "check", "run", "adjust", "serve"}) {
    EXPECT_NE(text.find(command), std::string::npos) << command << ": " << text;
  }
  EXPECT_EQ(text.find("A subcommand is required"), std::string::npos) << text;
  // After zebrageo's own options too.
  EXPECT_EQ(RunZebrageo("--log-level error bogus --threads 2", out, err), 2);
  EXPECT_NE(ReadWholeFile(err).find("unknown command 'bogus'"),
            std::string::npos);
  // No command at all stays CLI11's message.
  EXPECT_EQ(RunZebrageo("--log-level error", out, err), 2);
}

TEST(Cli, LogLevelAfterTheCommand) {
  TemporaryFolder folder;
  const std::string out = folder.Path("out"), err = folder.Path("err");
  for (const char* args : {"--log-level error run --print-options",
                           "run --print-options --log-level error",
                           "run --log-level=debug --print-options -v 2"}) {
    EXPECT_EQ(RunZebrageo(args, out, err), 0) << args << ReadWholeFile(err);
    EXPECT_NE(ReadWholeFile(out).find("\"threads\""), std::string::npos);
  }
  EXPECT_EQ(RunZebrageo("run --print-options --log-level loud", out, err), 2);
  EXPECT_NE(ReadWholeFile(err).find("--log-level"), std::string::npos)
      << ReadWholeFile(err);
}

// The --threads line of `zebrageo COMMAND --help`.
std::string ThreadsHelp(const std::string& command, TemporaryFolder* folder) {
  const std::string out = folder->Path("help.out");
  EXPECT_EQ(RunZebrageo(command + " --help", out, folder->Path("help.err")), 0);
  std::smatch line;
  const std::string text = ReadWholeFile(out);
  std::regex_search(text, line, std::regex("--threads[^\\n]*"));
  return line.str();
}

TEST(Cli, ThreadsMeanTheSameInEveryStageCommand) {
  TemporaryFolder folder;
  const std::string run = ThreadsHelp("run", &folder);
  EXPECT_NE(run.find("0: one per hardware thread"), std::string::npos) << run;
  EXPECT_EQ(ThreadsHelp("adjust", &folder), run);
  EXPECT_EQ(ThreadsHelp("reconstruct", &folder), run);
  // 0 is every hardware thread, the solver's too: accepted by both.
  const std::string out = folder.Path("out"), err = folder.Path("err");
  EXPECT_EQ(RunZebrageo("run --print-options --threads 0", out, err), 0)
      << ReadWholeFile(err);
  EXPECT_EQ(RunZebrageo("run --print-options --threads 3", out, err), 0);
  EXPECT_NE(ReadWholeFile(out).find("\"num_threads\": 3"), std::string::npos)
      << ReadWholeFile(out);
}

}  // namespace
}  // namespace zebrageo
