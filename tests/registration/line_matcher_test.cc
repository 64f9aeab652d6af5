#include "registration/line_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "registration/line_offset.h"

namespace zebrageo {
namespace {

// A straight road along +x (east): solid edge lines at y = -3.2 and 3.2, a
// dashed centre line at y = 0, a stop line across at x = 50.
std::vector<DatabaseLineEnu> Street() {
  std::vector<DatabaseLineEnu> db;
  auto line = [&](const std::string& type, Eigen::Vector3d a,
                  Eigen::Vector3d b) {
    DatabaseLineEnu l;
    l.id = type + std::to_string(db.size());
    l.type = type;
    for (int k = 0; k <= 10; ++k) l.points.push_back(a + (b - a) * k / 10.0);
    l.sigma_xy_m = 0.05;
    l.sigma_z_m = 0.05;
    db.push_back(l);
  };
  line("lane_solid", {0, -3.2, 0}, {100, -3.2, 0});
  line("lane_solid", {0, 3.2, 0}, {100, 3.2, 0});
  for (double x = 0; x < 100; x += 9) {
    line("lane_dashed", {x, 0, 0}, {x + 3, 0, 0});
  }
  line("stop_line", {50, -3.0, 0}, {50, -0.2, 0});
  return db;
}

// A reconstructed line along x at lateral y, from x0 to x1, shifted by the
// trajectory error `drift`.
std::vector<LinePointEnu> Seen(int64_t id, const std::string& type, double y,
                               double x0, double x1,
                               const Eigen::Vector3d& drift) {
  std::vector<LinePointEnu> points;
  for (double x = x0; x <= x1 + 1e-9; x += 1.0) {
    points.push_back({id, type, Eigen::Vector3d(x, y, 0.0) + drift});
  }
  return points;
}

TEST(MatchLinePoints, MatchesUnderDriftAndSaysWhatIsConstrained) {
  const auto db = Street();
  const Eigen::Vector3d drift(0.7, 0.3, -0.1);  // along, across, up
  auto points = Seen(1, "lane_solid", -3.2, 10, 20, drift);
  const auto dashed = Seen(2, "lane_dashed", 0.0, 18.5, 20.5, drift);
  points.insert(points.end(), dashed.begin(), dashed.end());
  const auto matches = MatchLinePoints(points, db, LineMatchOptions());
  ASSERT_EQ(matches.size(), points.size());
  for (const LinePointMatch& m : matches) {
    EXPECT_EQ(db[m.db_line].type.substr(0, 5), "lane_");
    EXPECT_NEAR(std::abs(m.across_enu.y()), 1.0, 1e-9);
    EXPECT_NEAR(std::abs(m.along_enu.x()), 1.0, 1e-9);
    // The residual across is the drift across; along is not seen.
    EXPECT_NEAR(m.distance_m * m.across_enu.y(), 0.3, 1e-9);
    EXPECT_NEAR(m.height_m, -0.1, 1e-9);
  }
  EXPECT_EQ(matches.front().db_line, 0);
}

TEST(MatchLinePoints, LeavesOutAmbiguousAndFarLines) {
  const auto db = Street();
  // Half-way between the centre line and an edge line: ambiguous.
  auto points = Seen(1, "lane_solid", -1.6, 10, 20, Eigen::Vector3d::Zero());
  // Beyond the gate.
  const auto far = Seen(2, "lane_solid", 4.5, 10, 20, Eigen::Vector3d::Zero());
  points.insert(points.end(), far.begin(), far.end());
  EXPECT_TRUE(MatchLinePoints(points, db, LineMatchOptions()).empty());
}

TEST(MatchLinePoints, TypesAndDirectionMustAgree) {
  const auto db = Street();
  // A "stop line" on the edge line: no stop line there.
  auto points = Seen(1, "stop_line", -3.2, 10, 20, Eigen::Vector3d::Zero());
  // A lane line crossing the edge line at 30 degrees.
  for (int k = 0; k < 6; ++k) {
    points.push_back({2, "lane_solid",
                      Eigen::Vector3d(30 + 0.5 * k * std::cos(0.5),
                                      3.2 + 0.5 * (k - 3) * std::sin(0.5), 0)});
  }
  EXPECT_TRUE(MatchLinePoints(points, db, LineMatchOptions()).empty());
  // The stop line itself matches, across = along x.
  std::vector<LinePointEnu> stop;
  for (double y = -2.4; y <= -0.7; y += 0.4) {
    stop.push_back({3, "stop_line", Eigen::Vector3d(50.2, y, 0)});
  }
  const auto matches = MatchLinePoints(stop, db, LineMatchOptions());
  ASSERT_EQ(matches.size(), stop.size());
  EXPECT_NEAR(std::abs(matches[0].across_enu.x()), 1.0, 1e-9);
  EXPECT_NEAR(std::abs(matches[0].distance_m), 0.2, 1e-9);
}

// Both edge lines and the centre line seen from 0 to 100 m at 10 m/s,
// with a common trajectory error `drift`; the right edge line painted
// `moved_m` to the left of where the database has it.
struct SeenStreet {
  std::vector<LinePointEnu> points;
  std::vector<double> time;  // per point
  // Adds a reconstructed line, seen at 10 m/s.
  void Add(const std::vector<LinePointEnu>& line) {
    for (const LinePointEnu& p : line) {
      points.push_back(p);
      time.push_back(p.p_enu.x() / 10.0);
    }
  }
};
SeenStreet SeeStreet(const Eigen::Vector3d& drift, double moved_m) {
  SeenStreet seen;
  seen.Add(Seen(1, "lane_solid", -3.2 + moved_m, 1, 99, drift));
  seen.Add(Seen(2, "lane_solid", 3.2, 1, 99, drift));
  for (double x = 0; x < 100; x += 9) {
    seen.Add(Seen(3 + static_cast<int64_t>(x), "lane_dashed", 0.0, x + 0.5,
                  x + 2.5, drift));
  }
  return seen;
}

TEST(DatabaseLineGrade, FitsTheSlopeOverTheWindowNotOneSegment) {
  // A line climbing 2 % eastwards, vertices every 2.5 m with +-3 cm of
  // height noise (alternating): one 2.5 m segment alone reads +-2.4 %.
  DatabaseLineEnu line;
  for (int i = 0; i <= 16; ++i) {
    const double x = 2.5 * i;
    line.points.emplace_back(x, 0.0, 0.02 * x + (i % 2 == 0 ? 0.03 : -0.03));
  }
  const double segment_slope = (line.points[5].z() - line.points[4].z()) / 2.5;
  EXPECT_GT(std::abs(segment_slope - 0.02), 0.02);
  EXPECT_NEAR(DatabaseLineGrade(line, 4, 0.5, 10.0), 0.02, 0.002);
  // Walking the line the other way reverses the slope.
  std::reverse(line.points.begin(), line.points.end());
  EXPECT_NEAR(DatabaseLineGrade(line, 11, 0.5, 10.0), -0.02, 0.002);
  // A two-vertex dash: the segment's own slope.
  DatabaseLineEnu dash;
  dash.points = {Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d(3, 0, 1.06)};
  EXPECT_NEAR(DatabaseLineGrade(dash, 0, 0.3, 10.0), 0.02, 1e-12);
  EXPECT_EQ(DatabaseLineGrade(dash, 1, 0.3, 10.0), 0.0);  // no such segment
}

TEST(RejectInconsistentLines, RejectsALineRepaintedSinceTheDatabase) {
  const auto db = Street();
  const SeenStreet seen = SeeStreet(Eigen::Vector3d(0.4, -0.25, 0.1), 0.3);
  const auto matches = MatchLinePoints(seen.points, db, LineMatchOptions());
  // Within the gate, the moved line matches its old database position.
  const auto on_moved =
      std::count_if(matches.begin(), matches.end(),
                    [](const LinePointMatch& m) { return m.db_line == 0; });
  ASSERT_GE(on_moved, 95);
  std::vector<LinePointMatch> kept;
  const auto rejected = RejectInconsistentLines(
      matches, seen.time, LineConsistencyOptions(), &kept);
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].db_line, 0);
  // The offset is the repaint, not the trajectory's error (-0.25 across).
  EXPECT_NEAR(std::abs(rejected[0].offset_m), 0.3, 0.01);
  EXPECT_GT(rejected[0].points, 50);
  for (const LinePointMatch& m : kept) EXPECT_NE(m.db_line, 0);
  EXPECT_EQ(kept.size(), matches.size() - on_moved);
}

