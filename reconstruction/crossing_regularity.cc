#include "reconstruction/crossing_regularity.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {

bool CrossingEndDirection(const std::vector<EndDirectionObservation>& all,
                          int crossing, int min_count,
                          Eigen::Vector2d* direction_2d) {
  // Ends this close to the median are averaged (a near end's angle is good
  // to about 0.01 rad, a far one's to a few hundredths).
  constexpr double kInlierAngleRad = 0.05;
  const EndDirectionObservation* heaviest = nullptr;
  int count = 0;
  for (const EndDirectionObservation& o : all) {
    if (o.crossing != crossing || !(o.weight > 0.0)) continue;
    ++count;
    if (heaviest == nullptr || o.weight > heaviest->weight) heaviest = &o;
  }
  if (count < min_count || heaviest == nullptr) return false;
  const double reference =
      std::atan2(heaviest->direction_2d.y(), heaviest->direction_2d.x());
  // (angle from the reference in (-pi/2, pi/2], weight)
  std::vector<std::pair<double, double>> angles;
  double total = 0.0;
  for (const EndDirectionObservation& o : all) {
    if (o.crossing != crossing || !(o.weight > 0.0)) continue;
    const double angle = std::atan2(o.direction_2d.y(), o.direction_2d.x());
    angles.push_back({std::remainder(angle - reference, kPi), o.weight});
    total += o.weight;
  }
  std::sort(angles.begin(), angles.end());
  double cumulated = 0.0;
  double median = angles.back().first;
  for (const auto& [angle, weight] : angles) {
    cumulated += weight;
    if (cumulated >= 0.5 * total) {
      median = angle;
      break;
    }
  }
  // The weighted mean of the angles near the median: as robust, and not
  // tied to one observation's noise.
  double sum = 0.0, sum_weights = 0.0;
  for (const auto& [angle, weight] : angles) {
    if (std::abs(angle - median) > kInlierAngleRad) continue;
    sum += weight * angle;
    sum_weights += weight;
  }
  const double mean = sum / sum_weights;
  *direction_2d =
      Eigen::Vector2d(std::cos(reference + mean), std::sin(reference + mean));
  return true;
}

namespace {

// Whether a band of `length_m` is longer than the longest of its crossing's
// `others` that another one confirms (two bands running on into squares
// confirm each other: then nothing is dropped). A band cut short by the
// image's edge or an occluder is shorter, never longer, so it never makes a
// full band look too long.
bool LongerThanItsCrossing(double length_m, std::vector<double> others,
                           const BandOptions& options) {
  std::sort(others.begin(), others.end(), std::greater<double>());
  for (size_t k = 0; k + 1 < others.size(); ++k) {
    if (others[k] - others[k + 1] <= options.crossing_length_agreement_m) {
      return length_m > others[k] + options.max_crossing_length_excess_m;
    }
  }
  return false;
}

}  // namespace

std::vector<char> LongerThanTheirCrossings(const std::vector<int>& crossing_of,
                                           const std::vector<double>& length_m,
                                           const BandOptions& options) {
  std::vector<char> longer(length_m.size(), 0);
  for (size_t i = 0; i < length_m.size(); ++i) {
    std::vector<double> others;
    for (size_t j = 0; j < length_m.size(); ++j) {
      if (j != i && crossing_of[j] == crossing_of[i]) {
        others.push_back(length_m[j]);
      }
    }
    longer[i] = LongerThanItsCrossing(length_m[i], std::move(others), options);
  }
  return longer;
}

std::vector<Band> WithoutOverlongBands(std::vector<Band> bands,
                                       const BandOptions& options) {
  std::vector<int> crossing_of;
  std::vector<double> length_m;
  for (const Band& band : bands) {
    crossing_of.push_back(band.crossing);
    length_m.push_back(band.length_m);
  }
  const std::vector<char> drop =
      LongerThanTheirCrossings(crossing_of, length_m, options);
  std::vector<Band> kept;
  for (size_t i = 0; i < bands.size(); ++i) {
    if (drop[i]) {
      VLOG(2) << "band of crossing " << bands[i].crossing << ": "
              << bands[i].length_m << " m long, longer than its crossing's: "
              << "dropped";
      continue;
    }
    kept.push_back(std::move(bands[i]));
  }
  return kept;
}

}  // namespace zebrageo
