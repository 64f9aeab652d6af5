#include "registration/line_matcher.h"

#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace zebrageo
