// The image evidence of registration/paint_probe.h on a rendered street:
// paint, bare road, a band in a cast shadow, out of view, an occluder.
#include "registration/paint_probe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

namespace zebrageo {
namespace {

constexpr double kPitchDownRad = 30.0 * M_PI / 180.0;

// A band 0.5 m wide (east) and 3 m long (north) from (x0, 8) on flat ground.
BandCornersEnu BandAt(double x0) {
  return {Eigen::Vector3d(x0, 8.0, 0.0), Eigen::Vector3d(x0 + 0.5, 8.0, 0.0),
          Eigen::Vector3d(x0 + 0.5, 11.0, 0.0), Eigen::Vector3d(x0, 11.0, 0.0)};
}

// One camera 2.5 m above the ground looking north, 30 degrees down; the
// body pose is the identity, so T_body_cam is the camera's pose in ENU.
Eigen::Isometry3d CameraPose() {
  const Eigen::Vector3d x(1, 0, 0);
  const Eigen::Vector3d z(0, std::cos(kPitchDownRad), -std::sin(kPitchDownRad));
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << x, y, z;
  T.translation() = Eigen::Vector3d(0, 0, 2.5);
  return T;
}

class PaintProbeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("zebrageo-paint-probe-" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
    survey_.folder = folder_.string();
    const Camera camera("left", 640, 480, 500, 500, 320, 240, {0, 0, 0, 0, 0});
    survey_.rig.cameras = {{camera, CameraPose()}, {camera, CameraPose()}};
    survey_.rig.stereo_pairs = {{0, 1}};
    ExposureImage image;
    image.exposure_id = 1;
    image.camera = 0;
    image.image = "left.png";
    survey_.exposures.images = {image};
    Exposure exposure;
    exposure.exposure_id = 1;
    exposure.image_of_camera = {0, -1};
    survey_.exposures.exposures = {exposure};
    Render();
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  // Asphalt 40 (noise 2), bands painted at x0 = -2, -1, 0, 1 (grey 90), a
  // cast shadow (x 0.45) over x < -1.05, a textured occluder on x in
  // [3, 3.5], an even one on x in [3.8, 5.8]; nothing at x0 = 2.
  void Render() {
    cv::Mat image(480, 640, CV_8U, cv::Scalar(0));
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 2.0);
    std::uniform_int_distribution<int> texture(0, 255);
    const Eigen::Isometry3d T_cam_enu = CameraPose().inverse();
    const Camera& camera = survey_.rig.cameras[0].camera;
    for (double x = -4.0; x <= 6.0; x += 0.004) {
      for (double y = 5.0; y <= 14.0; y += 0.004) {
        double value = 40.0 + noise(rng);
        for (double x0 : {-2.0, -1.0, 0.0, 1.0}) {
          if (x >= x0 && x <= x0 + 0.5 && y >= 8.0 && y <= 11.0) value = 90.0;
        }
        if (x < -1.05) value *= 0.45;
        if (x >= 3.0 && x <= 3.5 && y >= 7.5 && y <= 11.5) {
          value = texture(rng);
        }
        // An even, untextured vehicle side, brighter than the asphalt.
        if (x >= 3.8 && x <= 5.8 && y >= 7.5 && y <= 11.5) value = 75.0;
        Eigen::Vector2d uv;
        if (!camera.Project(T_cam_enu * Eigen::Vector3d(x, y, 0.0), &uv)) {
          continue;
        }
        const int u = static_cast<int>(std::lround(uv.x()));
        const int v = static_cast<int>(std::lround(uv.y()));
        if (u >= 0 && v >= 0 && u < 640 && v < 480) {
          image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(value);
        }
      }
    }
    ASSERT_TRUE(cv::imwrite((folder_ / "left.png").string(), image));
  }

  // Without seen bands: the paint contrast assumed.
  PaintEvidence ClassifyAlone(const BandCornersEnu& band) {
    ImagePaintProbe probe(survey_);
    return probe.Classify(1, Pose(), band, {});
  }

  PaintEvidence Classify(const BandCornersEnu& band) {
    const std::vector<BandCornersEnu> seen = {BandAt(-1.0), BandAt(0.0),
                                              BandAt(1.0)};
    ImagePaintProbe probe(survey_);
    return probe.Classify(1, Pose(), band, seen);
  }

  std::filesystem::path folder_;
  Survey survey_;
};

TEST_F(PaintProbeTest, PaintWhereABandIsPainted) {
  EXPECT_EQ(Classify(BandAt(0.0)), PaintEvidence::kPaint);
}

TEST_F(PaintProbeTest, BareRoadWhereNothingIsPainted) {
  EXPECT_EQ(Classify(BandAt(2.0)), PaintEvidence::kBareRoad);
}

TEST_F(PaintProbeTest, PaintInACastShadowIsStillPaint) {
  // Darker than the sunlit asphalt between the seen bands, brighter than
  // the shadowed asphalt beside it.
  EXPECT_EQ(Classify(BandAt(-2.0)), PaintEvidence::kPaint);
}

TEST_F(PaintProbeTest, NoEvidenceOfAbsenceOutOfViewOrBehindAnOccluder) {
  BandCornersEnu far = BandAt(0.0);
  for (Eigen::Vector3d& corner : far) corner.y() += 100.0;
  EXPECT_EQ(Classify(far), PaintEvidence::kUnknown);
  // A textured occluder is not bare road (what it is does not matter: only
  // kBareRoad counts against a hypothesis).
  EXPECT_NE(Classify(BandAt(3.0)), PaintEvidence::kBareRoad);
}

// A database crossing nothing was matched to (gone from the street?):
// no seen band to measure the paint contrast on.
TEST_F(PaintProbeTest, WithoutSeenBandsPaintAndBareRoadAreStillTold) {
  EXPECT_EQ(ClassifyAlone(BandAt(0.0)), PaintEvidence::kPaint);
  EXPECT_EQ(ClassifyAlone(BandAt(1.0)), PaintEvidence::kPaint);
  EXPECT_EQ(ClassifyAlone(BandAt(2.0)), PaintEvidence::kBareRoad);
}

TEST_F(PaintProbeTest, WithoutSeenBandsAnEvenVehicleSideIsNotBareRoad) {
  // Even and the same beside the band: bare road by contrast alone; its
  // level is not the road's ahead of the vehicle.
  EXPECT_NE(ClassifyAlone(BandAt(4.5)), PaintEvidence::kBareRoad);
  EXPECT_NE(ClassifyAlone(BandAt(3.0)), PaintEvidence::kBareRoad);
  BandCornersEnu far = BandAt(2.0);
  for (Eigen::Vector3d& corner : far) corner.y() += 100.0;
  EXPECT_EQ(ClassifyAlone(far), PaintEvidence::kUnknown);
}

TEST_F(PaintProbeTest, MissingImageIsUnknownNotAnError) {
  std::filesystem::remove(folder_ / "left.png");
  EXPECT_EQ(Classify(BandAt(2.0)), PaintEvidence::kUnknown);
}

TEST(PaintProbeOptions, CheckRefusesInconsistentLevels) {
  EXPECT_EQ(PaintProbeOptions().Check(), "");
  PaintProbeOptions options;
  options.bare_level = 0.7;
  EXPECT_NE(options.Check(), "");
}

}  // namespace
}  // namespace zebrageo
