// The GNSS/INS error the matched road lines show (line_discrepancies.h).
#include "adjustment/line_discrepancies.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "survey/math_util.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// One line point's offset from its database line with the INS trajectory
// (database minus point), across the line and in height, with their
// variances (0 across when the line runs across the road: its row of the
// whitening is zero and it measures the height only).
struct LineOffset {
  double across_m = 0.0;
  double up_m = 0.0;
  double variance_across_m2 = 0.0;
  double variance_up_m2 = 0.0;
  bool has_across = false;
};

LineOffset OffsetOf(const State::Line& line) {
  const LineControlPoint& p = line.point;
  const Eigen::Vector3d X =
      line.ins_pose.p_enu + line.ins_pose.q_enu_body * p.p_body;
  const Eigen::Vector3d d = X - p.db_point_enu;
  const double along = p.along_enu.head<2>().dot(d.head<2>());
  LineOffset out;
  out.across_m = -p.across_enu.dot(d);
  out.up_m = -(d.z() - p.grade * along);
  const Eigen::Matrix2d& S = p.sqrt_information;
  out.has_across = S.row(0).norm() > 0.0;
  if (out.has_across) {
    const Eigen::Matrix2d C = (S.transpose() * S).inverse();
    out.variance_across_m2 = C(0, 0);
    out.variance_up_m2 = C(1, 1);
  } else {
    out.variance_up_m2 = 1.0 / std::max(S(1, 1) * S(1, 1), 1e-12);
  }
  return out;
}

// The median of `values` and the variance of it: pi/2 times that of the
// mean of values of these variances.
void MedianAndVariance(const std::vector<double>& values,
                       const std::vector<double>& variances, double* median,
                       double* variance) {
  *median = Median(values);
  double sum = 0.0;
  for (double v : variances) sum += v;
  const double m = static_cast<double>(values.size());
  *variance = (kPi / 2.0) * sum / (m * m);
}

}  // namespace

std::vector<CrossingDiscrepancy> LineDiscrepancies(const State& state,
                                                   double bin_s,
                                                   int min_points) {
  std::vector<CrossingDiscrepancy> out;
  if (state.lines.empty() || !(bin_s > 0.0)) return out;
  const double start = state.correction.KnotTime(0);
  std::map<int, std::vector<const State::Line*>> bins;
  for (const State::Line& line : state.lines) {
    // A dash's centre measures the along-track error, not this one.
    if (line.point.along_track) continue;
    bins[static_cast<int>(std::floor((line.point.time - start) / bin_s))]
        .push_back(&line);
  }
  for (const auto& [bin, lines] : bins) {
    if (static_cast<int>(lines.size()) < min_points) continue;
    std::vector<double> across, variance_across, up, variance_up;
    double time_sum = 0.0;
    Eigen::Vector3d across_sum = Eigen::Vector3d::Zero();
    for (const State::Line* line : lines) {
      const LineOffset o = OffsetOf(*line);
      if (o.has_across) {
        // The across direction signed consistently (towards the same side
        // of the road) before the offsets are pooled.
        const double sign =
            across_sum.dot(line->point.across_enu) < 0.0 ? -1.0 : 1.0;
        across_sum += sign * line->point.across_enu;
        across.push_back(sign * o.across_m);
        variance_across.push_back(o.variance_across_m2);
      }
      up.push_back(o.up_m);
      variance_up.push_back(o.variance_up_m2);
      time_sum += line->point.time;
    }
    CrossingDiscrepancy d;
    d.valid = true;
    d.vertices = static_cast<int>(lines.size());
    d.time_s = time_sum / static_cast<double>(lines.size());
    const Eigen::Matrix3d R_track_enu =
        state.correction.Frame(lines.front()->ins_pose).transpose();
    d.variance_m2 = Eigen::Vector3d::Constant(kUnmeasuredVarianceM2);
    Eigen::Vector3d offset_enu = Eigen::Vector3d::Zero();
    if (!across.empty()) {
      double median = 0.0;
      double variance = 0.0;
      MedianAndVariance(across, variance_across, &median, &variance);
      offset_enu += median * across_sum.normalized();
      // Lines run with the vehicle: across them is cross-track.
      d.variance_m2[1] = variance;
    }
    double median_up = 0.0;
    MedianAndVariance(up, variance_up, &median_up, &d.variance_m2[2]);
    d.value_m = R_track_enu * offset_enu;
    d.value_m[0] = 0.0;
    d.value_m[2] = median_up;
    if (across.empty()) d.value_m[1] = 0.0;
    const Eigen::Vector3d jump = state.PriorJumpAt(d.time_s);
    d.value_m[1] -= jump[1];
    d.value_m[2] -= jump[2];
    VLOG(2) << "line discrepancy at " << d.time_s << " s (" << lines.size()
            << " points): " << d.value_m.transpose() << " m, sd "
            << d.variance_m2.cwiseSqrt().transpose();
    out.push_back(d);
  }
  return out;
}

std::vector<CrossingDiscrepancy> DashDiscrepancies(const State& state) {
  // A dash measures the error along itself: the along-track error times
  // cos(angle to the track) plus the cross-track error times its sine.
  // The cross-track error is not known here (a metre in a city is
  // possible): counted as this much unknown error, and dashes more than
  // 10 degrees off the track left out.
  constexpr double kMinAlongTrackCosine = 0.985;
  constexpr double kUnknownCrossTrackErrorM = 1.0;
  std::vector<CrossingDiscrepancy> out;
  for (const State::Line& line : state.lines) {
    const LineControlPoint& p = line.point;
    if (!p.along_track) continue;
    // across_enu holds the dash's direction, row 0 of the whitening its sd.
    const double information = p.sqrt_information(0, 0);
    if (!(information > 0.0)) continue;
    const Eigen::Matrix3d R_track_enu =
        state.correction.Frame(line.ins_pose).transpose();
    const Eigen::Vector3d direction_track = R_track_enu * p.across_enu;
    const double cosine = direction_track.x();
    if (std::abs(cosine) < kMinAlongTrackCosine) continue;
    const double sine = direction_track.y();
    const Eigen::Vector3d X =
        line.ins_pose.p_enu + line.ins_pose.q_enu_body * p.p_body;
    const double along_dash = p.across_enu.dot(p.db_point_enu - X);
    CrossingDiscrepancy d;
    d.valid = true;
    d.vertices = 1;
    d.time_s = p.time;
    d.variance_m2 = Eigen::Vector3d::Constant(kUnmeasuredVarianceM2);
    d.value_m.x() = along_dash / cosine;
    const double cross_track = sine * kUnknownCrossTrackErrorM;
    d.variance_m2.x() =
        (1.0 / (information * information) + cross_track * cross_track) /
        (cosine * cosine);
    d.value_m.x() -= state.PriorJumpAt(d.time_s).x();
    VLOG(2) << "dash discrepancy at " << d.time_s << " s: " << d.value_m.x()
            << " m along the track, sd " << std::sqrt(d.variance_m2.x());
    out.push_back(d);
  }
  std::sort(out.begin(), out.end(),
            [](const CrossingDiscrepancy& a, const CrossingDiscrepancy& b) {
              return a.time_s < b.time_s;
            });
  return out;
}

}  // namespace adjustment_internal
}  // namespace zebrageo
