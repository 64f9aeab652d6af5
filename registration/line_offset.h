// The cross-track offset of a drifting trajectory from the road lines
// alone, for the line matching when no zebra crossing corrected the
// trajectory first.
//
// MatchLinePoints (line_matcher.h) takes each point's nearest database line
// within a gate: right when the trajectory is good to decimetres, wrong
// when it drifts by a metre or more, where a point lands nearer the next
// line (an edge line lies under 2 m from a lane divider). Here, per window
// of time, every reconstructed point votes for each lateral shift (along
// the vehicle's left) that would put it on a compatible database line
// within the search range (Hough voting); the shift most points agree on
// is taken when it beats every other shift at least min_separation_m away
// by min_ratio, and its points lie on two painted lines or more across the
// road (one line alone fits anywhere a line of its type is). A dashed
// point on a solid line votes a quarter: lanes repeat, their kinds less.
// Windows
// without such a shift are left undecided: their points are not used.
#ifndef ZEBRAGEO_REGISTRATION_LINE_OFFSET_H_
#define ZEBRAGEO_REGISTRATION_LINE_OFFSET_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "registration/line_matcher.h"

namespace zebrageo {

struct LateralOffsetOptions {
  // The shifts searched: +-max_offset_m (MatchOptions::max_drift_m).
  double max_offset_m = 4.0;
  double window_s = 2.0;
  double bin_m = 0.05;
  // A point votes for a shift that puts it this close to a line.
  double tolerance_m = 0.15;
  double min_separation_m = 0.5;
  double min_ratio = 2.0;
  int min_points = 10;
  // The voting points' spread across the road: two painted lines apart.
  double min_spread_m = 1.0;
  // Continuity: a window left undecided takes the shift within
  // continuity_m of a decided window at most continuity_windows away (the
  // nearest; its own such neighbours in turn), when at least
  // min_continuity_points agree on it. A GNSS/INS cross-track error moves
  // by centimetres between windows, painted lines lie a metre and more
  // apart: the lane a window alone could not tell (one line in view, or
  // lanes alike) is the one next to its neighbour's. A sudden switch (a
  // metre in a few seconds) leaves no votes that near, and the window
  // undecided. 0 windows: no continuity.
  int continuity_windows = 3;
  double continuity_m = 0.2;
  double min_continuity_points = 5.0;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_offset_m", max_offset_m);
    v("window_s", window_s);
    v("bin_m", bin_m);
    v("tolerance_m", tolerance_m);
    v("min_separation_m", min_separation_m);
    v("min_ratio", min_ratio);
    v("min_points", min_points);
    v("min_spread_m", min_spread_m);
    v("continuity_windows", continuity_windows);
    v("continuity_m", continuity_m);
    v("min_continuity_points", min_continuity_points);
  }
};

struct LateralOffset {
  double start_s = 0.0;  // the window [start_s, start_s + window_s)
  bool decided = false;
  double offset_m = 0.0;  // along the vehicle's left, to add to the points
  // The points voting for it (a lane line of the other kind counts a
  // quarter), and for the best shift min_separation_m away or more.
  double points = 0.0;
  double runner_up_points = 0.0;
  double spread_m = 0.0;
  // Decided by continuity with the window that many windows away (0: by
  // its own votes).
  int by_continuity = 0;
};

// Per window holding points (time order). `time_of[i]` and `left_of[i]`
// (horizontal unit vector, the vehicle's left) belong to points[i].
std::vector<LateralOffset> SearchLateralOffsets(
    const std::vector<LinePointEnu>& points, const std::vector<double>& time_of,
    const std::vector<Eigen::Vector2d>& left_of,
    const std::vector<DatabaseLineEnu>& database,
    const LateralOffsetOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_LINE_OFFSET_H_
