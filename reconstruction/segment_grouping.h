// Grouping of collinear segments into long sides (Soheilian et al.,
// section 4.3, after Jang and Hong 2002): groups of 2D points of the plane
// frame, merged best first while they stay one line.
//
// Frames: the plane frame of long_sides.h (metres).
#ifndef ZEBRAGEO_RECONSTRUCTION_SEGMENT_GROUPING_H_
#define ZEBRAGEO_RECONSTRUCTION_SEGMENT_GROUPING_H_

#include <Eigen/Core>
#include <vector>

namespace zebrageo {

// Total least squares line through 2D points: centre and unit direction.
void FitLine2d(const std::vector<Eigen::Vector2d>& points,
               const std::vector<int>& support, Eigen::Vector2d* centre,
               Eigen::Vector2d* direction);

// A set of collinear supports being grouped.
struct Group {
  std::vector<int> support;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();  // along `axis`
  double t_min = 0.0;  // extent along direction from centre
  double t_max = 0.0;
  double rms_m = 0.0;  // perpendicular residuals
  // +1 when the image brightens across the group towards the left of
  // `axis`, -1 the other way: one edge of a paint mark keeps its polarity.
  int polarity = 1;
  double Length() const { return t_max - t_min; }
  Eigen::Vector2d Begin() const { return centre + t_min * direction; }
  Eigen::Vector2d End() const { return centre + t_max * direction; }
};

// The group of the points `support` (indices into `points`): their TLS
// line, oriented along `axis`, its extent and residuals (polarity +1).
Group MakeGroup(const std::vector<Eigen::Vector2d>& points,
                std::vector<int> support, const Eigen::Vector2d& axis);

// Thresholds of one grouping pass.
struct GroupingThresholds {
  double max_gap_m;
  double max_offset_m;
  double max_angle_rad;
};

// Greedy best-first merging of collinear groups (an approximation of Jang
// and Hong's globally favourable grouping): candidate links are sorted by a
// normalised cost of gap, offset and angle, and merged while the merged
// group stays a line (rms below the offset threshold).
std::vector<Group> MergeCollinear(const std::vector<Eigen::Vector2d>& points,
                                  std::vector<Group> groups,
                                  const Eigen::Vector2d& axis,
                                  const GroupingThresholds& limits);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_SEGMENT_GROUPING_H_
