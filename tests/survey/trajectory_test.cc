#include "survey/trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "survey/input_error.h"
#include "survey/math_util.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = kPi / 180.0;
const char kHeader[] =
    "time,lat,lon,h,roll,pitch,heading,sd_e,sd_n,sd_u,sd_roll,sd_pitch,"
    "sd_heading\n";

std::string MessageOf(const std::string& text) {
  try {
    ParseTrajectorySamples(text, "trajectory.csv");
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

Trajectory TwoSampleTrajectory(double heading0_deg, double heading1_deg) {
  const std::string text =
      std::string(kHeader) + "100.0,49.8941,2.2958,60,0,0," +
      std::to_string(heading0_deg) + ",0.02,0.02,0.03,0.01,0.01,0.05\n" +
      "100.1,49.89411,2.29581,60.2,2,1," + std::to_string(heading1_deg) +
      ",0.02,0.02,0.03,0.01,0.01,0.05\n";
  const std::vector<TrajectorySample> samples =
      ParseTrajectorySamples(text, "trajectory.csv");
  return Trajectory(samples, LocalFrame(samples.front().position));
}

TEST(Trajectory, InterpolationAtSamplesReturnsTheSamples) {
  const Trajectory trajectory = TwoSampleTrajectory(10.0, 12.0);
  for (int i = 0; i < 2; ++i) {
    Pose pose;
    ASSERT_TRUE(
        trajectory.InterpolatePose(trajectory.samples()[i].time, &pose));
    EXPECT_LT((pose.p_enu - trajectory.poses()[i].p_enu).norm(), 1e-12);
    EXPECT_LT(pose.q_enu_body.angularDistance(trajectory.poses()[i].q_enu_body),
              1e-12);
  }
}

TEST(Trajectory, InterpolatesPositionLinearlyAndAttitudeBySlerp) {
  const Trajectory trajectory = TwoSampleTrajectory(10.0, 12.0);
  const Pose& a = trajectory.poses()[0];
  const Pose& b = trajectory.poses()[1];
  Pose pose;
  ASSERT_TRUE(trajectory.InterpolatePose(100.025, &pose));
  EXPECT_LT((pose.p_enu - (0.75 * a.p_enu + 0.25 * b.p_enu)).norm(), 1e-9);
  const double total = a.q_enu_body.angularDistance(b.q_enu_body);
  EXPECT_NEAR(a.q_enu_body.angularDistance(pose.q_enu_body), 0.25 * total,
              1e-9);
  EXPECT_NEAR(pose.q_enu_body.angularDistance(b.q_enu_body), 0.75 * total,
              1e-9);
}

TEST(Trajectory, HeadingIsNeverInterpolatedAsANumber) {
  // 359 deg -> 1 deg: the midpoint is north (0 deg), not south (180 deg).
  const Trajectory trajectory = TwoSampleTrajectory(359.0, 1.0);
  Pose pose;
  ASSERT_TRUE(trajectory.InterpolatePose(100.05, &pose));
  const Eigen::Vector3d forward = pose.q_enu_body * Eigen::Vector3d::UnitX();
  EXPECT_GT(forward.y(), 0.99);  // north in ENU
}

TEST(Trajectory, RefusesTimesOutsideItsSpan) {
  const Trajectory trajectory = TwoSampleTrajectory(10.0, 12.0);
  Pose pose;
  EXPECT_FALSE(trajectory.InterpolatePose(99.999, &pose));
  EXPECT_FALSE(trajectory.InterpolatePose(100.1001, &pose));
  EXPECT_TRUE(trajectory.InterpolatePose(100.1, &pose));
  EXPECT_EQ(trajectory.FindSegment(100.1), 0);
  EXPECT_EQ(trajectory.FindSegment(200.0), -1);
}

TEST(Trajectory, SampleFromPoseInvertsTheFrameChain) {
  const Trajectory trajectory = TwoSampleTrajectory(359.5, 0.5);
  const LocalFrame frame(trajectory.samples().front().position);
  for (int i = 0; i < 2; ++i) {
    const TrajectorySample& in = trajectory.samples()[i];
    const TrajectorySample out = SampleFromPose(
        in.time, trajectory.poses()[i], frame, in.sd_enu_m, in.sd_attitude_rad);
    EXPECT_NEAR(out.position.lat_deg, in.position.lat_deg, 1e-12);
    EXPECT_NEAR(out.position.lon_deg, in.position.lon_deg, 1e-12);
    EXPECT_NEAR(out.position.h_m, in.position.h_m, 1e-8);
    EXPECT_NEAR(out.attitude.roll, in.attitude.roll, 1e-12);
    EXPECT_NEAR(out.attitude.pitch, in.attitude.pitch, 1e-12);
    EXPECT_NEAR(
        std::remainder(out.attitude.heading - in.attitude.heading, 2 * kPi),
        0.0, 1e-12);
  }
}

TEST(Trajectory, WriteThenReadIsExact) {
  TemporaryFolder folder;
  const Trajectory trajectory = TwoSampleTrajectory(359.9, 0.1);
  WriteTrajectorySamples(trajectory.samples(), folder.Path("t.csv"));
  EXPECT_EQ(folder.CountEntries(), 1);
  const std::vector<TrajectorySample> back =
      ReadTrajectorySamples(folder.Path("t.csv"), "t.csv");
  ASSERT_EQ(back.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const TrajectorySample& a = trajectory.samples()[i];
    EXPECT_EQ(back[i].time, a.time);
    EXPECT_EQ(back[i].position.lat_deg, a.position.lat_deg);
    EXPECT_EQ(back[i].position.h_m, a.position.h_m);
    EXPECT_NEAR(back[i].attitude.heading, a.attitude.heading, 1e-15);
    EXPECT_NEAR(back[i].sd_attitude_rad.z(), a.sd_attitude_rad.z(), 1e-18);
  }
}

TEST(TrajectoryReader, RejectsNanWithLineAndColumn) {
  EXPECT_THAT(
      MessageOf(std::string("# c\n") + kHeader +
                "1,49,2,60,0,0,10,0,0,0,0,0,0\n"
                "2,49,2,60,0,nan,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:4: column 'pitch': \"nan\" is not finite"));
}

TEST(TrajectoryReader, RejectsNonNumbers) {
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "1,49,2,60,0,0,abc,0,0,0,0,0,0\n"
                                       "2,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:2: column 'heading': \"abc\" is not a number"));
}

