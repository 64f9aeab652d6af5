#include "survey/input_error.h"

namespace zebrageo {
namespace {

// A problem quotes the offending bytes of an untrusted file: a NUL among them
// would cut what() (a C string) short of the problem, and other control
// bytes would reach the terminal. They are shown as \xNN; line breaks and
// tabs are kept.
std::string Printable(const std::string& problem) {
  static const char kHex[] = "0123456789abcdef";
  std::string shown;
  shown.reserve(problem.size());
  for (const char c : problem) {
    const unsigned char byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && c != '\n' && c != '\t') || byte == 0x7f) {
      shown += "\\x";
      shown += kHex[byte >> 4];
      shown += kHex[byte & 0xf];
    } else {
      shown += c;
    }
  }
  return shown;
}

std::string FormatMessage(const std::string& file, int line,
                          const std::string& problem) {
  if (line > 0) return file + ":" + std::to_string(line) + ": " + problem;
  return file + ": " + problem;
}

}  // namespace

InputError::InputError(const std::string& file, int line,
                       const std::string& problem)
    : std::runtime_error(FormatMessage(file, line, Printable(problem))),
      file_(file),
      line_(line),
      problem_(Printable(problem)) {}

}  // namespace zebrageo
