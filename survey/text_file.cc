#include "survey/text_file.h"

#include <fstream>
#include <sstream>

#include "survey/input_error.h"

namespace zebrageo {

std::string ReadTextFile(const std::string& path,
                         const std::string& display_name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(display_name, 0, "cannot open " + path);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(display_name, 0, "cannot read " + path);
  return text.str();
}

}  // namespace zebrageo
