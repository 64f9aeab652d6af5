#include "registration/dash_matcher.h"

#include <gtest/gtest.h>

#include <cmath>

namespace zebrageo {
namespace {

// A road along +x: a dashed centre line (3 m dashes every 8 m, from x = 0),
// a solid edge line, a long "dashed" line (a database that draws the dashed
// line as one polyline says nothing of its dashes) and a short solid piece.
std::vector<DatabaseLineEnu> Street() {
  std::vector<DatabaseLineEnu> db;
  auto line = [&](const std::string& type, double x0, double x1, double y) {
    DatabaseLineEnu l;
    l.id = type + std::to_string(db.size());
    l.type = type;
    l.points = {Eigen::Vector3d(x0, y, 0.0), Eigen::Vector3d(x1, y, 0.0)};
    l.sigma_xy_m = 0.05;
    db.push_back(l);
  };
  for (double x = 0.0; x < 80.0; x += 8.0) line("lane_dashed", x, x + 3.0, 0);
  line("lane_solid", 0.0, 80.0, -3.5);
  line("lane_dashed", 0.0, 80.0, 7.0);
  line("lane_solid", 20.0, 22.0, 3.5);
  return db;
}

// A dash seen from x0 to x1 at lateral y.
ReconstructedDashEnu Seen(double x0, double x1, double y, double gate_m) {
  return {Eigen::Vector3d(x0, y, 0.0), Eigen::Vector3d(x1, y, 0.0), gate_m};
}

TEST(DatabaseDashes, OnlyShortLinesNamedDashes) {
  const auto db = Street();
  const std::vector<int> dashes = DatabaseDashes(db, DashMatchOptions());
  ASSERT_EQ(dashes.size(), 10u);
  for (int d : dashes) EXPECT_EQ(db[d].points.front().y(), 0.0);
}

TEST(MatchDashes, AWholeDashGivesItsCentresOffsetAlongTheDash) {
  const auto db = Street();
  const auto db_dashes = DatabaseDashes(db, DashMatchOptions());
  // The dash at x = 16..19, seen 0.1 m shorter (its ends at half contrast,
  // within a few centimetres of the paint's), 0.15 m ahead and 0.1 m to the
  // side.
  const auto matches = MatchDashes({Seen(16.2, 19.1, 0.1, 0.3)}, db, db_dashes,
                                   DashMatchOptions());
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(db[matches[0].db_line].points.front().x(), 16.0);
  EXPECT_NEAR(matches[0].offset_m, 0.15, 1e-12);
  EXPECT_NEAR(matches[0].length_difference_m, -0.1, 1e-12);
  EXPECT_NEAR(matches[0].db_centre_enu.x(), 17.5, 1e-12);
  EXPECT_NEAR(std::abs(matches[0].along_enu.x()), 1.0, 1e-12);
}

TEST(MatchDashes, RefusesCutDashesAndOffsetsBeyondTheGate) {
  const auto db = Street();
  const auto db_dashes = DatabaseDashes(db, DashMatchOptions());
  const std::vector<ReconstructedDashEnu> seen = {
      // Cut by 1 m at one end: its centre is 0.5 m off.
      Seen(17.2, 18.8, 0.0, 1.0),
      // Cut by 0.4 m (a wheel over its end): its centre is 0.2 m off.
      Seen(16.4, 19.0, 0.0, 1.0),
      // Whole but 0.5 m ahead, with a 0.3 m gate.
      Seen(16.5, 19.5, 0.0, 0.3),
      // Whole, but 0.5 m to the side.
      Seen(16.0, 19.0, 0.5, 0.3),
      // Longer than painted.
      Seen(15.5, 19.5, 0.0, 0.3)};
  EXPECT_TRUE(MatchDashes(seen, db, db_dashes, DashMatchOptions()).empty());
  // The same second dash with a gate that allows it.
  EXPECT_EQ(MatchDashes({Seen(16.5, 19.5, 0.0, 0.6)}, db, db_dashes,
                        DashMatchOptions())
                .size(),
            1u);
}

TEST(MatchDashes, RefusesADashHalfWayToTheNext) {
  const auto db = Street();
  const auto db_dashes = DatabaseDashes(db, DashMatchOptions());
  // 3 m ahead of the dash at 16..19 (5 m behind the one at 24..27): a
  // trajectory that far off would match either; with any gate, none.
  EXPECT_TRUE(MatchDashes({Seen(19.0, 22.0, 0.0, 10.0)}, db, db_dashes,
                          DashMatchOptions())
                  .empty());
  // 1.2 m ahead: the next dash is 5.6 times farther.
  EXPECT_EQ(MatchDashes({Seen(17.2, 20.2, 0.0, 1.5)}, db, db_dashes,
                        DashMatchOptions())
                .size(),
            1u);
}

TEST(DashMatchOptions, CheckNamesTheField) {
  DashMatchOptions options;
  EXPECT_EQ(options.Check(), "");
  options.min_length_difference_m = 0.5;
  EXPECT_NE(options.Check().find("min_length_difference_m"), std::string::npos);
  options = DashMatchOptions();
  options.min_separation_ratio = 0.5;
  EXPECT_NE(options.Check().find("min_separation_ratio"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
