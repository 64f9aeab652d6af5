// The boresight check's second look (pipeline/mount_attitude_check.h) on
// plain poses: one body-frame rotation for the whole survey beyond the
// INS's stated sd is found on its axis; a drift through zero, an offset
// within the stated sd, and a rotation that changes along the survey are
// not; nor is a yaw that turns the heading towards the course over ground
// (the INS's own heading error) rather than away from it (a mount).
#include "pipeline/mount_attitude_check.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

struct Poses {
  std::vector<TrajectorySample> samples;
  std::vector<Pose> input;
  std::vector<Pose> corrected;
};

// A vehicle driving straight on for 100 m at 10 m/s, then turning through
// 90 degrees of heading, its corrected attitude the input's turned in the
// body frame by offset(i). Its positions travel along the input's heading
// turned back by input_departure_deg (the INS's own heading error), with
// jitter_m of lateral wander (a jittery trajectory), and are the same in
// the corrected poses.
template <typename Offset>
Poses Turning(const Offset& offset, double stated_heading_sd_deg = 0.02,
              double input_departure_deg = 0.0, double jitter_m = 0.0) {
  Poses poses;
  const int n = 200;
  Eigen::Vector3d along = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    TrajectorySample sample;
    sample.time = 0.1 * i;
    sample.sd_attitude_rad = Eigen::Vector3d(DegToRad(0.005), DegToRad(0.005),
                                             DegToRad(stated_heading_sd_deg));
    poses.samples.push_back(sample);
    // ENU, the body FRD (x forward, z down: a yaw about z turns the compass
    // heading on); a turn about up turns the heading back.
    const double turned = i < n / 2 ? 0.0 : M_PI / 2 * (i - n / 2) / (n / 2);
    Pose pose;
    pose.q_enu_body =
        Eigen::AngleAxisd(DegToRad(30.0) + turned, Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
        Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY());
    const Eigen::Vector3d course =
        Eigen::AngleAxisd(DegToRad(input_departure_deg),
                          Eigen::Vector3d::UnitZ()) *
        (pose.q_enu_body * Eigen::Vector3d::UnitX());
    const Eigen::Vector3d left(-course.y(), course.x(), 0.0);
    pose.p_enu = along + jitter_m * std::sin(2.3 * i) * left.normalized();
    along += 1.0 * Eigen::Vector3d(course.x(), course.y(), 0.0).normalized();
    poses.input.push_back(pose);
    const Eigen::Vector3d w = offset(i, n);
    Pose corrected = pose;
    if (w.norm() > 0.0) {
      corrected.q_enu_body =
          pose.q_enu_body * Eigen::AngleAxisd(w.norm(), w.normalized());
    }
    poses.corrected.push_back(corrected);
  }
  return poses;
}

Eigen::Vector3d Yaw(double deg) {
  return Eigen::Vector3d(0.0, 0.0, DegToRad(deg));
}

AttitudeOffset OffsetOf(const Poses& poses) {
  return MountLikeAttitudeOffset(MountAttitudeOptions(), poses.samples,
                                 poses.input, poses.corrected);
}

TEST(MountAttitudeCheck, FindsOneYawForTheSurvey) {
  // amiens-short with 0.3 degrees of unstated mount yaw: the adjustment
  // turned the body by -0.058 degrees.
  const AttitudeOffset offset = OffsetOf(Turning(
      [](int, int) { return Eigen::Vector3d(0.0, 0.0, DegToRad(-0.058)); }));
  EXPECT_TRUE(offset.found);
  EXPECT_EQ(offset.axes, Eigen::Vector3i(0, 0, 1));
  EXPECT_NEAR(RadToDeg(offset.mean_rad.z()), -0.058, 1e-6);
  EXPECT_LT(RadToDeg(offset.scatter_rad.z()), 1e-6);
  EXPECT_NEAR(RadToDeg(offset.stated_sd_rad.z()), 0.02, 1e-9);
  EXPECT_NE(offset.Describe().find("yaw -0.058 deg"), std::string::npos)
      << offset.Describe();
  EXPECT_NE(offset.Describe().find("off the course over ground 0.000 -> "
                                   "-0.058 deg"),
            std::string::npos)
      << offset.Describe();
}

