// The boresight check's second look (pipeline/mount_attitude_check.h) on
// plain poses: one body-frame rotation for the whole survey beyond the
// INS's stated sd is found on its axis; a drift through zero, an offset
// within the stated sd, and a rotation that changes along the survey are
// not.
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

// A vehicle turning through 90 degrees of heading, its corrected attitude
// the input's turned in the body frame by offset(i).
template <typename Offset>
Poses Turning(const Offset& offset, double stated_heading_sd_deg = 0.02) {
  Poses poses;
  const int n = 200;
  for (int i = 0; i < n; ++i) {
    TrajectorySample sample;
    sample.time = 0.1 * i;
    sample.sd_attitude_rad = Eigen::Vector3d(DegToRad(0.005), DegToRad(0.005),
                                             DegToRad(stated_heading_sd_deg));
    poses.samples.push_back(sample);
    Pose pose;
    pose.q_enu_body =
        Eigen::AngleAxisd(M_PI / 2 * i / n, Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY());
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
