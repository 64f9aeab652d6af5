#include "reconstruction/long_sides.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace zebrageo {
namespace {

Segment2d Segment(double lateral, double from, double to) {
  Segment2d s;
  s.a = Eigen::Vector2d(lateral, from);  // direction +y, lateral along x
  s.b = Eigen::Vector2d(lateral, to);
  return s;
}

TEST(LongSides, DouglasPeuckerKeepsTheCornerOfAnL) {
  std::vector<Eigen::Vector2d> polyline;
  for (int i = 0; i <= 10; ++i) polyline.emplace_back(0.1 * i, 0.001 * (i % 2));
  for (int i = 1; i <= 10; ++i) polyline.emplace_back(1.0, 0.1 * i);
  EXPECT_EQ(DouglasPeucker(polyline, 0.02), (std::vector<int>{0, 10, 20}));
}

TEST(LongSides, AccumulatorPairsLinesOneBandWidthApart) {
  // A 4-band crossing (edges at 0, 0.5, ..., 3.5 m), its sides broken in
  // pieces; a lane line (two edges 0.15 m apart) at 5 m; manhole-cover
  // clutter at 7 m.
  std::vector<Segment2d> segments;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int edge = 0; edge < 8; ++edge) {
    for (double from = 0.0; from < 3.0; from += 0.6) {
      segments.push_back(Segment(0.5 * edge + noise(rng), from, from + 0.5));
    }
  }
  segments.push_back(Segment(5.0, 0.0, 3.0));
  segments.push_back(Segment(5.15, 0.0, 3.0));
  segments.push_back(Segment(7.0, 0.0, 0.6));
  const std::vector<AccumulatorComponent> components = ParallelLineComponents(
      segments, Eigen::Vector2d(0, 1), ZebraSpecification(), LongSideOptions());
  // With direction +y, the lateral axis is (-1, 0): laterals are -x.
  int paired = 0;
  for (const AccumulatorComponent& c : components) {
    const double x = -c.lateral_m;
    if (x < 3.7) {
      EXPECT_TRUE(c.paired) << x;
      EXPECT_NEAR(x, 0.5 * std::round(x / 0.5), 0.01);
      ++paired;
    } else {
      EXPECT_FALSE(c.paired) << x;  // the lane line, the clutter
    }
  }
  EXPECT_EQ(paired, 8);
}

TEST(LongSides, PrincipalDirectionIsTheMostFrequentOne) {
  std::vector<Segment2d> segments;
  for (int i = 0; i < 10; ++i) {
    Segment2d s;
    s.a = Eigen::Vector2d(i, 0);
    s.b = s.a + Eigen::Vector2d(std::cos(0.3), std::sin(0.3));
    segments.push_back(s);
  }
  Segment2d other;
  other.b = Eigen::Vector2d(0, 3);
  segments.push_back(other);
  double weight = 0.0;
  const Eigen::Vector2d d = PrincipalDirection(segments, 0.17, &weight);
  EXPECT_NEAR(std::atan2(d.y(), d.x()), 0.3, 0.005);
  EXPECT_NEAR(weight, 10.0, 1e-9);
}

// 3D chains of a 3-band crossing on the plane z = 1 (body), bands along x;
// one side of the middle band is broken by a 0.6 m occlusion.
std::vector<EdgeChain3d> CrossingChains() {
  std::vector<EdgeChain3d> chains;
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (int edge = 0; edge < 6; ++edge) {
    const double y = 0.5 * edge;  // band k: [y_2k, y_2k+1] bright
    const double gradient = edge % 2 == 0 ? 1.0 : -1.0;  // along +y
    std::vector<std::pair<double, double>> pieces = {{5.0, 8.0}};
    if (edge == 2) pieces = {{5.0, 6.0}, {6.6, 8.0}};
    for (const auto& [from, to] : pieces) {
      EdgeChain3d chain;
      for (double x = from; x <= to; x += 0.01) {
        EdgePoint3d p;
        p.p_body = Eigen::Vector3d(x, y + noise(rng), 1.0 + noise(rng));
        p.p_chain_body = p.p_body;
        // The plane frame's e1 is the body y axis (see the test).
        p.gradient = Eigen::Vector2d(30.0 * gradient, 0.0);
        chain.points.push_back(p);
      }
      chains.push_back(chain);
    }
  }
  return chains;
}

