// Exit status of the zebrageo command (README.md, "Exit status").
#ifndef ZEBRAGEO_PIPELINE_EXIT_CODES_H_
#define ZEBRAGEO_PIPELINE_EXIT_CODES_H_

#include <stdexcept>
#include <string>

namespace zebrageo {

enum ExitCode : int {
  kExitOk = 0,
  // The survey (or another input file) is invalid: the message names the
  // file, the line and the problem.
  kExitBadInput = 1,
  // The command line is wrong.
  kExitUsage = 2,
  // The input is valid but a stage could not produce a usable result.
  kExitStageFailed = 3,
  // The command or stage is not implemented in this version.
  kExitNotImplemented = 4,
  // A bug or an environment failure (disk full, out of memory).
  kExitInternalError = 5,
  // Cancelled (SIGINT, SIGTERM): the stage in progress wrote nothing, a
  // rerun resumes the stages before it.
  kExitCancelled = 6,
};

// Thrown by a command whose stage is not built yet: a clear error, never a
// fake result.
class NotImplementedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown when command-line values are inconsistent after parsing (a bad
// --set override, an unknown preset).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown when a stage ran on valid input but its result is not usable.
class StageFailedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_EXIT_CODES_H_
