#include "registration/edge_matcher.h"

#include <gtest/gtest.h>

#include <cmath>

namespace zebrageo {
namespace {

// A crossing of `bands` bands 0.5 m wide, 1 m apart, 3 m long, along the
// road's direction `heading` (ENU, radians from east), its near ends (the
// -u ends) on x = x0 along the road; skewed ends optional.
void AddCrossing(const LocalFrame& frame, const std::string& id, double x0,
                 int bands, double heading, double skew, RoadmarkDatabase* db) {
  const Eigen::Vector2d u(std::cos(heading), std::sin(heading));
  const Eigen::Vector2d w(-u.y(), u.x());
  for (int b = 0; b < bands; ++b) {
    RoadmarkBand band;
    band.crossing_id = id;
    band.band = b + 1;
    band.sigma_xy_m = 0.05;
    band.sigma_z_m = 0.1;
    const double y0 = -2.5 + b, y1 = y0 + 0.5;
    // Counter-clockwise seen from above.
    const Eigen::Vector2d corners[4] = {
        (x0 + skew * y0) * u + y0 * w, (x0 + skew * y0 + 3.0) * u + y0 * w,
        (x0 + skew * y1 + 3.0) * u + y1 * w, (x0 + skew * y1) * u + y1 * w};
    for (int k = 0; k < 4; ++k) {
      band.corners[k] = frame.GeodeticFromEnu(
          Eigen::Vector3d(corners[k].x(), corners[k].y(), 0.0));
    }
    db->bands.push_back(band);
  }
}

const LocalFrame& Frame() {
  static const LocalFrame frame(Geodetic{-34.6, -58.4, 20.0});
  return frame;
}

// The far (+u) ends of bands 2..4 seen from a vehicle driving along u,
// `along` metres behind where it thinks (the points land ahead of the
// paint by `along`), ordered so that the paint (behind, -u) is on their
// left.
std::vector<Eigen::Vector3d> SeenFarEnds(double x0, double heading,
                                         double along, double skew = 0.0) {
  const Eigen::Vector2d u(std::cos(heading), std::sin(heading));
  const Eigen::Vector2d w(-u.y(), u.x());
  std::vector<Eigen::Vector3d> points;
  for (int b = 1; b <= 3; ++b) {
    const double y = -2.5 + b + 0.25;
    const Eigen::Vector2d p = (x0 + skew * y + 3.0 + along) * u + y * w;
    points.emplace_back(p.x(), p.y(), 0.0);
  }
  return points;  // running along +w: left of +w is -u, the paint
}

TEST(DatabaseCrossingEdges, BothEdgesWithThePaintOnTheirLeft) {
  RoadmarkDatabase db;
  AddCrossing(Frame(), "C1", 10.0, 5, 0.3, 0.0, &db);
  const std::vector<DatabaseCrossingEdge> edges =
      DatabaseCrossingEdges(db, Frame());
  ASSERT_EQ(edges.size(), 2u);
  const Eigen::Vector2d u(std::cos(0.3), std::sin(0.3));
  for (const DatabaseCrossingEdge& e : edges) {
    EXPECT_EQ(e.crossing_id, "C1");
    EXPECT_EQ(e.points.size(), 5u);
    // The paint lies towards the crossing's middle (x0 + 1.5 along u).
    const Eigen::Vector2d middle = 11.5 * u;
    EXPECT_GT((middle - e.point).dot(e.Normal()), 1.4);
    EXPECT_NEAR(e.to_m - e.from_m, 4.0, 1e-6);
    EXPECT_NEAR(std::abs(e.direction.dot(u)), 0.0, 1e-6);
  }
  EXPECT_NE(edges[0].id, edges[1].id);
}

TEST(MatchCrossingEdges, TheFarEdgeAndItsOffsetWhateverTheSkew) {
  for (const double skew : {0.0, 0.4}) {
    SCOPED_TRACE(::testing::Message() << "skew " << skew);
    RoadmarkDatabase db;
    AddCrossing(Frame(), "C1", 10.0, 5, 1.2, skew, &db);
    AddCrossing(Frame(), "C2", 60.0, 5, 1.2, skew, &db);
    const auto edges = DatabaseCrossingEdges(db, Frame());
    const auto matches = MatchCrossingEdges({SeenFarEnds(10.0, 1.2, 0.7, skew)},
                                            edges, CrossingEdgeMatchOptions());
    ASSERT_EQ(matches.size(), 1u);
    const DatabaseCrossingEdge& e = edges[matches[0].db_edge];
    EXPECT_EQ(e.crossing_id, "C1");
    EXPECT_EQ(e.id, "C1:edge+");
    // 0.7 m ahead of the paint's edge, away from the paint: -0.7 along the
    // normal towards it, whatever the skew.
    EXPECT_NEAR(matches[0].offset_m, -0.7 / std::sqrt(1.0 + skew * skew), 1e-6);
  }
}

TEST(MatchCrossingEdges, RefusesTheWrongWayOutOfTheGateOrBetweenTwo) {
  RoadmarkDatabase db;
  AddCrossing(Frame(), "C1", 10.0, 5, 0.0, 0.0, &db);
  const auto edges = DatabaseCrossingEdges(db, Frame());
  const CrossingEdgeMatchOptions options;
  // The paint on the other side: the near edge 3 m back is the only one
  // that runs that way, out of the gate.
  std::vector<Eigen::Vector3d> reversed = SeenFarEnds(10.0, 0.0, 0.0);
  std::reverse(reversed.begin(), reversed.end());
  EXPECT_TRUE(MatchCrossingEdges({reversed}, edges, options).empty());
  // 1.6 m off: out of the 1.5 m gate.
  EXPECT_TRUE(MatchCrossingEdges({SeenFarEnds(10.0, 0.0, 1.6)}, edges, options)
                  .empty());
  // Two crossings' far edges 1.2 m apart along the road (a double
  // crossing): 0.5 m from one is 0.7 m from the other, too close to tell.
  db.bands.clear();
  AddCrossing(Frame(), "C1", 10.0, 5, 0.0, 0.0, &db);
  AddCrossing(Frame(), "C2", 11.2, 5, 0.0, 0.0, &db);
  const auto two = DatabaseCrossingEdges(db, Frame());
  EXPECT_TRUE(
      MatchCrossingEdges({SeenFarEnds(10.0, 0.0, 0.5)}, two, options).empty());
  // Most points beyond the database edge's extent (another crossing on the
  // same line): not this edge.
  std::vector<Eigen::Vector3d> beside = SeenFarEnds(10.0, 0.0, 0.1);
  for (Eigen::Vector3d& p : beside) p.y() += 6.0;
  EXPECT_TRUE(MatchCrossingEdges({beside}, edges, options).empty());
}

TEST(CrossingEdgeMatchOptions, Check) {
  EXPECT_EQ(CrossingEdgeMatchOptions().Check(), "");
  CrossingEdgeMatchOptions o;
  o.min_separation_ratio = 0.5;
  EXPECT_NE(o.Check().find("min_separation_ratio"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
