// The import commands on the real binary: what a user runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>

#include "survey/rig.h"
#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr char kMount[] = "--lever-arm 1.5 0.4 -1.8 --pitch-down-deg 14";

std::string Row(const double* values, int n) {
  std::ostringstream out;
  out.precision(17);
  out << "[";
  for (int i = 0; i < n; ++i) out << (i ? ", " : "") << values[i];
  out << "]";
  return out.str();
}

// The same rig as an OpenCV stereoCalibrate file and a Kalibr camchain
// (k3 = 0: Kalibr's radtan has four coefficients).
TEST(ImportCommands, KalibrAndOpenCvGiveTheSameRigYaml) {
  TemporaryFolder tmp;
  const cv::Matx33d K1(1105.2, 0, 641.7, 0, 1103.9, 478.2, 0, 0, 1);
  const cv::Matx33d K2(1098.6, 0, 633.1, 0, 1099.8, 485.9, 0, 0, 1);
  const cv::Vec<double, 5> D1(-0.112, 0.087, 0.0011, -0.0007, 0.0);
  const cv::Vec<double, 5> D2(-0.105, 0.079, -0.0004, 0.0009, 0.0);
  cv::Matx33d R;
  cv::Rodrigues(cv::Vec3d(0.004, -0.012, 0.0021), R);
  const cv::Vec3d T(-0.8123, 0.0071, -0.0042);
  {
    cv::FileStorage fs(tmp.Path("stereo.yaml"), cv::FileStorage::WRITE);
    fs << "image_width" << 1280 << "image_height" << 960 << "K1" << cv::Mat(K1)
       << "D1" << cv::Mat(D1) << "K2" << cv::Mat(K2) << "D2" << cv::Mat(D2)
       << "R" << cv::Mat(R) << "T" << cv::Mat(T);
  }
  auto camera = [](const cv::Matx33d& K, const cv::Vec<double, 5>& D) {
    const double intrinsics[] = {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
    const double d[] = {D[0], D[1], D[2], D[3]};
    return "  camera_model: pinhole\n  intrinsics: " + Row(intrinsics, 4) +
           "\n  distortion_model: radtan\n  distortion_coeffs: " + Row(d, 4) +
           "\n  resolution: [1280, 960]\n";
  };
  std::ostringstream kalibr;
  kalibr << "cam0:\n" << camera(K1, D1) << "cam1:\n  T_cn_cnm1:\n";
  for (int r = 0; r < 3; ++r) {
    const double row[] = {R(r, 0), R(r, 1), R(r, 2), T[r]};
    kalibr << "  - " << Row(row, 4) << "\n";
  }
  kalibr << "  - [0.0, 0.0, 0.0, 1.0]\n" << camera(K2, D2);
  tmp.Write("camchain.yaml", kalibr.str());

  ASSERT_EQ(RunZebrageo("import-opencv-stereo " +
                            Quote(tmp.Path("stereo.yaml")) + " " + kMount +
                            " -o " + Quote(tmp.Path("rig_opencv.yaml")),
                        tmp.Path("out"), tmp.Path("err")),
            0)
      << ReadWholeFile(tmp.Path("err"));
  ASSERT_EQ(
      RunZebrageo("import-kalibr " + Quote(tmp.Path("camchain.yaml")) + " " +
                      kMount + " -o " + Quote(tmp.Path("rig_kalibr.yaml")),
                  tmp.Path("out"), tmp.Path("err")),
      0)
      << ReadWholeFile(tmp.Path("err"));
  const Rig opencv = ReadRig(tmp.Path("rig_opencv.yaml"), "rig_opencv.yaml");
  const Rig kalibr_rig =
      ReadRig(tmp.Path("rig_kalibr.yaml"), "rig_kalibr.yaml");
  ASSERT_EQ(opencv.cameras.size(), kalibr_rig.cameras.size());
  EXPECT_EQ(opencv.stereo_pairs, kalibr_rig.stereo_pairs);
  for (size_t c = 0; c < opencv.cameras.size(); ++c) {
    EXPECT_EQ(opencv.cameras[c].camera.name(),
              kalibr_rig.cameras[c].camera.name());
    for (int k = 0; k < kNumIntrinsics; ++k) {
      EXPECT_NEAR(opencv.cameras[c].camera.intrinsics()[k],
                  kalibr_rig.cameras[c].camera.intrinsics()[k], 1e-12);
    }
    EXPECT_LT((opencv.cameras[c].T_body_cam.matrix() -
               kalibr_rig.cameras[c].T_body_cam.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
  }
}

TEST(ImportCommands, TruncatedSbetExitsOneNamingTheRecordAndWritesNothing) {
  TemporaryFolder tmp;
  tmp.Write("sbet.out", std::string(136 * 3 + 40, '\0'));
  const int status =
      RunZebrageo("import-trajectory " + Quote(tmp.Path("sbet.out")) +
                      " --format sbet -o " + Quote(tmp.Path("trajectory.csv")),
                  tmp.Path("out"), tmp.Path("err"));
  EXPECT_EQ(status, 1);
  EXPECT_NE(ReadWholeFile(tmp.Path("err")).find("record 4 is truncated"),
            std::string::npos)
      << ReadWholeFile(tmp.Path("err"));
  EXPECT_FALSE(fs::exists(tmp.Path("trajectory.csv")));
}

TEST(ImportCommands, CsvTrajectoryThroughTheCommandLine) {
  TemporaryFolder tmp;
  tmp.Write("ins.txt",
            "Time;Lat;Lon;HEll;Roll;Pitch;Yaw\n"
            "345600.00;49.8941;2.2958;60.0;0.5;-1.0;359.9\n"
            "345600.01;49.89410001;2.29580002;60.001;0.5;-1.0;0.1\n");
  ASSERT_EQ(RunZebrageo("import-trajectory " + Quote(tmp.Path("ins.txt")) +
                            " --format csv --delimiter semicolon --columns "
                            "time=Time,lat=Lat,lon=Lon,h=HEll,roll=Roll,"
                            "pitch=Pitch,heading=Yaw -o " +
                            Quote(tmp.Path("trajectory.csv")),
                        tmp.Path("out"), tmp.Path("err")),
            0)
      << ReadWholeFile(tmp.Path("err"));
  const std::string text = ReadWholeFile(tmp.Path("trajectory.csv"));
  EXPECT_EQ(text.rfind("time,lat,lon,h,roll,pitch,heading,sd_e", 0), 0u)
      << text;
  EXPECT_NE(text.find("\n345600.01,49.89410001,2.29580002,60.001,"),
            std::string::npos)
      << text;
  // A usage error in the column map: exit 2.
  EXPECT_EQ(RunZebrageo("import-trajectory " + Quote(tmp.Path("ins.txt")) +
                            " --format csv --columns yaw=Yaw -o " +
                            Quote(tmp.Path("t2.csv")),
                        tmp.Path("out"), tmp.Path("err")),
            2);
}

}  // namespace
}  // namespace zebrageo
