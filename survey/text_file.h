// A whole file read as text, with the contract's errors.
#ifndef ZEBRAGEO_SURVEY_TEXT_FILE_H_
#define ZEBRAGEO_SURVEY_TEXT_FILE_H_

#include <string>

namespace zebrageo {

// The file's bytes; InputError naming `display_name` when it cannot be
// opened ("cannot open PATH") or read ("cannot read PATH").
std::string ReadTextFile(const std::string& path,
                         const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_TEXT_FILE_H_
