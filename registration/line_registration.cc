#include "registration/line_registration.h"

#include "survey/option_check.h"

namespace zebrageo {

std::string LineRegistrationOptions::Check() const {
  OptionCheck check;
  OPTION_NESTED(check, lines);
  OPTION_NESTED(check, consistency);
  OPTION_NESTED(check, lateral_offsets);
  OPTION_NESTED(check, dashes);
  OPTION_NESTED(check, crossing_edges);
  return check.problem();
}

}  // namespace zebrageo
