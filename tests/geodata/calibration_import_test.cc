// Kalibr and ROS calibrations of one known rig give the rig the OpenCV
// import gives (written by OpenCV's own FileStorage; the ROS files from
// cv::stereoRectify, as ROS's camera_calibration makes them).
#include "geodata/calibration_import.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <sstream>

#include "survey/input_error.h"
#include "survey/math_util.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

struct KnownRig {
  int width = 1280, height = 960;
  cv::Matx33d K1{1105.2, 0, 641.7, 0, 1103.9, 478.2, 0, 0, 1};
  cv::Matx33d K2{1098.6, 0, 633.1, 0, 1099.8, 485.9, 0, 0, 1};
  cv::Vec<double, 5> D1{-0.112, 0.087, 0.0011, -0.0007, -0.021};
  cv::Vec<double, 5> D2{-0.105, 0.079, -0.0004, 0.0009, -0.017};
  cv::Matx33d R;
  cv::Vec3d T{-0.8123, 0.0071, -0.0042};  // p_right = R p_left + T, metres
  KnownRig() { cv::Rodrigues(cv::Vec3d(0.004, -0.012, 0.0021), R); }
};

Eigen::Isometry3d Mount() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -0.2588190451, 0.9659258263, 1, 0, 0, 0, 0.9659258263,
      0.2588190451;
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.2, -0.4, -1.9);
  return T;
}

std::string Row(const double* values, int n) {
  std::ostringstream out;
  out.precision(17);
  out << "[";
  for (int i = 0; i < n; ++i) out << (i ? ", " : "") << values[i];
  out << "]";
  return out.str();
}

std::string OpenCvFile(const TemporaryFolder& tmp, const KnownRig& rig) {
  const std::string path = tmp.Path("stereo.yaml");
  cv::FileStorage fs(path, cv::FileStorage::WRITE);
  fs << "image_width" << rig.width << "image_height" << rig.height;
  fs << "K1" << cv::Mat(rig.K1) << "D1" << cv::Mat(rig.D1) << "K2"
     << cv::Mat(rig.K2) << "D2" << cv::Mat(rig.D2) << "R" << cv::Mat(rig.R)
     << "T" << cv::Mat(rig.T);
  fs.release();
  return path;
}

