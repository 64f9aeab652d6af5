// Which matched crossings serve as control (adjustment/control_selection.h):
// each tested against the others and the GNSS/INS error model.
#include "adjustment/control_selection.h"

#include <gtest/gtest.h>

#include <vector>

#include "adjustment/trajectory_adjuster.h"

namespace zebrageo {
namespace adjustment_internal {
namespace {

// A crossing's discrepancy (track frame: along, left, up) with the
// database's and the crossing offset's error, 7 cm per axis.
CrossingDiscrepancy Crossing(double time_s, const Eigen::Vector3d& value_m) {
  CrossingDiscrepancy d;
  d.valid = true;
  d.time_s = time_s;
  d.value_m = value_m;
  d.variance_m2 = Eigen::Vector3d::Constant(0.07 * 0.07);
  d.period_m = Eigen::Vector3d(0.0, 1.0, 0.0);
  d.vertices = 24;
  return d;
}

std::vector<CrossingVerdict> Select(
    const std::vector<CrossingDiscrepancy>& crossings,
    double two_crossings_sigma_m) {
  const AdjustmentOptions options;
  std::vector<std::string> names;
  for (size_t c = 0; c < crossings.size(); ++c) {
    names.push_back("zc-" + std::to_string(c));
  }
  return SelectConsistentCrossings(
      crossings, names, PositionFitOptions(options),
      options.crossing_consistency_chi_square, two_crossings_sigma_m);
}

int Rejected(const std::vector<CrossingVerdict>& verdicts) {
  int rejected = 0;
  for (const CrossingVerdict& v : verdicts) rejected += v.consistent ? 0 : 1;
  return rejected;
}

// A multipath error of the rendered sweep (random-11): between two right
// crossings 4.4 s (40 m) apart the error changes by 0.6 m along the track
// and 0.85 m across it, the second crossing lying where the INS is nearly
// right. Fitted on that one crossing, the error model allowed 3 cm of
// change, and the first crossing was dropped: H 5 -> 58 cm.
TEST(SelectConsistentCrossings,
     TwoCrossingsFollowAMetreOfDriftOverFortyMetres) {
  const std::vector<CrossingDiscrepancy> crossings = {
      Crossing(3.1, Eigen::Vector3d(0.64, -0.85, -0.06)),
      Crossing(7.5, Eigen::Vector3d(0.03, 0.0, 0.0))};
  EXPECT_EQ(Rejected(Select(
                crossings, AdjustmentOptions().two_crossings_position_sigma_m)),
            0);
  // Without the floor, the one-crossing fit rejects one of them: the test
  // above is not passed by a lax threshold.
  EXPECT_EQ(Rejected(Select(crossings, 0.0)), 1);
}

TEST(SelectConsistentCrossings, TwoCrossingsStillRejectAJumpNoDriftExplains) {
  // Four metres across the track within a second: a wrong match or a
  // database error, not a GNSS/INS drift.
  const std::vector<CrossingDiscrepancy> crossings = {
      Crossing(3.0, Eigen::Vector3d(0.1, 0.2, 0.0)),
      Crossing(4.0, Eigen::Vector3d(0.1, 4.2, 0.0))};
  const std::vector<CrossingVerdict> verdicts =
      Select(crossings, AdjustmentOptions().two_crossings_position_sigma_m);
  EXPECT_EQ(Rejected(verdicts), 1);
}

TEST(SelectConsistentCrossings, WithThreeTheRepaintedOneIsOut) {
  // The floor is for two crossings alone: with three, the error model is
  // fitted on the two others, and a crossing repainted 0.6 m across is
  // found where the INS is good to a decimetre.
  std::vector<CrossingDiscrepancy> crossings = {
      Crossing(0.0, Eigen::Vector3d(0.1, 0.1, 0.02)),
      Crossing(8.0, Eigen::Vector3d(0.1, 0.7, 0.0)),
      Crossing(16.0, Eigen::Vector3d(0.12, 0.08, 0.01))};
  const double floor_m = AdjustmentOptions().two_crossings_position_sigma_m;
  const std::vector<CrossingVerdict> verdicts = Select(crossings, floor_m);
  ASSERT_EQ(verdicts.size(), 3u);
  EXPECT_TRUE(verdicts[0].consistent);
  EXPECT_FALSE(verdicts[1].consistent);
  EXPECT_TRUE(verdicts[2].consistent);
  // Two alone cannot tell which is wrong: both kept.
  crossings.pop_back();
  EXPECT_EQ(Rejected(Select(crossings, floor_m)), 0);
}

}  // namespace
}  // namespace adjustment_internal
}  // namespace zebrageo
