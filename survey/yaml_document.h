// Parsing the survey's YAML files (survey.yaml, rig.yaml) with line-aware
// errors, shared by their readers.
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

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_YAML_DOCUMENT_H_
