#include "survey/json_file.h"

#include <fstream>

#include "survey/input_error.h"

namespace zebrageo {

nlohmann::json ReadJsonFile(const std::string& path,
                            const std::string& display_name) {
  std::ifstream in(path);
  if (!in) throw InputError(display_name, 0, "cannot open " + path);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(display_name, 0,
                     std::string("malformed JSON: ") + error.what());
  }
}

}  // namespace zebrageo
