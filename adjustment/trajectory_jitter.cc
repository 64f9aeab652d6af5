#include "adjustment/trajectory_jitter.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "adjustment/trajectory_correction.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Departure of sample i's position from the weighted (tricube) quadratic
// fit of the positions within +-window_s of it; false with too few
// samples.
bool Departure(const std::vector<double>& times, const std::vector<Pose>& poses,
               int i, double window_s, Eigen::Vector3d* departure) {
  const int n = static_cast<int>(times.size());
  const auto low =
      std::lower_bound(times.begin(), times.end(), times[i] - window_s) -
      times.begin();
  const auto high =
      std::upper_bound(times.begin(), times.end(), times[i] + window_s) -
      times.begin();
  if (high - low < 7) return false;
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d AtB = Eigen::Matrix3d::Zero();  // columns: e, n, u
  for (auto k = low; k < std::min<decltype(high)>(high, n); ++k) {
    const double dt = (times[k] - times[i]) / window_s;
    const double w = std::pow(1.0 - std::pow(std::abs(dt), 3), 3);
    const Eigen::Vector3d a(1.0, dt, dt * dt);
    AtA += w * a * a.transpose();
    AtB += w * a * (poses[k].p_enu - poses[i].p_enu).transpose();
  }
  const Eigen::Matrix3d coefficients = AtA.ldlt().solve(AtB);
  if (!coefficients.allFinite()) return false;
  // The fit at t_i is the constant term; the sample departs from it.
  *departure = -coefficients.row(0).transpose();
  return true;
}

// The Gauss-Markov sigma and tau whose increments have variances v1 at
// lag l1 and v2 at lag l2 (l1 < l2): v(l) = 2 sigma^2 (1 - exp(-l / tau)).
// Their ratio fixes tau (bisection: it grows with tau from 1 towards
// l2 / l1), then v1 fixes sigma.
void FitIncrements(double l1, double v1, double l2, double v2, double* sigma,
                   double* tau) {
  constexpr double kMinTau = 0.02;
  constexpr double kMaxTau = 5.0;
  auto ratio = [&](double t) {
    return (1.0 - std::exp(-l2 / t)) / (1.0 - std::exp(-l1 / t));
  };
  const double target = v1 > 0.0 ? v2 / v1 : 1.0;
  double low = kMinTau;
  double high = kMaxTau;
  if (target <= ratio(low)) {
    high = low;
  } else if (target >= ratio(high)) {
    low = high;
  } else {
    for (int i = 0; i < 60; ++i) {
      const double mid = std::sqrt(low * high);
      (ratio(mid) < target ? low : high) = mid;
    }
  }
  *tau = 0.5 * (low + high);
  *sigma = std::sqrt(v1 / (2.0 * (1.0 - std::exp(-l1 / *tau))));
}

}  // namespace

PositionJitter EstimatePositionJitter(const std::vector<double>& times,
                                      const std::vector<Pose>& poses,
                                      double window_s, double lag_s) {
  PositionJitter jitter;
  const int n = static_cast<int>(times.size());
  if (n < 16) return jitter;
  const double duration = times.back() - times.front();
  const double dt = duration / (n - 1);
  // Departures from the smooth path at consecutive samples, in blocks of
  // lag2 + 1 samples spread over the survey (at most ~2000 blocks).
  const int lag2 = std::max(2, static_cast<int>(std::lround(lag_s / dt)));
  const int blocks = std::min(2000, n / (lag2 + 1));
  const int stride = std::max(lag2 + 1, n / std::max(blocks, 1));
  std::vector<double> step1[3], step2[3];
  for (int start = 0; start + lag2 < n; start += stride) {
    std::vector<Eigen::Vector3d> d(lag2 + 1);
    bool ok = true;
    for (int k = 0; k <= lag2 && ok; ++k) {
      Eigen::Vector3d departure;
      ok = Departure(times, poses, start + k, window_s, &departure);
      d[k] = TrackFrame(poses[start]).transpose() * departure;
    }
    if (!ok) continue;
    for (int axis = 0; axis < 3; ++axis) {
      step1[axis].push_back(d[1][axis] - d[0][axis]);
      step2[axis].push_back(d[lag2][axis] - d[0][axis]);
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (step1[axis].size() < 8) return PositionJitter();
    // Robust variances (MAD): a few GNSS jumps must not count as jitter.
    auto variance = [](const std::vector<double>& v) {
      std::vector<double> magnitude;
      for (double x : v) magnitude.push_back(std::abs(x));
      const double s = 1.4826 * Median(magnitude);
      return s * s;
    };
    FitIncrements(dt, variance(step1[axis]), lag2 * dt, variance(step2[axis]),
                  &jitter.sigma_m[axis], &jitter.tau_s[axis]);
  }
  return jitter;
}

}  // namespace zebrageo
