#include "adjustment/never_worse_options.h"

#include <string>

#include "survey/option_check.h"

namespace zebrageo {

std::string NeverWorseOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, outage_min_jump_m, 0.0);  // 0 disables
  OPTION_GT(check, outage_min_length_s, 0.0);
  OPTION_GE(check, outage_max_length_s, outage_min_length_s);
  OPTION_GT(check, gnss_return_decay_s, 0.0);
  OPTION_GE(check, guard_sigmas, 0.0);  // 0 disables
  OPTION_GE(check, guard_min_difference_m, 0.0);
  OPTION_GT(check, guard_crossing_sigma_m, 0.0);
  return check.problem();
}

}  // namespace zebrageo