TEST(RejectInconsistentLines, KeepsLinesThatAgreeOrCannotBeChecked) {
  const auto db = Street();
  // A large common error is the trajectory's, not the lines'.
  const SeenStreet seen = SeeStreet(Eigen::Vector3d(0.4, -0.45, 0.1), 0.0);
  const auto matches = MatchLinePoints(seen.points, db, LineMatchOptions());
  std::vector<LinePointMatch> kept;
  EXPECT_TRUE(RejectInconsistentLines(matches, seen.time,
                                      LineConsistencyOptions(), &kept)
                  .empty());
  EXPECT_EQ(kept.size(), matches.size());
  // One line alone, even off by 0.3 m: nothing to compare with, kept.
  const auto alone =
      Seen(1, "lane_solid", -2.9, 1, 99, Eigen::Vector3d::Zero());
  std::vector<double> time;
  for (const auto& p : alone) time.push_back(p.p_enu.x() / 10.0);
  const auto alone_matches = MatchLinePoints(alone, db, LineMatchOptions());
  ASSERT_FALSE(alone_matches.empty());
  EXPECT_TRUE(RejectInconsistentLines(alone_matches, time,
                                      LineConsistencyOptions(), &kept)
                  .empty());
  EXPECT_EQ(kept.size(), alone_matches.size());
}

