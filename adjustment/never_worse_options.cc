#include "adjustment/never_worse_options.h"

#include <sstream>
#include <string>

namespace zebrageo {
namespace {

std::string Violation(const char* field, double value, const char* rule) {
  std::ostringstream message;
  message << "never_worse." << field << " = " << value << ": " << rule;
  return message.str();
}

}  // namespace

std::string NeverWorseOptions::Check() const {
  if (!(outage_min_jump_m >= 0.0)) {
    return Violation("outage_min_jump_m", outage_min_jump_m, "must be >= 0");
  }
  if (!(outage_min_length_s > 0.0)) {
    return Violation("outage_min_length_s", outage_min_length_s, "must be > 0");
  }
  if (!(outage_max_length_s >= outage_min_length_s)) {
    return Violation("outage_max_length_s", outage_max_length_s,
                     "must be >= outage_min_length_s");
  }
  if (!(gnss_return_decay_s > 0.0)) {
    return Violation("gnss_return_decay_s", gnss_return_decay_s, "must be > 0");
  }
  if (!(guard_sigmas >= 0.0)) {
    return Violation("guard_sigmas", guard_sigmas, "must be >= 0");
  }
  if (!(guard_min_difference_m >= 0.0)) {
    return Violation("guard_min_difference_m", guard_min_difference_m,
                     "must be >= 0");
  }
  if (!(guard_crossing_sigma_m > 0.0)) {
    return Violation("guard_crossing_sigma_m", guard_crossing_sigma_m,
                     "must be > 0");
  }
  return "";
}

}  // namespace zebrageo