TEST(LongSides, DetectsEverySideAndBridgesTheOcclusion) {
  RoadPlane road;
  road.offset_m = 1.0;
  const PlaneFrame frame =
      PlaneFrame::Make(road, Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero());
  const LongSideDetection detection = DetectLongSides(
      CrossingChains(), frame, ZebraSpecification(), LongSideOptions());
  ASSERT_EQ(detection.sides.size(), 6u);
  for (const LongSide& side : detection.sides) {
    EXPECT_NEAR(side.Length(), 3.0, 0.02);  // the broken one too
    EXPECT_LT(std::abs(side.direction_body.x()), 1.0);
    EXPECT_NEAR(std::abs(side.direction_body.x()), 1.0, 1e-3);
    EXPECT_LT(side.lateral_rms_m, 0.004);
    // Brighter towards +y on even edges.
    const double y = side.point_body.y();
    const int edge = static_cast<int>(std::lround(y / 0.5));
    const double towards_plus_y =
        side.contrast * frame.Direction3d(side.Normal2d()).y();
    EXPECT_EQ(towards_plus_y > 0.0, edge % 2 == 0) << y;
  }
}

// A far crossing seen by a low rig, as triangulated: 3 bands (edges at
// 3.0, 3.5, ..., 5.5 m to the right), 13-16 m ahead, on a road that falls
// 2 % to the right (camber), each point moved along its left image ray by
// the depth error of a 0.15 px disparity error (f = 880 px, B = 0.8 m).
// Chains are ordered as in the image, one point per 1.5 cm.
struct FarCrossing {
  RoadPlane road;  // the flat plane fitted through the middle of the road
  Eigen::Vector3d camera = Eigen::Vector3d(0.0, 0.0, -1.0);  // 2 m up
  std::vector<EdgeChain3d> chains;
  std::vector<double> true_height;  // per chain: over `road`, metres
};

FarCrossing MakeFarCrossing() {
  FarCrossing far;
  far.road.offset_m = 1.0;
  std::mt19937 rng(5);
  std::normal_distribution<double> disparity_error(0.0, 0.15);
  for (int edge = 0; edge < 6; ++edge) {
    const double y = 3.0 + 0.5 * edge;
    const double height = 0.02 * y;  // below the plane: positive distance
    const double gradient = edge % 2 == 0 ? 1.0 : -1.0;
    EdgeChain3d chain;
    int index = 0;
    for (double x = 13.0; x <= 16.0; x += 0.015, ++index) {
      const Eigen::Vector3d truth(x, y, 1.0 + height);
      const Eigen::Vector3d ray = truth - far.camera;
      const double depth = ray.x();
      // dZ = Z^2 / (f B) dd, along the ray.
      const double depth_error =
          depth * depth / (880.0 * 0.8) * disparity_error(rng);
      EdgePoint3d p;
      p.p_body = truth + depth_error / depth * ray;
      p.p_chain_body = p.p_body;
      p.index_in_chain = index;
      p.gradient = Eigen::Vector2d(30.0 * gradient, 0.0);
      chain.points.push_back(p);
    }
    far.chains.push_back(chain);
    far.true_height.push_back(height);
  }
  return far;
}

TEST(LongSides, RegularisedHeightsRemoveTheStereoNoiseWithoutBias) {
  FarCrossing far = MakeFarCrossing();
  for (size_t c = 0; c < far.chains.size(); ++c) {
    EdgeChain3d& chain = far.chains[c];
    double raw_ss = 0.0, smooth_ss = 0.0, bias = 0.0;
    const double y = 3.0 + 0.5 * c;
    for (const EdgePoint3d& p : chain.points) {
      raw_ss += std::pow(p.p_body.y() - y, 2);
    }
    RegulariseChainHeights(far.road, far.camera, 25, &chain);
    for (const EdgePoint3d& p : chain.points) {
      smooth_ss += std::pow(p.p_chain_body.y() - y, 2);
      bias += far.road.SignedDistance(p.p_chain_body) - far.true_height[c];
      // Still on the left image ray: the image position is kept.
      const Eigen::Vector3d a = (p.p_body - far.camera).normalized();
      const Eigen::Vector3d b = (p.p_chain_body - far.camera).normalized();
      EXPECT_LT((a - b).norm(), 1e-9);
    }
    const double n = static_cast<double>(chain.points.size());
    // About 7 mm of lateral scatter before (0.15 px of disparity at 14 m,
    // 3-5.5 m aside), 1-2 mm after.
    EXPECT_GT(std::sqrt(raw_ss / n), 0.005);
    EXPECT_LT(std::sqrt(smooth_ss / n), 0.003);
    // The camber is kept: the heights are not pulled to the plane.
    EXPECT_LT(std::abs(bias / n), 0.001) << "chain " << c;
  }
}

