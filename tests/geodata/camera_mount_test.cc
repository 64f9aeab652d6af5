// The mount convention of the calibration imports (geodata/camera_mount.h):
// each angle moves the camera's axes the way the help text says, the
// simulator's nominal camera is the same rotation, angles and matrices
// round-trip, and mount files are read or refused with the line.
#include "geodata/camera_mount.h"

#include <gtest/gtest.h>

#include <random>

#include "simulator/motion.h"
#include "simulator/simulator.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

// Body-frame directions of the camera's optical axis (z), image right (x)
// and image down (y).
Eigen::Vector3d OpticalAxis(const Eigen::Matrix3d& R) { return R.col(2); }
Eigen::Vector3d ImageRight(const Eigen::Matrix3d& R) { return R.col(0); }

TEST(CameraMount, EachAngleMovesTheCameraAsDocumented) {
  const Eigen::Matrix3d level = MountRotation(0, 0, 0);
  EXPECT_TRUE(OpticalAxis(level).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(ImageRight(level).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(level.col(1).isApprox(Eigen::Vector3d::UnitZ()));  // down
  const double a = DegToRad(20.0);
  // Pitch -20: the optical axis 20 degrees below the horizon (z is down).
  EXPECT_TRUE(OpticalAxis(MountRotation(0, -a, 0))
                  .isApprox(Eigen::Vector3d(std::cos(a), 0, std::sin(a))));
  // Yaw +20: the optical axis turned to the right (y is right).
  EXPECT_TRUE(OpticalAxis(MountRotation(0, 0, a))
                  .isApprox(Eigen::Vector3d(std::cos(a), std::sin(a), 0)));
  // Roll +20: the image's right side goes down.
  EXPECT_TRUE(ImageRight(MountRotation(a, 0, 0))
                  .isApprox(Eigen::Vector3d(0, std::cos(a), std::sin(a))));
  // Order: roll first (about the level optical axis), then pitch, then yaw:
  // after pitching down, a yaw still turns the optical axis about body z.
  const Eigen::Vector3d axis = OpticalAxis(MountRotation(0.1, -a, 0.05));
  EXPECT_NEAR(std::atan2(axis.y(), axis.x()), 0.05, 1e-12);
  EXPECT_NEAR(std::asin(axis.z()), a, 1e-12);
}

TEST(CameraMount, TheSimulatorsNominalCameraIsThePitchDownShorthand) {
  SimulationOptions options;
  options.camera_pitch_down_deg = 17.0;
  options.camera_misalignment_deg = 0.0;
  const Rig rig = sim::MakeRig(options);
  ASSERT_FALSE(rig.cameras.empty());
  EXPECT_LT((rig.cameras[0].T_body_cam.linear() -
             MountRotation(0, DegToRad(-17.0), 0))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
}

TEST(CameraMount, AnglesRoundTripThroughTheMatrix) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), pitch(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d rpy(angle(rng), pitch(rng), angle(rng));
    const Eigen::Matrix3d R = MountRotation(rpy.x(), rpy.y(), rpy.z());
    EXPECT_EQ(RotationProblem(R), "");
    const Eigen::Vector3d back = MountAngles(R);
    EXPECT_LT((back - rpy).cwiseAbs().maxCoeff(), 1e-9) << rpy.transpose();
  }
  // Looking straight down: roll and yaw are one; the matrix is kept.
  const Eigen::Matrix3d down = MountRotation(0.0, -kPi / 2, 0.3);
  const Eigen::Vector3d rpy = MountAngles(down);
  EXPECT_LT(
      (MountRotation(rpy.x(), rpy.y(), rpy.z()) - down).cwiseAbs().maxCoeff(),
      1e-9);
}

TEST(CameraMount, RotationProblemsAreNamed) {
  Eigen::Matrix3d scaled = MountRotation(0, 0, 0) * 1.001;
  EXPECT_NE(RotationProblem(scaled).find("not orthonormal"), std::string::npos);
  Eigen::Matrix3d flipped = MountRotation(0, 0, 0);
  flipped.col(0) *= -1.0;
  EXPECT_NE(RotationProblem(flipped).find("reflection"), std::string::npos);
}

TEST(CameraMount, MountFilesGiveTheSameMountAsTheOptions) {
  TemporaryFolder tmp;
  const CameraMount angles = ReadCameraMountFile(
      tmp.Write("a.yaml",
                "# mount sheet\nlever_arm: [1.27, -0.5, -1.35]\n"
                "roll_deg: -0.65\npitch_down_deg: 21.33\nyaw_deg: 0.95\n"));
  EXPECT_TRUE(angles.rotation_stated);
  EXPECT_TRUE(angles.lever_arm_m.isApprox(Eigen::Vector3d(1.27, -0.5, -1.35)));
  const Eigen::Matrix3d expected =
      MountRotation(DegToRad(-0.65), DegToRad(-21.33), DegToRad(0.95));
  EXPECT_LT((angles.R_body_cam - expected).cwiseAbs().maxCoeff(), 1e-15);

  std::ostringstream matrix;
  matrix.precision(17);
  matrix << "R_body_cam: [";
  for (int i = 0; i < 9; ++i) {
    matrix << (i ? ", " : "") << expected(i / 3, i % 3);
  }
  matrix << "]\nlever_arm: [1.27, -0.5, -1.35]\n";
  const CameraMount rotation =
      ReadCameraMountFile(tmp.Write("r.yaml", matrix.str()));
  EXPECT_LT((rotation.R_body_cam - expected).cwiseAbs().maxCoeff(), 1e-15);

  std::ostringstream full;
  full.precision(17);
  full << "T_body_cam: [";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) full << expected(r, c) << ", ";
    full << angles.lever_arm_m[r] << ", ";
  }
  full << "0, 0, 0, 1]\n";
  const CameraMount transform =
      ReadCameraMountFile(tmp.Write("t.yaml", full.str()));
  EXPECT_LT((transform.T_body_cam().matrix() - angles.T_body_cam().matrix())
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
  // Only a lever arm: the level camera, and no rotation stated.
  const CameraMount arm_only =
      ReadCameraMountFile(tmp.Write("l.yaml", "lever_arm: [1, 0, -1]\n"));
  EXPECT_FALSE(arm_only.rotation_stated);
  EXPECT_TRUE(arm_only.R_body_cam.isApprox(LevelForwardCameraRotation()));
}