// Kalibr camchain.yaml: intrinsics [fu, fv, pu, pv], radtan [k1, k2, r1, r2]
// (Kalibr's radtan has no k3), T_cn_cnm1 nested 4x4 rows.
std::string KalibrRadtanText(const KnownRig& rig) {
  auto camera = [&](const cv::Matx33d& K, const cv::Vec<double, 5>& D) {
    const double intrinsics[] = {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
    const double d[] = {D[0], D[1], D[2], D[3]};
    return "  camera_model: pinhole\n  intrinsics: " + Row(intrinsics, 4) +
           "\n  distortion_model: radtan\n  distortion_coeffs: " + Row(d, 4) +
           "\n  resolution: [" + std::to_string(rig.width) + ", " +
           std::to_string(rig.height) + "]\n";
  };
  std::ostringstream text;
  text << "cam0:\n  cam_overlaps: [1]\n"
       << camera(rig.K1, rig.D1)
       << "  rostopic: /cam0/image_raw\ncam1:\n  T_cn_cnm1:\n";
  for (int r = 0; r < 3; ++r) {
    const double row[] = {rig.R(r, 0), rig.R(r, 1), rig.R(r, 2), rig.T[r]};
    text << "  - " << Row(row, 4) << "\n";
  }
  text << "  - [0.0, 0.0, 0.0, 1.0]\n  cam_overlaps: [0]\n"
       << camera(rig.K2, rig.D2) << "  rostopic: /cam1/image_raw\n";
  return text.str();
}

std::string RosMatrix(const std::string& name, const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return name + ":\n  rows: " + std::to_string(d.rows) +
         "\n  cols: " + std::to_string(d.cols) +
         "\n  data: " + Row(d.ptr<double>(), static_cast<int>(d.total())) +
         "\n";
}

std::string RosCameraInfo(const KnownRig& rig, const std::string& name,
                          const cv::Matx33d& K, const cv::Vec<double, 5>& D,
                          const cv::Mat& R, const cv::Mat& P) {
  return "image_width: " + std::to_string(rig.width) +
         "\nimage_height: " + std::to_string(rig.height) +
         "\ncamera_name: " + name + "\n" +
         RosMatrix("camera_matrix", cv::Mat(K)) +
         "distortion_model: plumb_bob\n" +
         RosMatrix("distortion_coefficients", cv::Mat(D).reshape(1, 1)) +
         RosMatrix("rectification_matrix", R) +
         RosMatrix("projection_matrix", P);
}

void ExpectSameRig(const Rig& expected, const Rig& actual, double tolerance) {
  ASSERT_EQ(expected.cameras.size(), actual.cameras.size());
  ASSERT_EQ(expected.stereo_pairs, actual.stereo_pairs);
  for (size_t i = 0; i < expected.cameras.size(); ++i) {
    const RigCamera& e = expected.cameras[i];
    const RigCamera& a = actual.cameras[i];
    EXPECT_EQ(e.camera.name(), a.camera.name());
    EXPECT_EQ(e.camera.width(), a.camera.width());
    EXPECT_EQ(e.camera.height(), a.camera.height());
    for (int k = 0; k < kNumIntrinsics; ++k) {
      EXPECT_NEAR(e.camera.intrinsics()[k], a.camera.intrinsics()[k], 1e-12);
    }
    EXPECT_LT(
        (e.T_body_cam.matrix() - a.T_body_cam.matrix()).cwiseAbs().maxCoeff(),
        tolerance)
        << "camera " << i << "\n"
        << e.T_body_cam.matrix() << "\n"
        << a.T_body_cam.matrix();
  }
}

TEST(CalibrationImport, KalibrAndRosGiveTheOpenCvImportsRig) {
  TemporaryFolder tmp;
  const KnownRig known;
  const Rig opencv = ImportOpenCvStereo(OpenCvFile(tmp, known), 0, 0, Mount());
  ASSERT_EQ(opencv.cameras.size(), 2u);

  const Rig kalibr = ImportKalibrCamchain(
      tmp.Write("camchain.yaml", KalibrRadtanText(known)), Mount(), {});
  // Kalibr's radtan has no k3: the known rig's k3 is compared separately.
  Rig opencv_without_k3 = opencv;
  for (RigCamera& c : opencv_without_k3.cameras) {
    std::array<double, 5> d = c.camera.distortion();
    d[4] = 0.0;
    c.camera =
        Camera(c.camera.name(), c.camera.width(), c.camera.height(),
               c.camera.fx(), c.camera.fy(), c.camera.cx(), c.camera.cy(), d);
  }
  ExpectSameRig(opencv_without_k3, kalibr, 1e-12);

  cv::Mat R1, R2, P1, P2, Q;
  cv::stereoRectify(known.K1, known.D1, known.K2, known.D2,
                    cv::Size(known.width, known.height), known.R, known.T, R1,
                    R2, P1, P2, Q);
  const std::string left = tmp.Write(
      "left.yaml", RosCameraInfo(known, "left", known.K1, known.D1, R1, P1));
  const std::string right = tmp.Write(
      "right.yaml", RosCameraInfo(known, "right", known.K2, known.D2, R2, P2));
  const Rig ros = ImportRosCameraInfoPair(left, right, Mount(), {});
  // Through the rectification: R1, R2 are orthonormal to ~1e-15.
  ExpectSameRig(opencv, ros, 1e-9);
}

// An equidistant lens of moderate field (Kalibr's model for any lens):
// the fitted OpenCV model projects like cv::fisheye::projectPoints over the
// whole image. (With fx = 900 px, 51 degrees to the corner, the best fit
// departs by 1.6 px: refused, as the next test shows for a fisheye.)
TEST(CalibrationImport, EquidistantKalibrCameraProjectsLikeOpenCvFisheye) {
  TemporaryFolder tmp;
  const double fx = 1500.0, fy = 1499.0, cx = 640.3, cy = 480.9;
  const cv::Vec4d k(-0.021, 0.0113, -0.0062, 0.0011);
  std::ostringstream text;
  text << "cam0:\n  camera_model: pinhole\n  intrinsics: [" << fx << ", " << fy
       << ", " << cx << ", " << cy << "]\n  distortion_model: equidistant\n"
       << "  distortion_coeffs: [" << k[0] << ", " << k[1] << ", " << k[2]
       << ", " << k[3] << "]\n  resolution: [1280, 960]\n";
  // A stereo camchain: cam1 the same lens 0.8 m to the right.
  std::string cam1 = text.str().substr(5);
  text << "cam1:\n  T_cn_cnm1:\n  - [1, 0, 0, -0.8]\n  - [0, 1, 0, 0]\n"
       << "  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n"
       << cam1;
  const Rig rig = ImportKalibrCamchain(tmp.Write("camchain.yaml", text.str()),
                                       Eigen::Isometry3d::Identity(), {});
  ASSERT_EQ(rig.cameras.size(), 2u);
  const Camera& camera = rig.cameras[0].camera;
  std::vector<cv::Point3d> rays;
  for (double x = -0.45; x <= 0.45; x += 0.02) {
    for (double y = -0.34; y <= 0.34; y += 0.02) rays.emplace_back(x, y, 1.0);
  }
  std::vector<cv::Point2d> expected;
  const cv::Matx33d K(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  cv::fisheye::projectPoints(rays, expected, cv::Vec3d(0, 0, 0),
                             cv::Vec3d(0, 0, 0), K, k);
  double max_error_px = 0.0;
  int inside = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector2d uv_expected(expected[i].x, expected[i].y);
    if (!camera.IsInImage(uv_expected)) continue;
    ++inside;
    Eigen::Vector2d uv;
    ASSERT_TRUE(
        camera.Project(Eigen::Vector3d(rays[i].x, rays[i].y, rays[i].z), &uv));
    max_error_px = std::max(max_error_px, (uv - uv_expected).norm());
  }
  EXPECT_GT(inside, 300);
  EXPECT_LT(max_error_px, 0.05);
}

TEST(CalibrationImport, WideFisheyeIsRefusedWithTheFitError) {
  TemporaryFolder tmp;
  const std::string path = tmp.Write(
      "camchain.yaml",
      "cam0:\n  camera_model: pinhole\n  intrinsics: [300, 300, 640, 480]\n"
      "  distortion_model: equidistant\n"
      "  distortion_coeffs: [0.02, -0.01, 0.003, -0.0005]\n"
      "  resolution: [1280, 960]\n");
  try {
    ImportKalibrCamchain(path, Eigen::Isometry3d::Identity(), {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 5);
    EXPECT_NE(e.problem().find("equidistant"), std::string::npos) << e.what();
  }
}

TEST(CalibrationImport, BadFilesNameTheLine) {
  TemporaryFolder tmp;
  const std::string path = tmp.Write(
      "camchain.yaml",
      "cam0:\n  camera_model: pinhole\n  intrinsics: [300, 300, 640]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n"
      "  resolution: [1280, 960]\n");
  try {
    ImportKalibrCamchain(path, Eigen::Isometry3d::Identity(), {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(e.problem().find("'intrinsics' must have 4"), std::string::npos)
        << e.what();
  }
  // A Kalibr file given as ROS camera_info: missing keys are InputErrors
  // (yaml-cpp throws its own exception when asked where an absent key is;
  // found by fuzz_calibration).
  EXPECT_THROW(
      ImportRosCameraInfoPair(path, path, Eigen::Isometry3d::Identity(), {}),
      InputError);
  // A resolution no int holds is refused, not cast.
  const std::string huge = tmp.Write(
      "huge.yaml",
      "cam0:\n  camera_model: pinhole\n  intrinsics: [300, 300, 640, 480]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [0, 0, 0, 0]\n"
      "  resolution: [1e300, 960]\n");
  try {
    ImportKalibrCamchain(huge, Eigen::Isometry3d::Identity(), {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 6);
    EXPECT_NE(e.problem().find("resolution"), std::string::npos) << e.what();
  }
  const std::string ros =
      tmp.Write("left.yaml",
                "image_width: 640\nimage_height: 480\n"
                "camera_matrix: {rows: 3, cols: 3, data: [1, 0, 2]}\n");
  EXPECT_THROW(
      ImportRosCameraInfoPair(ros, ros, Eigen::Isometry3d::Identity(), {}),
      InputError);
}

}  // namespace
}  // namespace zebrageo
