#include "simulator/gnss_outage.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "simulator/noise.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

// The outage's random draws (motion.cc's other purposes are 20-27).
constexpr uint64_t kOutageSeed = 23;

Eigen::Vector2d UnitAt(double angle) {
  return Eigen::Vector2d(std::cos(angle), std::sin(angle));
}

// Index of the first sample at or after road position s (the last one if
// none).
int SampleAtS(const std::vector<double>& s_of, double s) {
  const auto it = std::lower_bound(s_of.begin(), s_of.end(), s);
  return std::min(static_cast<int>(it - s_of.begin()),
                  static_cast<int>(s_of.size()) - 1);
}

}  // namespace

Outage DrawOutage(const SimulationOptions& options) {
  std::mt19937_64 outage_rng(SubSeed(options.seed, kOutageSeed));
  Outage outage;
  const double outage_angle = Uniform(&outage_rng, 0.0, 2.0 * kPi);
  outage.direction =
      Eigen::Vector3d(std::cos(outage_angle), std::sin(outage_angle),
                      0.3 * (Bernoulli(&outage_rng, 0.5) ? 1.0 : -1.0));
  const double jump_angle = Uniform(&outage_rng, 0.0, 2.0 * kPi);
  outage.jump_direction =
      Eigen::Vector3d(std::cos(jump_angle), std::sin(jump_angle),
                      Uniform(&outage_rng, -0.5, 0.5));
  // Drawn after the others: the quadratic outages stay as they were.
  outage.velocity_direction = UnitAt(Uniform(&outage_rng, 0.0, 2.0 * kPi));
  outage.acceleration_direction = UnitAt(Uniform(&outage_rng, 0.0, 2.0 * kPi));
  outage.velocity_share = Uniform(&outage_rng, 0.0, 1.0);
  outage.vertical_sign = Bernoulli(&outage_rng, 0.5) ? 1.0 : -1.0;
  outage.active = options.outage_duration_s > 0.0;
  outage.begin = options.outage_start_s;
  outage.end = options.outage_start_s + options.outage_duration_s;
  return outage;
}

void PlaceOutage(const SimulationOptions& options, const World& world,
                 const DriveSamples& drive, Outage* outage) {
  if (!outage->active || !(options.outage_clear_after_m > 0.0)) return;
  // Where each crossing of the street begins and ends along the road.
  std::vector<std::pair<double, double>> crossings;
  for (const Crossing& c : world.crossings) {
    if (c.in_street) crossings.emplace_back(c.s_min, c.s_max);
  }
  if (crossings.empty()) return;
  std::sort(crossings.begin(), crossings.end());
  constexpr double kPastCrossingM = 8.0;  // its last views are before it
  constexpr double kEarliestS = 2.0;
  const double duration = options.outage_duration_s;
  auto s_at_time = [&drive](double t) {
    return drive.s_of[SampleAtS(drive.times, t)];
  };
  auto time_at_s = [&drive](double s) {
    return drive.times[SampleAtS(drive.s_of, s)];
  };
  // The earliest end that holds the whole duration; that which leaves the
  // first crossing before the outage.
  const double first_end_s = s_at_time(kEarliestS + duration);
  const double after_first_s =
      s_at_time(time_at_s(crossings[0].second + kPastCrossingM) + duration);
  struct Place {
    double lo = 0.0, hi = 0.0;  // road s of the outage's end
    double clear_m = 0.0;
    int fits = 0, clear = 0, before = 0;
  };
  std::vector<Place> places;
  const double s_last = drive.s_of.back();
  for (size_t k = 0; k < crossings.size(); ++k) {
    const double next =
        k + 1 < crossings.size() ? crossings[k + 1].first : s_last;
    const double past = crossings[k].second + kPastCrossingM;
    if (past >= s_last || past >= next) continue;
    Place place;
    place.hi = std::max(past, next - options.outage_clear_after_m);
    place.fits = place.hi >= first_end_s;
    place.before = place.fits && place.hi >= after_first_s;
    place.lo = std::max(past, std::min(place.hi, place.before ? after_first_s
                                                 : place.fits ? first_end_s
                                                              : past));
    place.clear_m = next - place.lo;
    place.clear = place.clear_m >= options.outage_clear_after_m;
    places.push_back(place);
  }
  if (places.empty()) return;
  auto rank = [](const Place& p) {
    return std::make_tuple(p.fits && p.clear, p.fits && p.clear && p.before,
                           p.fits, p.clear_m);
  };
  int best = 0;
  for (int i = 1; i < static_cast<int>(places.size()); ++i) {
    if (rank(places[i]) > rank(places[best])) best = i;
  }
  std::vector<int> equal;
  for (int i = 0; i < static_cast<int>(places.size()); ++i) {
    if (std::get<0>(rank(places[i])) == std::get<0>(rank(places[best])) &&
        std::get<1>(rank(places[i])) == std::get<1>(rank(places[best])) &&
        std::get<2>(rank(places[i])) == std::get<2>(rank(places[best]))) {
      equal.push_back(i);
    }
  }
  std::mt19937_64 rng(SubSeed(options.seed, kOutageSeed, 1));
  // Among places equally good, one at random where each holds the clear
  // stretch; else the longest.
  const Place& place = std::get<0>(rank(places[best]))
                           ? places[equal[UniformInt(
                                 &rng, 0, static_cast<int>(equal.size()) - 1)]]
                           : places[best];
  const double s_end = Uniform(&rng, place.lo, place.hi);
  outage->end = std::max(time_at_s(s_end), kEarliestS + 1.0);
  outage->begin = std::max(kEarliestS, outage->end - duration);
}