TEST(TrajectoryReader, RejectsNonMonotonicAndDuplicateTimes) {
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "2,49,2,60,0,0,10,0,0,0,0,0,0\n"
                                       "1,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:3: time 1 is earlier than the previous "
                "sample's 2"));
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "2,49,2,60,0,0,10,0,0,0,0,0,0\n"
                                       "2,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:3: time 2 repeats the previous "
                "sample's time"));
}

TEST(TrajectoryReader, RejectsTruncatedFile) {
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "1,49,2,60,0,0,10,0,0,0,0,0,0\n"
                                       "2,49,2,60,0,0,10,0,0\n"),
      HasSubstr(
          "trajectory.csv:3: truncated row: 9 fields, the header has 13"));
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "1,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv: needs at least 2 samples, has 1"));
}

TEST(TrajectoryReader, RejectsOutOfRangeValues) {
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "1,91,2,60,0,0,10,0,0,0,0,0,0\n"
                                       "2,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:2: latitude 91 is outside [-90, 90]"));
  EXPECT_THAT(
      MessageOf(std::string(kHeader) + "1,49,2,60,0,0,10,-1,0,0,0,0,0\n"
                                       "2,49,2,60,0,0,10,0,0,0,0,0,0\n"),
      HasSubstr("trajectory.csv:2: a standard deviation (sd_*) is negative"));
}

TEST(TrajectoryReader, RejectsMissingColumn) {
  EXPECT_THAT(
      MessageOf("time,lat,lon,h,roll,pitch,heading\n1,49,2,60,0,0,10\n"),
      HasSubstr("trajectory.csv:1: header lacks required column 'sd_e'"));
}

}  // namespace
}  // namespace zebrageo
