// Lane-line dashes as along-track control.
//
// A road line constrains the position across itself only (line_matcher.h),
// so between zebra crossings nothing holds the trajectory along the track.
// A dashed lane line is a row of marks each with two ends: a database that
// draws each dash as its own short line (the road-mark databases made from
// aerial images do) fixes where every dash begins and ends. A reconstructed
// dash seen whole (both ends inside the images: reconstruction/road_lines.h)
// then places the vehicle along the track too.
//
// The reconstruction finds a dash's ends where its paint ends at half
// contrast, alike at both ends, so the dash's CENTRE (the mid-point of its
// two ends) is the observation, and its length tells a whole dash from one
// cut by an occlusion or the image border.
//
// A dash is matched to the database dash whose centre is nearest when
//   - its length minus the database dash's lies in [min_length_difference_m,
//     max_length_difference_m] (a cut dash is shorter, its centre off by
//     half the cut);
//   - its centre lies within gate_m of the database dash's centre along it
//     (the trajectory's remaining error, which the caller sets from the
//     posterior sd) and within max_across_m across it;
//   - every other database dash's centre is at least min_separation_ratio
//     times farther (dashes repeat every few metres: a trajectory off by
//     half the period would match the neighbour; then nothing is matched).
// Database lines count as dashes when their type names a dash and they are
// at most max_dash_length_m long.
//
// Frames: the survey's ENU frame, metres.
#ifndef ZEBRAGEO_REGISTRATION_DASH_MATCHER_H_
#define ZEBRAGEO_REGISTRATION_DASH_MATCHER_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "registration/line_matcher.h"

namespace zebrageo {

struct DashMatchOptions {
  double max_dash_length_m = 6.5;
  // Reconstructed minus database length: the road-line stage puts a dash's
  // ends where its paint ends at half contrast (reconstruction/
  // road_lines.h), so a whole dash measures its painted length: within
  // 0.15 m of it on rendered surveys (sd 0.08 m). One cut by a vehicle or
  // the image border is shorter, and its centre off by half the cut: a
  // cut over 0.3 m is refused. Longer by more than 0.3 m is two marks.
  double min_length_difference_m = -0.3;
  double max_length_difference_m = 0.3;
  double max_across_m = 0.4;
  double min_separation_ratio = 2.5;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_dash_length_m", max_dash_length_m);
    v("min_length_difference_m", min_length_difference_m);
    v("max_length_difference_m", max_length_difference_m);
    v("max_across_m", max_across_m);
    v("min_separation_ratio", min_separation_ratio);
  }
};

// One reconstructed dash in ENU: its two end points (the first and last
// points of the reconstructed line) and the gate along it.
struct ReconstructedDashEnu {
  Eigen::Vector3d first_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_enu = Eigen::Vector3d::Zero();
  double gate_m = 0.3;
};

struct DashMatch {
  int dash = 0;     // index into the reconstructed dashes
  int db_line = 0;  // index into the database lines
  Eigen::Vector3d db_centre_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d along_enu = Eigen::Vector3d::Zero();  // horizontal unit
  double offset_m = 0.0;             // reconstructed minus database, along
  double length_difference_m = 0.0;  // reconstructed minus database
};

// The database lines that are single dashes (see above).
std::vector<int> DatabaseDashes(const std::vector<DatabaseLineEnu>& database,
                                const DashMatchOptions& options);

// At most one match per reconstructed dash; `db_dashes` from
// DatabaseDashes.
std::vector<DashMatch> MatchDashes(
    const std::vector<ReconstructedDashEnu>& dashes,
    const std::vector<DatabaseLineEnu>& database,
    const std::vector<int>& db_dashes, const DashMatchOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_DASH_MATCHER_H_