void IntegrateInsDrift(const SimulationOptions& options,
                       const DriveSamples& drive,
                       const std::vector<Eigen::Vector3d>& p_enu,
                       Outage* outage) {
  const int n = static_cast<int>(drive.times.size());
  outage->ins_error.assign(n, Eigen::Vector3d::Zero());
  if (!outage->active || !options.outage_ins_drift) return;
  const double duration = outage->end - outage->begin;
  if (!(duration > 0.0)) return;
  // Heading part: a compass heading too far clockwise turns the steps
  // clockwise, i.e. by minus the angle about up in ENU.
  std::vector<Eigen::Vector2d> heading(n, Eigen::Vector2d::Zero());
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int last = 0;
  for (int k = 1; k < n; ++k) {
    const double t = drive.times[k];
    if (t < outage->begin) continue;
    if (t >= outage->end) break;
    const double angle = DegToRad(options.outage_heading_drift_deg) *
                         (t - outage->begin) / duration;
    const Eigen::Vector2d step = (p_enu[k] - p_enu[k - 1]).head<2>();
    sum += -angle * Eigen::Vector2d(-step.y(), step.x());
    heading[k] = sum;
    last = k;
  }
  // The biases' shape at the end, and their size.
  const double a = outage->velocity_share;
  const Eigen::Vector2d w = a * outage->velocity_direction +
                            (1.0 - a) * outage->acceleration_direction;
  const Eigen::Vector2d h = heading[last];
  const double target = options.outage_drift_m;
  double lambda = 0.0;
  if (h.norm() < target && w.squaredNorm() > 1e-12) {
    const double b = h.dot(w);
    const double disc =
        b * b - w.squaredNorm() * (h.squaredNorm() - target * target);
    lambda = (-b + std::sqrt(std::max(0.0, disc))) / w.squaredNorm();
  }
  constexpr double kVerticalShare = 0.15;
  for (int k = 0; k < n; ++k) {
    const double t = drive.times[k];
    if (t < outage->begin || t >= outage->end) continue;
    const double f = (t - outage->begin) / duration;
    const Eigen::Vector2d bias =
        lambda * (a * f * outage->velocity_direction +
                  (1.0 - a) * f * f * outage->acceleration_direction);
    outage->ins_error[k].head<2>() = heading[k] + bias;
    outage->ins_error[k].z() = outage->vertical_sign * kVerticalShare * target *
                               (a * f + (1.0 - a) * f * f);
  }
}

}  // namespace zebrageo::sim
