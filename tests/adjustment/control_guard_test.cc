// The guard of "never worse than the input" (adjustment/control_guard.h) on
// plain data: crossings placed with the input and the adjusted trajectory.
#include "adjustment/control_guard.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "adjustment/adjustment_options.h"

namespace zebrageo {
namespace {

// A crossing of 16 vertices at time t (observed over [t - 2, t]), its
// database corners `database_error` off the truth, placed by trajectories
// off by `input_error` and `adjusted_error`, with 1 cm of noise per vertex.
GuardCrossing CrossingAt(const std::string& id, double t,
                         const Eigen::Vector3d& input_error,
                         const Eigen::Vector3d& adjusted_error,
                         const Eigen::Vector3d& database_error, bool used,
                         std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0.0, 0.01);
  GuardCrossing c;
  c.id = id;
  c.first_time_s = t - 2.0;
  c.last_time_s = t;
  c.used = used;
  for (int v = 0; v < 16; ++v) {
    const Eigen::Vector3d truth(10.0 * t + 0.5 * (v % 8), 3.0 * (v / 8), 0.0);
    const Eigen::Vector3d n((noise)(*rng), (noise)(*rng), (noise)(*rng));
    c.database_enu.push_back(truth + database_error);
    c.input_enu.push_back(truth + input_error + n);
    c.adjusted_enu.push_back(truth + adjusted_error + n);
  }
  c.sigma_m = Eigen::Vector3d::Constant(0.07);
  return c;
}

TEST(ControlGuard, StandsByAnAdjustmentThatFitsTheControlBetter) {
  std::mt19937_64 rng(1);
  std::vector<GuardCrossing> crossings;
  for (int k = 0; k < 5; ++k) {
    crossings.push_back(CrossingAt(
        "C" + std::to_string(k), 20.0 * k, Eigen::Vector3d(0.8, -0.5, 0.2),
        Eigen::Vector3d(0.02, 0.01, 0.0), Eigen::Vector3d(0.05, -0.08, 0.03),
        true, &rng));
  }
  const GuardResult guard = GuardAgainstInput(crossings, NeverWorseOptions());
  ASSERT_EQ(guard.verdicts.size(), 5u);
  EXPECT_FALSE(guard.Fired());
  for (const GuardVerdict& v : guard.verdicts) {
    EXPECT_FALSE(v.worse);
    EXPECT_LT(v.z, -2.0);
  }
  EXPECT_EQ(guard.AdjustedWeight(-100.0), 1.0);
  EXPECT_EQ(guard.AdjustedWeight(35.0), 1.0);
}

// Two trajectories as far from the truth (4 cm, in different directions):
// whatever the database's offset, the guard fires about once in 700 (its
// 3 sd), never where they lie within 5 cm of each other.
TEST(ControlGuard, RarelyFiresBetweenTrajectoriesEquallyGood) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> offset(0.0, 0.07);
  int fired = 0, fired_close = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector3d database(offset(rng), offset(rng), offset(rng));
    fired +=
        GuardAgainstInput(
            {CrossingAt("C", 10.0, Eigen::Vector3d(0.2, 0.0, 0.0),
                        Eigen::Vector3d(0.0, 0.2, 0.0), database, true, &rng)},
            NeverWorseOptions())
            .Fired();
    fired_close +=
        GuardAgainstInput(
            {CrossingAt("C", 10.0, Eigen::Vector3d(0.03, 0, 0),
                        Eigen::Vector3d(0, 0.03, 0), database, true, &rng)},
            NeverWorseOptions())
            .Fired();
  }
  EXPECT_LE(fired, 6);
  EXPECT_EQ(fired_close, 0);
}