TEST(CameraMount, BadMountFilesNameTheLine) {
  TemporaryFolder tmp;
  struct Case {
    const char* text;
    int line;
    const char* problem;
  } cases[] = {
      {"lever_arm: [1, 0, -1]\nyaw_deg: .nan\n", 2, "yaw_deg is not finite"},
      {"lever_arm: [1, 0, -1]\nroll_deg: 1\nyaw: 2\n", 3, "unknown key 'yaw'"},
      {"lever_arm: [1500, 0, -1]\n", 1, "outside [-100, 100]"},
      {"lever_arm: [1, 0]\n", 1, "lever_arm must be a list of 3 numbers"},
      {"pitch_deg: -20\npitch_down_deg: 20\n", 2, "both given"},
      {"roll_deg: 1\nR_body_cam: [0, 0, 1, 1, 0, 0, 0, 1, 0]\n", 1, "one way"},
      {"R_body_cam: [0, 0, 1, 1, 0, 0, 0, 1, 0.5]\n", 1, "not orthonormal"},
      {"pitch_deg: 95\n", 1, "outside [-90, 90]"},
  };
  for (const Case& c : cases) {
    try {
      ReadCameraMountFile(tmp.Write("m.yaml", c.text));
      ADD_FAILURE() << "no error for " << c.text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_NE(e.problem().find(c.problem), std::string::npos) << e.what();
    }
  }
  // Not a mount file at all: named as such, and never read for ever.
  try {
    ReadCameraMountFile("/dev/zero");
    ADD_FAILURE() << "no error for /dev/zero";
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("not a camera mount file"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace zebrageo