// A dashed centre line repainted 0.3 m over, its dashes each a database
// line of their own: the dashes are one painted line and vote once, so
// they are rejected, not the two solid lines they outnumber. The solid
// lines are checked (vouched for by another line).
TEST(RejectInconsistentLines, ADashedLineOfManyPiecesVotesOnce) {
  const auto db = Street();
  SeenStreet seen;
  const Eigen::Vector3d drift(0.4, -0.25, 0.1);
  seen.Add(Seen(1, "lane_solid", -3.2, 1, 99, drift));
  seen.Add(Seen(2, "lane_solid", 3.2, 1, 99, drift));
  for (double x = 0; x < 100; x += 9) {
    seen.Add(Seen(3 + static_cast<int64_t>(x), "lane_dashed", 0.3, x + 0.5,
                  x + 2.5, drift));
  }
  const auto matches = MatchLinePoints(seen.points, db, LineMatchOptions());
  std::vector<LinePointMatch> kept;
  std::set<int> checked;
  const auto rejected = RejectInconsistentLines(
      matches, seen.time, LineConsistencyOptions(), &kept, &checked);
  ASSERT_FALSE(rejected.empty());
  for (const RejectedLine& r : rejected) {
    EXPECT_EQ(db[r.db_line].type, "lane_dashed");
    EXPECT_NEAR(std::abs(r.offset_m), 0.3, 0.05);
  }
  EXPECT_TRUE(checked.count(0));
  EXPECT_TRUE(checked.count(1));
  for (const LinePointMatch& m : kept) {
    EXPECT_EQ(db[m.db_line].type, "lane_solid");
  }
}

// A solid line drawn in three pieces whose middle piece the database has
// 0.45 m over (a section repainted since): that piece is tested on its
// own, not pooled with the pieces it continues, and is the only one out.
TEST(RejectInconsistentLines, AMovedPieceOfALineIsOutAlone) {
  std::vector<DatabaseLineEnu> db = Street();
  DatabaseLineEnu& edge = db[0];  // y = -3.2, x 0..100
  auto piece = [&](double x0, double x1, double y) {
    DatabaseLineEnu l = edge;
    l.id = "edge" + std::to_string(db.size());
    l.points = {Eigen::Vector3d(x0, y, 0), Eigen::Vector3d(x1, y, 0)};
    return l;
  };
  const DatabaseLineEnu a = piece(0, 40, -3.2), b = piece(40, 70, -3.65),
                        c = piece(70, 100, -3.2);
  edge = a;
  db.push_back(b);
  db.push_back(c);
  const int moved = static_cast<int>(db.size()) - 2;
  // Each exposure sees a few metres of line: one reconstructed line per
  // 10 m, each within one piece.
  SeenStreet seen;
  const Eigen::Vector3d drift(0.0, -0.1, 0.0);
  for (double x = 0; x < 100; x += 10) {
    seen.Add(Seen(200 + static_cast<int64_t>(x), "lane_solid", -3.2, x + 1,
                  x + 9, drift));
    seen.Add(Seen(300 + static_cast<int64_t>(x), "lane_solid", 3.2, x + 1,
                  x + 9, drift));
  }
  for (double x = 0; x < 100; x += 9) {
    seen.Add(Seen(3 + static_cast<int64_t>(x), "lane_dashed", 0.0, x + 0.5,
                  x + 2.5, drift));
  }
  const auto matches = MatchLinePoints(seen.points, db, LineMatchOptions());
  std::vector<LinePointMatch> kept;
  const auto rejected = RejectInconsistentLines(
      matches, seen.time, LineConsistencyOptions(), &kept);
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].db_line, moved);
  EXPECT_NEAR(std::abs(rejected[0].offset_m), 0.45, 0.03);
}

