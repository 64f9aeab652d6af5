#include "survey/option_json.h"

namespace zebrageo {
namespace option_json_internal {

std::string Describe(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(value.type_name()) + " " + text;
}

}  // namespace option_json_internal

void OptionsJsonReader::RefuseUnknownMembers() const {
  for (const auto& [name, value] : json_.items()) {
    if (known_.count(name)) continue;
    std::string names;
    for (const std::string& known : known_) {
      names += (names.empty() ? "" : ", ") + known;
    }
    throw OptionsJsonError(
        Key(name) + ": not an option (" +
        (path_.empty() ? std::string("options") : path_ + " has") + ": " +
        names + ")");
  }
}

}  // namespace zebrageo
