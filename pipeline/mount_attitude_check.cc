#include "pipeline/mount_attitude_check.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "survey/option_check.h"

namespace zebrageo {

std::string MountAttitudeOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, min_stated_sds, 0.0);
  OPTION_GE(check, min_offset_rad, 0.0);
  OPTION_GT(check, max_scatter_fraction, 0.0);
  OPTION_GT(check, boresight_sigma_rad, 0.0);
  OPTION_GE(check, min_course_fraction, 0.0);
  OPTION_GT(check, course_chord_m, 0.0);
  OPTION_GT(check, max_chord_turn_rad, 0.0);
  OPTION_GE(check, min_course_chords, 1);
  return check.problem();
}

std::string AttitudeOffset::Describe() const {
  constexpr const char* kAxisNames[3] = {"roll", "pitch", "yaw"};
  std::ostringstream text;
  text.precision(3);
  text << std::fixed;
  bool first = true;
  for (int k = 0; k < 3; ++k) {
    if (!axes[k]) continue;
    text << (first ? "" : ", ") << kAxisNames[k] << " " << RadToDeg(mean_rad[k])
         << " deg (scatter " << RadToDeg(scatter_rad[k])
         << ", the trajectory's sd " << RadToDeg(stated_sd_rad[k]);
    if (k == 2) {
      text << "; off the course over ground "
           << RadToDeg(input_course_departure_rad) << " -> "
           << RadToDeg(corrected_course_departure_rad) << " deg";
    }
    text << ")";
    first = false;
  }
  return text.str();
}

namespace {

// The compass heading (clockwise from north, radians) of an ENU direction.
double CompassOf(const Eigen::Vector3d& d_enu) {
  return std::atan2(d_enu.x(), d_enu.y());
}

double Wrapped(double angle) { return std::remainder(angle, 2.0 * M_PI); }

// The median departures (heading minus course) of `a` and `b`'s headings
// from the course over ground of `course`'s positions, over chords of
// options.course_chord_m on straight stretches; the chords' count.
struct CourseDepartures {
  double a_rad = 0.0;
  double b_rad = 0.0;
  int chords = 0;
};
CourseDepartures CourseDeparturesOf(const MountAttitudeOptions& options,
                                    const std::vector<Pose>& course,
                                    const std::vector<Pose>& a,
                                    const std::vector<Pose>& b) {
  const size_t n = course.size();
  // Prefix sums of the horizontal forward axes: a chord's mean heading.
  std::vector<Eigen::Vector2d> sum_a(n + 1, Eigen::Vector2d::Zero());
  std::vector<Eigen::Vector2d> sum_b(n + 1, Eigen::Vector2d::Zero());
  std::vector<double> along(n, 0.0);  // horizontal distance travelled
  for (size_t i = 0; i < n; ++i) {
    sum_a[i + 1] =
        sum_a[i] +
        (a[i].q_enu_body * Eigen::Vector3d::UnitX()).head<2>().normalized();
    sum_b[i + 1] =
        sum_b[i] +
        (b[i].q_enu_body * Eigen::Vector3d::UnitX()).head<2>().normalized();
    if (i > 0) {
      along[i] = along[i - 1] +
                 (course[i].p_enu - course[i - 1].p_enu).head<2>().norm();
    }
  }
  std::vector<double> departures_a, departures_b;
  size_t j = 0;
  for (size_t i = 0; i < n; ++i) {
    j = std::max(j, i + 1);
    while (j < n && along[j] - along[i] < options.course_chord_m) ++j;
    if (j >= n) break;
    const Eigen::Vector3d chord = course[j].p_enu - course[i].p_enu;
    const double course_rad =
        CompassOf(Eigen::Vector3d(chord.x(), chord.y(), 0.0));
    const Eigen::Vector2d mean_a = sum_a[j + 1] - sum_a[i];
    const Eigen::Vector2d mean_b = sum_b[j + 1] - sum_b[i];
    const double turn =
        Wrapped(CompassOf(b[j].q_enu_body * Eigen::Vector3d::UnitX()) -
                CompassOf(b[i].q_enu_body * Eigen::Vector3d::UnitX()));
    if (std::abs(turn) > options.max_chord_turn_rad ||
        chord.head<2>().norm() < 0.5 * options.course_chord_m) {
      continue;
    }
    departures_a.push_back(Wrapped(
        CompassOf(Eigen::Vector3d(mean_a.x(), mean_a.y(), 0.0)) - course_rad));
    departures_b.push_back(Wrapped(
        CompassOf(Eigen::Vector3d(mean_b.x(), mean_b.y(), 0.0)) - course_rad));
  }
  CourseDepartures departures;
  departures.chords = static_cast<int>(departures_a.size());
  if (departures.chords > 0) {
    departures.a_rad = Median(departures_a);
    departures.b_rad = Median(departures_b);
  }
  return departures;
}

}  // namespace

AttitudeOffset MountLikeAttitudeOffset(
    const MountAttitudeOptions& options,
    const std::vector<TrajectorySample>& input,
    const std::vector<Pose>& input_poses,
    const std::vector<Pose>& corrected_poses) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("MountAttitudeOptions: " + problem);
  }
  AttitudeOffset offset;
  const size_t n = input_poses.size();
  if (n == 0 || corrected_poses.size() != n || input.size() != n) {
    return offset;
  }
  // Body-frame differences: a mount turned by E is undone by a body
  // turned by E^-1, whatever the heading.
  std::vector<Eigen::Vector3d> differences(n);
  std::vector<double> sds[3];
  for (size_t i = 0; i < n; ++i) {
    const Eigen::AngleAxisd d(input_poses[i].q_enu_body.conjugate() *
                              corrected_poses[i].q_enu_body);
    differences[i] = d.angle() * d.axis();
    if (d.angle() > M_PI) differences[i] -= 2.0 * M_PI * d.axis();
    offset.mean_rad += differences[i] / static_cast<double>(n);
    for (int k = 0; k < 3; ++k) sds[k].push_back(input[i].sd_attitude_rad[k]);
  }
  for (const Eigen::Vector3d& d : differences) {
    offset.scatter_rad +=
        (d - offset.mean_rad).cwiseAbs2() / static_cast<double>(n);
  }
  offset.scatter_rad = offset.scatter_rad.cwiseSqrt();
  for (int k = 0; k < 3; ++k) {
    offset.stated_sd_rad[k] = Median(sds[k]);
    const double mean = std::abs(offset.mean_rad[k]);
    offset.axes[k] =
        mean > options.min_offset_rad &&
        mean > options.min_stated_sds * offset.stated_sd_rad[k] &&
        offset.scatter_rad[k] <= options.max_scatter_fraction * mean;
  }
  const CourseDepartures course = CourseDeparturesOf(
      options, corrected_poses, input_poses, corrected_poses);
  offset.input_course_departure_rad = course.a_rad;
  offset.corrected_course_departure_rad = course.b_rad;
  offset.course_chords = course.chords;
  // The adjustment turned the heading away from the course (a mount), not
  // towards it (the INS's own heading error).
  offset.axes[2] =
      offset.axes[2] && course.chords >= options.min_course_chords &&
      std::abs(course.b_rad) - std::abs(course.a_rad) >=
          options.min_course_fraction * std::abs(offset.mean_rad[2]);
  offset.found = (offset.axes.array() != 0).any();
  return offset;
}

}  // namespace zebrageo
