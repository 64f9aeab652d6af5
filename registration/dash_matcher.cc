#include "registration/dash_matcher.h"

#include <glog/logging.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Horizontal length of a polyline.
double HorizontalLength(const std::vector<Eigen::Vector3d>& points) {
  double length = 0.0;
  for (size_t i = 1; i < points.size(); ++i) {
    length += (points[i] - points[i - 1]).head<2>().norm();
  }
  return length;
}

bool NamesDash(const std::string& type) {
  return type.find("dash") != std::string::npos;
}

}  // namespace

std::string DashMatchOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_dash_length_m, 0.0);
  OPTION_LT(check, min_length_difference_m, max_length_difference_m);
  OPTION_GT(check, max_across_m, 0.0);
  OPTION_GE(check, min_separation_ratio, 1.0);
  return check.problem();
}

std::vector<int> DatabaseDashes(const std::vector<DatabaseLineEnu>& database,
                                const DashMatchOptions& options) {
  std::vector<int> dashes;
  for (size_t i = 0; i < database.size(); ++i) {
    const DatabaseLineEnu& line = database[i];
    if (!NamesDash(line.type) || line.points.size() < 2) continue;
    const double length = HorizontalLength(line.points);
    if (length > 0.0 && length <= options.max_dash_length_m) {
      dashes.push_back(static_cast<int>(i));
    }
  }
  return dashes;
}

std::vector<DashMatch> MatchDashes(
    const std::vector<ReconstructedDashEnu>& dashes,
    const std::vector<DatabaseLineEnu>& database,
    const std::vector<int>& db_dashes, const DashMatchOptions& options) {
  std::vector<Eigen::Vector3d> db_centres;
  for (int index : db_dashes) {
    const DatabaseLineEnu& line = database[index];
    db_centres.push_back(0.5 * (line.points.front() + line.points.back()));
  }
  std::vector<DashMatch> matches;
  for (size_t d = 0; d < dashes.size(); ++d) {
    const ReconstructedDashEnu& dash = dashes[d];
    const Eigen::Vector3d centre = 0.5 * (dash.first_enu + dash.last_enu);
    const double length = (dash.last_enu - dash.first_enu).head<2>().norm();
    // The nearest database dash centre, and the distance to the next one.
    int best = -1;  // index into db_dashes
    double best_distance = std::numeric_limits<double>::infinity();
    double second_distance = best_distance;
    for (size_t k = 0; k < db_dashes.size(); ++k) {
      const double distance = (centre - db_centres[k]).head<2>().norm();
      if (distance < best_distance) {
        second_distance = best_distance;
        best_distance = distance;
        best = static_cast<int>(k);
      } else {
        second_distance = std::min(second_distance, distance);
      }
    }
    if (best < 0 ||
        second_distance < options.min_separation_ratio * best_distance) {
      VLOG(2) << "dash " << d << ": the nearest database dash is "
              << best_distance << " m away, the next " << second_distance;
      continue;
    }
    const DatabaseLineEnu& line = database[db_dashes[best]];
    const Eigen::Vector3d& db_centre = db_centres[best];
    Eigen::Vector3d along = line.points.back() - line.points.front();
    along.z() = 0.0;
    along.normalize();
    const Eigen::Vector3d across(-along.y(), along.x(), 0.0);
    const Eigen::Vector3d offset = centre - db_centre;
    const double length_difference = length - HorizontalLength(line.points);
    if (std::abs(offset.dot(across)) > options.max_across_m ||
        std::abs(offset.dot(along)) > dash.gate_m ||
        length_difference < options.min_length_difference_m ||
        length_difference > options.max_length_difference_m) {
      VLOG(2) << "dash " << d << " not matched to " << line.id << ": "
              << offset.dot(along) << " m along (gate " << dash.gate_m << "), "
              << offset.dot(across) << " m across, length " << length_difference
              << " m from the database's";
      continue;
    }
    matches.push_back({static_cast<int>(d), db_dashes[best], db_centre, along,
                       offset.dot(along), length_difference});
  }
  return matches;
}

}  // namespace zebrageo