TEST(MountAttitudeCheck, TellsAMountFromTheInsHeadingByTheCourse) {
  // A mount: the input's heading is on the course over ground, the
  // adjustment turns it away, also on a trajectory wandering by a degree
  // from sample to sample (2 cm of jitter every metre).
  for (const double jitter_m : {0.0, 0.02}) {
    const AttitudeOffset mount = OffsetOf(
        Turning([](int, int) { return Yaw(-0.058); }, 0.02, 0.0, jitter_m));
    EXPECT_TRUE(mount.found) << jitter_m;
    EXPECT_NEAR(RadToDeg(mount.input_course_departure_rad), 0.0, 0.005);
    EXPECT_NEAR(RadToDeg(mount.corrected_course_departure_rad), -0.058, 0.005);
    EXPECT_GE(mount.course_chords, 50);
  }
  // The simulator's demo survey: the INS's heading 0.085 degrees off the
  // course while stating 0.03, the adjustment turns it back towards it by
  // 0.075 (and, overdoing it, by 0.15): not a mount.
  for (const double yaw_deg : {-0.075, -0.15}) {
    const AttitudeOffset ins = OffsetOf(Turning(
        [yaw_deg](int, int) { return Yaw(yaw_deg); }, 0.03, 0.085, 0.02));
    EXPECT_FALSE(ins.found) << yaw_deg;
    EXPECT_NEAR(RadToDeg(ins.input_course_departure_rad), 0.085, 0.005);
    EXPECT_NEAR(RadToDeg(ins.corrected_course_departure_rad), 0.085 + yaw_deg,
                0.005);
  }
  // The INS's heading off the course, and a mount turning it further away.
  EXPECT_TRUE(
      OffsetOf(Turning([](int, int) { return Yaw(0.1); }, 0.03, 0.085)).found);
  // A standing vehicle: no course over ground, no yaw.
  Poses standing = Turning([](int, int) { return Yaw(-0.058); });
  for (Pose& pose : standing.input) pose.p_enu.setZero();
  for (Pose& pose : standing.corrected) pose.p_enu.setZero();
  const AttitudeOffset still = OffsetOf(standing);
  EXPECT_FALSE(still.found);
  EXPECT_EQ(still.course_chords, 0);
}

TEST(MountAttitudeCheck, FindsRollBeyondItsOwnStatedSd) {
  const AttitudeOffset offset = OffsetOf(Turning([](int, int) {
    return Eigen::Vector3d(DegToRad(0.015), 0.0, DegToRad(0.015));
  }));
  // Roll 0.015 is 3 of the INS's 0.005; yaw 0.015 is within its 0.02.
  EXPECT_EQ(offset.axes, Eigen::Vector3i(1, 0, 0));
}

TEST(MountAttitudeCheck, KeepsWhatTheInsStatesOrWhatDrifts) {
  // Within the stated sd.
  EXPECT_FALSE(OffsetOf(Turning([](int, int) {
                 return Eigen::Vector3d(0.0, 0.0, DegToRad(0.018));
               })).found);
  // The same yaw with an INS that states 0.08 degrees.
  EXPECT_FALSE(OffsetOf(Turning(
                            [](int, int) {
                              return Eigen::Vector3d(0.0, 0.0,
                                                     DegToRad(-0.058));
                            },
                            0.08))
                   .found);
  // A drift from -0.1 to 0.1 degrees: an INS's, not a mount's.
  EXPECT_FALSE(OffsetOf(Turning([](int i, int n) {
                 return Eigen::Vector3d(0.0, 0.0,
                                        DegToRad(-0.1 + 0.2 * i / (n - 1)));
               })).found);
  // A drift from 0.05 to 0.15 degrees: its mean is 0.1, its scatter 0.029,
  // within half of it: the constant part is found.
  EXPECT_TRUE(OffsetOf(Turning([](int i, int n) {
                return Eigen::Vector3d(0.0, 0.0,
                                       DegToRad(0.05 + 0.1 * i / (n - 1)));
              })).found);
  // Nothing changed.
  EXPECT_FALSE(OffsetOf(Turning([](int, int) {
                 return Eigen::Vector3d::Zero();
               })).found);
}

TEST(MountAttitudeCheck, MismatchedPosesFindNothing) {
  Poses poses = Turning(
      [](int, int) { return Eigen::Vector3d(0.0, 0.0, DegToRad(-0.1)); });
  poses.corrected.pop_back();
  EXPECT_FALSE(MountLikeAttitudeOffset(MountAttitudeOptions(), poses.samples,
                                       poses.input, poses.corrected)
                   .found);
}

TEST(MountAttitudeCheck, OptionErrorsNameTheField) {
  MountAttitudeOptions options;
  EXPECT_EQ(options.Check(), "");
  options.min_stated_sds = 0.0;
  EXPECT_EQ(options.Check().rfind("min_stated_sds = 0: must be > 0", 0), 0u)
      << options.Check();
  options = MountAttitudeOptions();
  options.boresight_sigma_rad = std::nan("");
  EXPECT_EQ(options.Check().rfind("boresight_sigma_rad", 0), 0u);
  EXPECT_THROW(MountLikeAttitudeOffset(options, {}, {}, {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace zebrageo
