#include "survey/input_error.h"

namespace zebrageo {
namespace {

std::string FormatMessage(const std::string& file, int line,
                          const std::string& problem) {
  if (line > 0) return file + ":" + std::to_string(line) + ": " + problem;
  return file + ": " + problem;
}

}  // namespace

InputError::InputError(const std::string& file, int line,
                       const std::string& problem)
    : std::runtime_error(FormatMessage(file, line, problem)),
      file_(file),
      line_(line),
      problem_(problem) {}

}  // namespace zebrageo
