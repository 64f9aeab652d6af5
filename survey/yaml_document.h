// Parsing the survey's YAML files (survey.yaml, rig.yaml) with line-aware
// errors, shared by their readers; quoting for their writers.
#ifndef ZEBRAGEO_SURVEY_YAML_DOCUMENT_H_
#define ZEBRAGEO_SURVEY_YAML_DOCUMENT_H_

#include <yaml-cpp/yaml.h>

#include <string>

namespace zebrageo {

// 1-based line of `node` for messages (yaml-cpp counts from 0), 0 if unknown.
int YamlLine(const YAML::Node& node);

// Parses `text` (a leading UTF-8 byte-order mark is allowed). Throws
// InputError naming `display_name` and the line: malformed YAML, or a key
// given twice in one mapping down to `max_key_depth` levels of nesting
// (yaml-cpp silently keeps the first value where other readers keep the
// last, so a repeated key means two readers may see two different surveys).
// The depth bound keeps the check linear in the file's size even when
// aliases make the document exponentially large (a "YAML bomb").
YAML::Node ParseYamlDocument(const std::string& text,
                             const std::string& display_name,
                             int max_key_depth = 3);

// `text` as a YAML scalar for the writers: plain when it can only be read
// as a string (a letter, then letters, digits, '_', '-', '.' or a character
// of `also_plain`, and no YAML 1.1 boolean or null such as "yes" or "off"),
// double-quoted otherwise ("1", "a: b").
std::string YamlScalar(const std::string& text, const char* also_plain = "");

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_YAML_DOCUMENT_H_
