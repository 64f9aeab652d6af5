// Small numeric helpers every library needs: angle units, robust
// statistics. Radians inside the libraries; degrees only at files and the
// command line (DegToRad / RadToDeg at those edges).
#ifndef ZEBRAGEO_SURVEY_MATH_UTIL_H_
#define ZEBRAGEO_SURVEY_MATH_UTIL_H_

#include <algorithm>
#include <cmath>
#include <vector>

namespace zebrageo {

constexpr double kPi = 3.14159265358979323846;

constexpr double DegToRad(double degrees) { return degrees * (kPi / 180.0); }
constexpr double RadToDeg(double radians) { return radians * (180.0 / kPi); }

// The value at quantile p in [0, 1] (nearest rank); 0 for no values.
inline double Percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const size_t i = std::min(
      values.size() - 1,
      static_cast<size_t>(std::clamp(p, 0.0, 1.0) * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + i, values.end());
  return values[i];
}

// The upper median (the element at size / 2 once sorted); 0 for no values.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

// Root mean square; 0 for no values.
inline double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / values.size());
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_MATH_UTIL_H_