TEST(ControlGuard, KeepsTheInputOverTheStretchTheAdjustmentFitsWorse) {
  std::mt19937_64 rng(3);
  const Eigen::Vector3d good_in(0.6, 0.3, 0.1), good_adj(0.01, 0.02, 0.0);
  const Eigen::Vector3d db = Eigen::Vector3d::Zero();
  std::vector<GuardCrossing> crossings = {
      CrossingAt("A", 10.0, good_in, good_adj, db, true, &rng),
      CrossingAt("B", 30.0, good_in, good_adj, db, true, &rng),
      // The adjusted trajectory 1.3 m off where the input is 0.3 m off.
      CrossingAt("C", 50.0, Eigen::Vector3d(0.3, 0.0, 0.0),
                 Eigen::Vector3d(1.0, -0.9, 0.1), db, false, &rng),
      CrossingAt("D", 70.0, good_in, good_adj, db, true, &rng)};
  const GuardResult guard = GuardAgainstInput(crossings, NeverWorseOptions());
  ASSERT_TRUE(guard.Fired());
  ASSERT_EQ(guard.kept.size(), 1u);
  const KeptStretch& k = guard.kept[0];
  ASSERT_EQ(k.crossings, std::vector<std::string>({"C"}));
  EXPECT_DOUBLE_EQ(k.ramp_begin_s, 30.0);  // B's last observation
  EXPECT_DOUBLE_EQ(k.begin_s, 48.0);       // C's first
  EXPECT_DOUBLE_EQ(k.end_s, 50.0);         // C's last
  EXPECT_DOUBLE_EQ(k.ramp_end_s, 68.0);    // D's first
  EXPECT_NEAR(k.adjusted_misfit_m, std::hypot(1.0, 0.9, 0.1), 0.02);
  EXPECT_NEAR(k.input_misfit_m, 0.3, 0.02);
  // The input over C, the adjustment at B and D, blended between.
  EXPECT_EQ(guard.AdjustedWeight(49.0), 0.0);
  EXPECT_EQ(guard.AdjustedWeight(30.0), 1.0);
  EXPECT_EQ(guard.AdjustedWeight(68.0), 1.0);
  EXPECT_NEAR(guard.AdjustedWeight(39.0), 0.5, 1e-9);
  EXPECT_FALSE(guard.KeepsInputEverywhere());
  const std::string text = KeptStretchText(k, 0.0);
  EXPECT_NE(text.find("crossing C worse than the input trajectory does"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("the input trajectory is kept from 48.0 s to 50.0 s"),
            std::string::npos)
      << text;
}

// Past the last crossing that stands by the adjustment, the input stays to
// the end of the survey.
TEST(ControlGuard, AStretchAfterTheLastCrossingKeepsTheInputToTheEnd) {
  std::mt19937_64 rng(4);
  const GuardResult guard = GuardAgainstInput(
      {CrossingAt("A", 10.0, Eigen::Vector3d(0.5, 0.0, 0.0),
                  Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), true, &rng),
       CrossingAt("B", 40.0, Eigen::Vector3d(0.2, 0.1, 0.0),
                  Eigen::Vector3d(-1.2, 1.4, 0.0), Eigen::Vector3d::Zero(),
                  true, &rng)},
      NeverWorseOptions());
  ASSERT_EQ(guard.kept.size(), 1u);
  EXPECT_TRUE(std::isinf(guard.kept[0].end_s));
  EXPECT_EQ(guard.AdjustedWeight(1000.0), 0.0);
  EXPECT_EQ(guard.AdjustedWeight(0.0), 1.0);
  EXPECT_NE(KeptStretchText(guard.kept[0], 0.0).find("to the end"),
            std::string::npos);
}

// A crossing the adjustment rejected (moved 1.5 m in the database) that
// the input misses too says nothing of either trajectory; one the input
// fits objects.
TEST(ControlGuard, ARejectedCrossingObjectsOnlyWhereTheInputFitsIt) {
  std::mt19937_64 rng(5);
  const Eigen::Vector3d moved(1.2, 0.9, 0.0);
  const GuardCrossing wrong =
      CrossingAt("X9", 10.0, Eigen::Vector3d(0.5, 0.4, 0.0),
                 Eigen::Vector3d(0.02, 0.0, 0.0), moved, false, &rng);
  EXPECT_FALSE(GuardAgainstInput({wrong}, NeverWorseOptions()).Fired());
  const GuardCrossing fitted =
      CrossingAt("X9", 10.0, Eigen::Vector3d(1.15, 0.85, 0.0),
                 Eigen::Vector3d(0.02, 0.0, 0.0), moved, false, &rng);
  EXPECT_TRUE(GuardAgainstInput({fitted}, NeverWorseOptions()).Fired());
  // Used as control the same misfit objects.
  GuardCrossing used = wrong;
  used.used = true;
  EXPECT_TRUE(GuardAgainstInput({used}, NeverWorseOptions()).Fired());
}

TEST(ControlGuard, OffWithZeroSigmas) {
  std::mt19937_64 rng(6);
  NeverWorseOptions options;
  options.guard_sigmas = 0.0;
  EXPECT_EQ(options.Check(), "");
  const GuardResult guard =
      GuardAgainstInput({CrossingAt("A", 10.0, Eigen::Vector3d::Zero(),
                                    Eigen::Vector3d(2.0, 0.0, 0.0),
                                    Eigen::Vector3d::Zero(), true, &rng)},
                        options);
  EXPECT_FALSE(guard.Fired());
  options.guard_sigmas = -1.0;
  EXPECT_NE(options.Check().find("guard_sigmas"), std::string::npos);
  // Within the adjustment's options the problem is named by its path.
  AdjustmentOptions adjustment;
  adjustment.never_worse = options;
  EXPECT_NE(adjustment.Check().find("never_worse.guard_sigmas"),
            std::string::npos);
}

}  // namespace
}  // namespace zebrageo
