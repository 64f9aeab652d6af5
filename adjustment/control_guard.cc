#include "adjustment/control_guard.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Per-axis median of `points`.
Eigen::Vector3d MedianOf(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d m;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> v;
    v.reserve(points.size());
    for (const Eigen::Vector3d& p : points) v.push_back(p[axis]);
    m[axis] = Median(v);
  }
  return m;
}

// A rejected crossing objects only where the input fits it within this
// share of the adjusted trajectory's misfit.
constexpr double kRejectedInputShare = 0.5;

GuardVerdict VerdictOf(const GuardCrossing& c,
                       const NeverWorseOptions& options) {
  GuardVerdict v;
  v.id = c.id;
  v.first_time_s = c.first_time_s;
  v.last_time_s = c.last_time_s;
  v.used = c.used;
  std::vector<Eigen::Vector3d> r_in, r_adj;
  for (size_t i = 0; i < c.database_enu.size(); ++i) {
    r_in.push_back(c.database_enu[i] - c.input_enu[i]);
    r_adj.push_back(c.database_enu[i] - c.adjusted_enu[i]);
  }
  const Eigen::Vector3d in = MedianOf(r_in);
  const Eigen::Vector3d adj = MedianOf(r_adj);
  v.input_misfit_m = in.norm();
  v.adjusted_misfit_m = adj.norm();
  const Eigen::Vector3d d = adj - in;
  const double spread = 2.0 * c.sigma_m.cwiseProduct(d).norm();
  // Where the two trajectories agree (to a millimetre) nothing tells them
  // apart.
  if (d.norm() < 1e-3 || !(spread > 0.0)) return v;
  v.z = d.dot(adj + in) / spread;
  v.worse = options.guard_sigmas > 0.0 && v.z > options.guard_sigmas &&
            d.norm() >= options.guard_min_difference_m;
  // A crossing the adjustment rejected may be wrong itself (repainted,
  // moved in the database): the input fitting it a little better is no
  // evidence against the adjusted trajectory. It objects only where the
  // input fits it at least twice as well.
  if (!c.used &&
      !(v.input_misfit_m <= kRejectedInputShare * v.adjusted_misfit_m)) {
    v.worse = false;
  }
  return v;
}

std::string Fixed(double value, int decimals) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

}  // namespace

double GuardResult::AdjustedWeight(double time_s) const {
  if (weight_knots.empty()) return 1.0;
  if (time_s <= weight_knots.front().first) return weight_knots.front().second;
  if (time_s >= weight_knots.back().first) return weight_knots.back().second;
  const auto it = std::upper_bound(
      weight_knots.begin(), weight_knots.end(), time_s,
      [](double t, const std::pair<double, double>& k) { return t < k.first; });
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double span = b.first - a.first;
  const double u = span > 0.0 ? (time_s - a.first) / span : 1.0;
  return (1.0 - u) * a.second + u * b.second;
}

bool GuardResult::KeepsInputEverywhere() const {
  return !verdicts.empty() &&
         std::all_of(verdicts.begin(), verdicts.end(),
                     [](const GuardVerdict& v) { return v.worse; });
}

GuardResult GuardAgainstInput(const std::vector<GuardCrossing>& crossings,
                              const NeverWorseOptions& options) {
  GuardResult result;
  for (const GuardCrossing& c : crossings) {
    if (c.database_enu.empty() || c.input_enu.size() != c.database_enu.size() ||
        c.adjusted_enu.size() != c.database_enu.size()) {
      continue;
    }
    result.verdicts.push_back(VerdictOf(c, options));
  }
  std::sort(result.verdicts.begin(), result.verdicts.end(),
            [](const GuardVerdict& a, const GuardVerdict& b) {
              return a.first_time_s < b.first_time_s;
            });
  const bool any_worse =
      std::any_of(result.verdicts.begin(), result.verdicts.end(),
                  [](const GuardVerdict& v) { return v.worse; });
  if (!any_worse) return result;
  for (const GuardVerdict& v : result.verdicts) {
    const double w = v.worse ? 0.0 : 1.0;
    result.weight_knots.emplace_back(v.first_time_s, w);
    result.weight_knots.emplace_back(std::max(v.first_time_s, v.last_time_s),
                                     w);
  }
  // Crossings overlapping in time: one that objects wins over the stretch.
  std::stable_sort(result.weight_knots.begin(), result.weight_knots.end(),
                   [](const auto& a, const auto& b) {
                     return a.first < b.first ||
                            (a.first == b.first && a.second < b.second);
                   });
  // The stretches: runs of crossings that object, between those that do
  // not.
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<GuardVerdict>& v = result.verdicts;
  for (size_t i = 0; i < v.size();) {
    if (!v[i].worse) {
      ++i;
      continue;
    }
    KeptStretch stretch;
    stretch.ramp_begin_s = i > 0 ? v[i - 1].last_time_s : -inf;
    stretch.begin_s = i > 0 ? v[i].first_time_s : -inf;
    size_t j = i;
    for (; j < v.size() && v[j].worse; ++j) {
      stretch.crossings.push_back(v[j].id);
      stretch.input_misfit_m =
          std::max(stretch.input_misfit_m, v[j].input_misfit_m);
      stretch.adjusted_misfit_m =
          std::max(stretch.adjusted_misfit_m, v[j].adjusted_misfit_m);
    }
    stretch.end_s = j < v.size() ? v[j - 1].last_time_s : inf;
    stretch.ramp_end_s = j < v.size() ? v[j].first_time_s : inf;
    result.kept.push_back(stretch);
    i = j;
  }
  return result;
}

std::string KeptStretchText(const KeptStretch& stretch, double time_origin_s) {
  std::string names;
  for (const std::string& id : stretch.crossings) {
    names += (names.empty() ? "" : ", ") + id;
  }
  const auto time = [time_origin_s](double t) {
    return Fixed(t - time_origin_s, 1) + " s";
  };
  std::string where;
  if (std::isinf(stretch.begin_s) && std::isinf(stretch.end_s)) {
    where = "over the whole survey";
  } else if (std::isinf(stretch.begin_s)) {
    where = "from the start to " + time(stretch.end_s) +
            (std::isinf(stretch.ramp_end_s)
                 ? std::string()
                 : " (blended into the adjusted trajectory by " +
                       time(stretch.ramp_end_s) + ")");
  } else if (std::isinf(stretch.end_s)) {
    where = "from " + time(stretch.begin_s) + " to the end (blended from " +
            time(stretch.ramp_begin_s) + ")";
  } else {
    where = "from " + time(stretch.begin_s) + " to " + time(stretch.end_s) +
            " (blended from " + time(stretch.ramp_begin_s) + " and into " +
            time(stretch.ramp_end_s) + ")";
  }
  return "the adjusted trajectory fits crossing" +
         std::string(stretch.crossings.size() > 1 ? "s " : " ") + names +
         " worse than the input trajectory does (" +
         Fixed(stretch.adjusted_misfit_m, 2) + " m from the database against " +
         Fixed(stretch.input_misfit_m, 2) +
         " m): the input trajectory is kept " + where +
         ", since the survey's own control shows the correction to be wrong "
         "there";
}

}  // namespace zebrageo