TEST(LongSides, FarSidesAreWholeOnceHeightsAreRegularised) {
  FarCrossing far = MakeFarCrossing();
  const PlaneFrame frame = PlaneFrame::Make(far.road, Eigen::Vector3d::UnitY(),
                                            Eigen::Vector3d::Zero());
  // As triangulated, the noisy sides break into pieces (or are lost).
  const LongSideDetection raw = DetectLongSides(
      far.chains, frame, ZebraSpecification(), LongSideOptions());
  int whole = 0;
  for (const LongSide& side : raw.sides) whole += side.Length() > 2.9;
  EXPECT_LT(whole, 6);
  for (EdgeChain3d& chain : far.chains) {
    RegulariseChainHeights(far.road, far.camera, 25, &chain);
  }
  const LongSideDetection smooth = DetectLongSides(
      far.chains, frame, ZebraSpecification(), LongSideOptions());
  ASSERT_EQ(smooth.sides.size(), 6u);
  for (const LongSide& side : smooth.sides) {
    EXPECT_NEAR(side.Length(), 3.0, 0.08);  // the noisy ends may be cut
    const double y = side.point_body.y();
    EXPECT_NEAR(y, 0.5 * std::round(y / 0.5), 0.003);
    EXPECT_LT(side.lateral_rms_m, 0.003);
  }
}

TEST(LongSides, RegularisationIgnoresAMismatchedPoint) {
  EdgeChain3d chain;
  const Eigen::Vector3d camera(0.0, 0.0, -1.0);
  RoadPlane road;
  road.offset_m = 1.0;
  for (int i = 0; i < 60; ++i) {
    EdgePoint3d p;
    p.p_body = Eigen::Vector3d(8.0 + 0.015 * i, 1.0, 1.0);
    p.index_in_chain = i;
    chain.points.push_back(p);
  }
  // One match 10 cm above the road (a wrong disparity).
  EdgePoint3d& wrong = chain.points[30];
  wrong.p_body = camera + 0.9 / 2.0 * (wrong.p_body - camera);
  RegulariseChainHeights(road, camera, 25, &chain);
  for (const EdgePoint3d& p : chain.points) {
    EXPECT_NEAR(road.SignedDistance(p.p_chain_body), 0.0, 1e-9);
  }
}

TEST(LongSides, ASideDoesNotRunOnIntoACollinearEdgeOfOppositePolarity) {
  // The crossing of CrossingChains (x 5-8 m); the first side (y = 0,
  // brightening into the band) continues, 1 m after the band's end, as the
  // darkening edge of a lane line from x = 9 to 19 m.
  std::vector<EdgeChain3d> chains = CrossingChains();
  EdgeChain3d lane;
  for (double x = 9.0; x <= 19.0; x += 0.01) {
    EdgePoint3d p;
    p.p_body = p.p_chain_body = Eigen::Vector3d(x, 0.0, 1.0);
    p.gradient = Eigen::Vector2d(-30.0, 0.0);
    lane.points.push_back(p);
  }
  chains.push_back(lane);
  RoadPlane road;
  road.offset_m = 1.0;
  const PlaneFrame frame =
      PlaneFrame::Make(road, Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero());
  const LongSideDetection detection =
      DetectLongSides(chains, frame, ZebraSpecification(), LongSideOptions());
  int band_sides = 0;
  for (const LongSide& side : detection.sides) {
    if (std::abs(side.point_body.y()) > 0.1) continue;
    // Either the band's side (5-8 m) or the lane line's edge (9-19 m).
    const bool band =
        side.contrast * frame.Direction3d(side.Normal2d()).y() > 0.0;
    EXPECT_NEAR(side.Length(), band ? 3.0 : 10.0, 0.03);
    band_sides += band;
  }
  EXPECT_EQ(band_sides, 1);
}

TEST(LongSides, CheckNamesTheBadField) {
  LongSideOptions options;
  options.min_long_side_length_m = 0.0;
  EXPECT_EQ(options.Check(), "min_long_side_length_m = 0: must be > 0");
  options = LongSideOptions();
  options.height_smoothing_half_window = -1;
  EXPECT_EQ(options.Check(), "height_smoothing_half_window = -1: must be >= 0");
  ZebraSpecification zebra;
  zebra.max_band_length_m = 1.0;
  EXPECT_EQ(zebra.Check(),
            "max_band_length_m = 1: must be >= min_band_length_m (2.5)");
}

}  // namespace
}  // namespace zebrageo