// The street seen from a trajectory `across` metres off to the right (the
// road runs east: left is north), 10 m/s.
struct Offsets {
  std::vector<LateralOffset> windows;
  SeenStreet seen;
};
Offsets SearchStreet(double across, bool centre_only) {
  Offsets out;
  const Eigen::Vector3d drift(0.3, -across, 0.0);
  if (!centre_only) {
    out.seen.Add(Seen(1, "lane_solid", -3.2, 1, 99, drift));
    out.seen.Add(Seen(2, "lane_solid", 3.2, 1, 99, drift));
  }
  for (double x = 0; x < 100; x += 9) {
    out.seen.Add(Seen(3 + static_cast<int64_t>(x), "lane_dashed", 0.0, x + 0.5,
                      x + 2.5, drift));
  }
  const std::vector<Eigen::Vector2d> left(out.seen.points.size(),
                                          Eigen::Vector2d::UnitY());
  out.windows = SearchLateralOffsets(out.seen.points, out.seen.time, left,
                                     Street(), LateralOffsetOptions());
  return out;
}

// 1.6 m off: nearer the next line than its own for the nearest-line
// matcher (1.6 of 3.2 m), found by the lines voting together.
TEST(SearchLateralOffsets, FindsADriftOfHalfALaneFromTheLinesTogether) {
  const Offsets found = SearchStreet(1.6, false);
  ASSERT_GE(found.windows.size(), 5u);
  for (const LateralOffset& w : found.windows) {
    if (w.start_s > 9.0) continue;  // the last dash's end alone
    EXPECT_TRUE(w.decided) << "window at " << w.start_s << ": " << w.points
                           << " points against " << w.runner_up_points;
    EXPECT_NEAR(w.offset_m, 1.6, 0.02);
    EXPECT_GT(w.spread_m, 6.0);
  }
}

// One painted line fits wherever a line of its kind is: undecided.
TEST(SearchLateralOffsets, OneLineAloneDecidesNothing) {
  const Offsets found = SearchStreet(0.5, true);
  ASSERT_FALSE(found.windows.empty());
  for (const LateralOffset& w : found.windows) EXPECT_FALSE(w.decided);
}

// Once the lines together decided the shift, one line alone keeps it in
// the next windows (continuity), but not across a sudden 1 m switch.
TEST(SearchLateralOffsets, OneLineKeepsTheShiftByContinuityNotAcrossASwitch) {
  const Eigen::Vector3d drift(0.3, -1.6, 0.0);
  const Eigen::Vector3d switched(0.3, -2.6, 0.0);
  SeenStreet seen;
  seen.Add(Seen(1, "lane_solid", -3.2, 1, 19, drift));
  seen.Add(Seen(2, "lane_solid", 3.2, 1, 19, drift));
  seen.Add(Seen(3, "lane_solid", -3.2, 20, 59, drift));
  seen.Add(Seen(4, "lane_solid", -3.2, 60, 99, switched));
  const std::vector<Eigen::Vector2d> left(seen.points.size(),
                                          Eigen::Vector2d::UnitY());
  const std::vector<LateralOffset> windows = SearchLateralOffsets(
      seen.points, seen.time, left, Street(), LateralOffsetOptions());
  ASSERT_GE(windows.size(), 5u);
  int by_continuity = 0;
  for (const LateralOffset& w : windows) {
    SCOPED_TRACE(::testing::Message() << "window at " << w.start_s);
    if (w.start_s < 6.0) {  // (the window at 4.1 s ends 2 dm switched)
      EXPECT_TRUE(w.decided);
      EXPECT_NEAR(w.offset_m, 1.6, 0.02);
      EXPECT_EQ(w.by_continuity > 0, w.start_s > 1.0);
      by_continuity += w.by_continuity > 0;
    } else {
      EXPECT_FALSE(w.decided);
    }
  }
  EXPECT_GE(by_continuity, 2);
  // Without continuity only the first window is decided.
  LateralOffsetOptions alone;
  alone.continuity_windows = 0;
  int decided = 0;
  for (const LateralOffset& w :
       SearchLateralOffsets(seen.points, seen.time, left, Street(), alone)) {
    decided += w.decided;
  }
  EXPECT_EQ(decided, 1);
}

TEST(LateralOffsetOptions, CheckNamesTheProblem) {
  LateralOffsetOptions options;
  EXPECT_EQ(options.Check(), "");
  options.min_ratio = 0.5;
  EXPECT_NE(options.Check().find("min_ratio"), std::string::npos);
  options = LateralOffsetOptions();
  options.bin_m = 0.0;
  EXPECT_NE(options.Check().find("bin_m"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
