#include "survey/yaml_document.h"

#include <cctype>
#include <map>
#include <string>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

void ThrowOnDuplicateKeys(const YAML::Node& node,
                          const std::string& display_name, int depth) {
  if (depth <= 0) return;
  if (node.IsMap()) {
    std::map<std::string, int> first_line;  // key -> line
    for (const auto& pair : node) {
      if (pair.first.IsScalar()) {
        const auto [it, inserted] =
            first_line.emplace(pair.first.Scalar(), YamlLine(pair.first));
        if (!inserted) {
          throw InputError(
              display_name, YamlLine(pair.first),
              "duplicate key '" + pair.first.Scalar() + "' (first on line " +
                  std::to_string(it->second) + "): give each key once");
        }
      }
      ThrowOnDuplicateKeys(pair.second, display_name, depth - 1);
    }
  } else if (node.IsSequence()) {
    for (const YAML::Node& child : node) {
      ThrowOnDuplicateKeys(child, display_name, depth - 1);
    }
  }
}

}  // namespace

int YamlLine(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

YAML::Node ParseYamlDocument(const std::string& text,
                             const std::string& display_name,
                             int max_key_depth) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(display_name, e.mark.is_null() ? 0 : e.mark.line + 1,
                     "malformed YAML: " + e.msg);
  }
  ThrowOnDuplicateKeys(root, display_name, max_key_depth);
  return root;
}

std::string YamlScalar(const std::string& text, const char* also_plain) {
  const std::string extra = also_plain;
  bool plain =
      !text.empty() && std::isalpha(static_cast<unsigned char>(text.front()));
  for (char c : text) {
    plain =
        plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                  c == '-' || c == '.' || extra.find(c) != std::string::npos);
  }
  std::string lower;
  for (char c : text) {
    lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  for (const char* keyword :
       {"y", "n", "yes", "no", "true", "false", "on", "off", "null"}) {
    plain = plain && lower != keyword;
  }
  if (plain) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace zebrageo
