// Damaged copies of a valid input file for the readers' tests: every
// truncation and every one-byte corruption must either parse to a result
// the test checks, or be refused with an InputError that names the file, a
// line of the damaged text (or none) and a problem, never another exception
// and never a crash.
#ifndef ZEBRAGEO_TESTS_SURVEY_DAMAGED_INPUT_H_
#define ZEBRAGEO_TESTS_SURVEY_DAMAGED_INPUT_H_

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "survey/input_error.h"

namespace zebrageo {

struct DamageCounts {
  int parsed = 0;   // damaged copies that still parsed (and passed the check)
  int refused = 0;  // damaged copies refused with a well-formed InputError
};

// Checks one InputError against the damaged `text` read as `file`.
inline void ExpectNamedInputError(const InputError& error,
                                  const std::string& file,
                                  const std::string& text) {
  EXPECT_EQ(error.file(), file) << error.what();
  const int lines =
      1 + static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  EXPECT_GE(error.line(), 0) << error.what();
  EXPECT_LE(error.line(), lines) << error.what();
  EXPECT_FALSE(error.problem().empty()) << error.what();
  const std::string where =
      error.line() > 0 ? file + ":" + std::to_string(error.line()) : file;
  EXPECT_EQ(std::string(error.what()), where + ": " + error.problem());
}

// Runs `parse(damaged)` on every prefix of `text` and on every copy with one
// byte replaced by one of `bytes`. `parse` reads the text as `file` and
// checks what it parsed (gtest assertions); it may throw InputError.
inline DamageCounts ParseDamagedCopies(
    const std::string& text, const std::string& file,
    const std::vector<char>& bytes,
    const std::function<void(const std::string&)>& parse) {
  DamageCounts counts;
  auto run = [&](const std::string& damaged, const std::string& what) {
    SCOPED_TRACE(what);
    try {
      parse(damaged);
      ++counts.parsed;
    } catch (const InputError& error) {
      ExpectNamedInputError(error, file, damaged);
      ++counts.refused;
    }
  };
  for (size_t length = 0; length < text.size(); ++length) {
    run(text.substr(0, length), "truncated to " + std::to_string(length));
  }
  for (size_t at = 0; at < text.size(); ++at) {
    for (const char c : bytes) {
      std::string corrupted = text;
      corrupted[at] = c;
      run(corrupted, "byte " + std::to_string(at) + " replaced by " +
                         std::to_string(static_cast<unsigned char>(c)));
    }
  }
  return counts;
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_SURVEY_DAMAGED_INPUT_H_
