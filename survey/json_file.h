// Reading a JSON file of the results folder (adjustment.json,
// line_control.json, match_evidence.json...), with the contract's errors.
#ifndef ZEBRAGEO_SURVEY_JSON_FILE_H_
#define ZEBRAGEO_SURVEY_JSON_FILE_H_

#include <nlohmann/json.hpp>
#include <string>

namespace zebrageo {

// The parsed file; InputError naming display_name when it cannot be opened
// ("cannot open PATH") or is not JSON ("malformed JSON: ...").
nlohmann::json ReadJsonFile(const std::string& path,
                            const std::string& display_name);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_JSON_FILE_H_
