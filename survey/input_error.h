// Errors in files given to zebrageo.
//
// Files are untrusted input: every reader throws InputError naming the file,
// the line (1-based, 0 when the problem is not tied to a line) and what is
// wrong, e.g. "trajectory.csv:213: heading "abc" is not a number". The CLI
// catches it once, prints it and exits with kExitBadInput. Bugs in our own
// code are not InputErrors: they are CHECKs.
#ifndef ZEBRAGEO_SURVEY_INPUT_ERROR_H_
#define ZEBRAGEO_SURVEY_INPUT_ERROR_H_

#include <stdexcept>
#include <string>

namespace zebrageo {

class InputError : public std::runtime_error {
 public:
  // `file` is the path as the user gave it (or as the manifest names it).
  InputError(const std::string& file, int line, const std::string& problem);

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  int line_;
  std::string problem_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_INPUT_ERROR_H_
