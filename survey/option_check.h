// Checked options: every options struct's Check() in one style, after
// Ceres' OPTION_GE (solver.cc) and COLMAP's CHECK_OPTION_GE. The field is
// named once, by the macro, so a message can never name another field:
//
//   std::string SolverOptions::Check() const {
//     OptionCheck check;
//     OPTION_GE(check, num_threads, 1);
//     OPTION_GE(check, max_sparse_pose_blocks, max_dense_pose_blocks);
//     OPTION_IN(check, min_ncc, "(", -1.0, 1.0, ")");
//     OPTION_NESTED(check, sideways_switches);
//     return check.problem();
//   }
//
// The first violated constraint is kept, as "field = value: must be ...":
//   "num_threads = 0: must be >= 1"
//   "max_sparse_pose_blocks = 10: must be >= max_dense_pose_blocks (50)"
//   "min_ncc = 1: must be in (-1, 1)"
//   "sideways_switches.min_switch_m = -1: must be > 0"
// A floating-point field must be finite for every comparison. Constraints
// of their own go through OPTION_REQUIRE(check, holds, field, "what").
#ifndef ZEBRAGEO_SURVEY_OPTION_CHECK_H_
#define ZEBRAGEO_SURVEY_OPTION_CHECK_H_

#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

namespace zebrageo {

class OptionCheck {
 public:
  // "" while every constraint holds, else the first violation.
  const std::string& problem() const { return problem_; }
  bool ok() const { return problem_.empty(); }

  // `holds` is `value OP bound` as the macros evaluate it.
  template <typename T, typename U>
  void Compare(const char* field, const T& value, const char* op, bool holds,
               const U& bound, const char* bound_text) {
    if (!ok() || (holds && Finite(value))) return;
    std::ostringstream constraint;
    constraint << "must be " << op << " ";
    if (IsNumberLiteral(bound_text)) {
      constraint << bound;
    } else {
      constraint << bound_text << " (" << bound << ")";
    }
    Fail(field, value, constraint.str());
  }

  // lower < value < upper, with "[" / "]" for a closed end.
  template <typename T, typename U>
  void InRange(const char* field, const T& value, const char* open,
               const U& lower, const U& upper, const char* close) {
    if (!ok()) return;
    const bool closed_low = open[0] == '[';
    const bool closed_high = close[0] == ']';
    const bool above = closed_low ? value >= lower : value > lower;
    const bool below = closed_high ? value <= upper : value < upper;
    if (above && below && Finite(value)) return;
    std::ostringstream constraint;
    constraint << "must be in " << open << lower << ", " << upper << close;
    Fail(field, value, constraint.str());
  }

  // A constraint the comparisons do not express.
  template <typename T>
  void Require(bool holds, const char* field, const T& value,
               const std::string& constraint) {
    if (ok() && !holds) Fail(field, value, constraint);
  }

  // The problem of a nested group's Check(), prefixed with its name.
  void Nested(const char* group, const std::string& problem) {
    if (ok() && !problem.empty()) problem_ = std::string(group) + "." + problem;
  }

 private:
  template <typename T>
  static bool Finite(const T& value) {
    if constexpr (std::is_floating_point_v<T>) {
      return std::isfinite(value);
    } else {
      return true;
    }
  }

  // Whether the macro's bound is written as a number ("0.5", "-1"): the
  // message then shows the value alone, else the name and its value.
  static bool IsNumberLiteral(const char* text) {
    std::istringstream in(text);
    double number = 0.0;
    return (in >> number) && (in >> std::ws).eof();
  }

  template <typename T>
  void Fail(const char* field, const T& value, const std::string& constraint) {
    std::ostringstream message;
    message << field << " = ";
    if constexpr (std::is_same_v<T, bool>) {
      message << (value ? "true" : "false");
    } else {
      message << value;
    }
    message << ": " << constraint;
    problem_ = message.str();
  }

  std::string problem_;
};

}  // namespace zebrageo

#define ZEBRAGEO_OPTION_OP(check, field, op, bound) \
  (check).Compare(#field, (field), #op, (field)op(bound), (bound), #bound)
#define OPTION_GT(check, field, bound) \
  ZEBRAGEO_OPTION_OP(check, field, >, bound)
#define OPTION_GE(check, field, bound) \
  ZEBRAGEO_OPTION_OP(check, field, >=, bound)
#define OPTION_LT(check, field, bound) \
  ZEBRAGEO_OPTION_OP(check, field, <, bound)
#define OPTION_LE(check, field, bound) \
  ZEBRAGEO_OPTION_OP(check, field, <=, bound)
// OPTION_IN(check, share, "[", 0.0, 1.0, ")"): 0 <= share < 1.
#define OPTION_IN(check, field, open, lower, upper, close) \
  (check).InRange(#field, (field), open, lower, upper, close)
#define OPTION_REQUIRE(check, holds, field, constraint) \
  (check).Require((holds), #field, (field), constraint)
#define OPTION_NESTED(check, group) (check).Nested(#group, (group).Check())

#endif  // ZEBRAGEO_SURVEY_OPTION_CHECK_H_
