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
         << ", the trajectory's sd " << RadToDeg(stated_sd_rad[k]) << ")";
    first = false;
  }
  return text.str();
}

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
    offset.found |= offset.axes[k] != 0;
  }
  return offset;
}

}  // namespace zebrageo
