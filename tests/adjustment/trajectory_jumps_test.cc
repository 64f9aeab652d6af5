#include "adjustment/trajectory_jumps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "survey/geodesy.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

const Geodetic kOrigin{49.8941, 2.2958, 60.0};
constexpr double kRateHz = 100.0;
constexpr double kSpeedMps = 10.0;
constexpr double kOutageStart = 10.0;  // s
constexpr double kOutageEnd = 16.0;    // GNSS back
constexpr double kFloorSd = 0.03;      // m, GNSS fixed

// 30 s east at 10 m/s. The INS drifts north through the outage,
// 0.05 t^2 m (1.8 m at its end), and the solution jumps back when the
// GNSS returns. With `stated_growth` the stated sd grows from 3 cm by
// 4.5 cm a second through the outage, as a GNSS/INS solution says; without
// it the sd stays at 3 cm (a solution that does not own up to the
// outage, or a multipath switch).
struct Outage {
  LocalFrame frame{kOrigin};
  std::vector<TrajectorySample> samples;

  explicit Outage(bool stated_growth) {
    for (int i = 0; i <= static_cast<int>(30.0 * kRateHz); ++i) {
      const double t = i / kRateHz;
      const bool in_outage = t >= kOutageStart && t < kOutageEnd;
      const double since = t - kOutageStart;
      const Eigen::Vector3d truth(kSpeedMps * t, 0.0, 0.0);
      TrajectorySample s;
      s.time = t;
      s.position =
          frame.GeodeticFromEnu(truth + Eigen::Vector3d(0.0, Drift(t), 0.0));
      s.attitude.heading = DegToRad(90.0);
      const double sd =
          kFloorSd + (stated_growth && in_outage ? 0.045 * since : 0.0);
      s.sd_enu_m = Eigen::Vector3d::Constant(sd);
      s.sd_attitude_rad = Eigen::Vector3d::Constant(DegToRad(0.01));
      samples.push_back(s);
    }
  }
  static double Drift(double t) {
    const bool in_outage = t >= kOutageStart && t < kOutageEnd;
    return in_outage ? 0.05 * (t - kOutageStart) * (t - kOutageStart) : 0.0;
  }
};

// Largest north error of the trajectory the prior's centre describes (the
// de-jumped INS plus the prior offset: where the correction goes without
// control) and of the input itself.
struct Errors {
  double prior_m = 0.0;
  double input_m = 0.0;
};

Errors NorthErrors(const Outage& outage, const DejumpedTrajectory& d) {
  const Trajectory trajectory(outage.samples, outage.frame);
  Errors e;
  for (int i = 0; i < trajectory.size(); ++i) {
    const double truth_north = 0.0;
    const double prior_north =
        (d.poses[i].p_enu + d.prior_position_offset[i]).y();
    e.prior_m = std::max(e.prior_m, std::abs(prior_north - truth_north));
    e.input_m = std::max(
        e.input_m, std::abs(trajectory.poses()[i].p_enu.y() - truth_north));
  }
  return e;
}

// The outage's trajectory, de-jumped with the adjustment's thresholds.
DejumpedTrajectory Dejump(const Outage& outage) {
  return RemoveJumps(Trajectory(outage.samples, outage.frame), 0.05,
                     DegToRad(0.05));
}

// The jump at the GNSS's return closes the outage: spread back over it in
// proportion to the stated variance, the prior's centre follows the drift
// (quadratic here) within 10 cm where the input was 1.8 m off, and meets the
// GNSS at both ends.
TEST(OutageClosure, AJumpIntoAGrowingStatedSdIsSpreadBackOverTheOutage) {
  const Outage outage(true);
  const DejumpedTrajectory d = Dejump(outage);
  ASSERT_EQ(d.num_jumps, 1);
  EXPECT_EQ(d.num_closed_outages, 1);
  const Errors e = NorthErrors(outage, d);
  EXPECT_GT(e.input_m, 1.7);
  EXPECT_LT(e.prior_m, 0.10);
  // The departure allowed from that spread grows to a quarter of the
  // closure's square at the jump and is zero outside the outage; the jump
  // itself adds none (the spread carries it).
  double in_outage = 0.0, elsewhere = 0.0;
  for (size_t i = 0; i < outage.samples.size(); ++i) {
    const double t = outage.samples[i].time;
    (t > kOutageStart && t < kOutageEnd ? in_outage : elsewhere) +=
        d.innovation_variance_m2[i];
  }
  EXPECT_NEAR(in_outage, 0.25 * 1.8 * 1.8, 0.05);
  EXPECT_EQ(elsewhere, 0.0);
}

// Without the stated sd's growth nothing says where the error accrued: the
// jump stays a step, as the input has it.
TEST(OutageClosure, AJumpWithoutGrowthOfTheStatedSdStaysAStep) {
  const Outage outage(false);
  const DejumpedTrajectory d = Dejump(outage);
  ASSERT_EQ(d.num_jumps, 1);
  EXPECT_EQ(d.num_closed_outages, 0);
  for (size_t i = 0; i < outage.samples.size(); ++i) {
    ASSERT_EQ(d.prior_position_offset[i], d.position_offset[i]) << i;
  }
  // The input's error steps there: its square is the innovation's.
  double total = 0.0;
  for (double v : d.innovation_variance_m2) total += v;
  EXPECT_NEAR(total, 1.8 * 1.8, 0.1);
  const Errors e = NorthErrors(outage, d);
  EXPECT_NEAR(e.prior_m, e.input_m, 1e-6);
}

}  // namespace
}  // namespace zebrageo
