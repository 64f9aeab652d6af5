#include "survey/rig.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "survey/input_error.h"
#include "tests/survey/damaged_input.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// Camera looking forward (body x) with image x to the right (body y) and
// image y down (body z): R_body_cam maps cam z -> body x, cam x -> body y,
// cam y -> body z.
const char kForward[] =
    "0, 0, 1, 1.5,  1, 0, 0, -0.3,  0, 1, 0, -1.2,  0, 0, 0, 1";

std::string RigText(const std::string& left_t = kForward,
                    const std::string& pairs = "  - [left, right]\n") {
  return "cameras:\n"
         "  - name: left\n"
         "    width: 1920\n"
         "    height: 1080\n"
         "    K: [1400.5, 0, 960.25, 0, 1401.5, 540.75, 0, 0, 1]\n"
         "    D: [-0.1, 0.01, 0.0001, -0.0002, 0.001]\n"
         "    T_body_cam: [" +
         left_t +
         "]\n"
         "  - name: right\n"
         "    width: 1920\n"
         "    height: 1080\n"
         "    K: [1400, 0, 960, 0, 1400, 540, 0, 0, 1]\n"
         "    D: [0, 0, 0, 0, 0]\n"
         "    T_body_cam: [0, 0, 1, 1.5,  1, 0, 0, 0.3,  0, 1, 0, -1.2,  0, 0, "
         "0, 1]\n"
         "stereo_pairs:\n" +
         pairs;
}

// `text` with its first `from` replaced by `to`.
std::string Replaced(std::string text, const std::string& from,
                     const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string ErrorOfParse(const std::string& text) {
  try {
    ParseRig(text, "rig.yaml");
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

Rig SampleRig() {
  Rig rig;
  RigCamera left;
  left.camera = Camera("left", 2048, 1536, 1234.5678901234567, 1234.1 / 3.0,
                       1023.5, 767.25, {-0.12, 0.034, 1e-4, -2e-5, 0.0017});
  left.T_body_cam.linear() =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()) *
       Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  left.T_body_cam.translation() = Eigen::Vector3d(1.25, -0.31, -1.9 / 7.0);
  RigCamera right = left;
  // Needs quoting in YAML: the writer must not rely on plain scalars.
  right.camera = Camera("right: #2", 2048, 1536, 1230.0, 1231.0, 1020.0, 770.0,
                        {0.1, 0.0, 0.0, 0.0, 0.0});
  right.T_body_cam.translation().y() = 0.29;
  rig.cameras = {left, right};
  rig.stereo_pairs = {{0, 1}};
  return rig;
}

TEST(Rig, ParsesTheFormatExample) {
  const Rig rig = ParseRig(RigText(), "rig.yaml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  const Camera& left = rig.cameras[0].camera;
  EXPECT_EQ(left.name(), "left");
  EXPECT_EQ(left.width(), 1920);
  EXPECT_EQ(left.height(), 1080);
  EXPECT_EQ(left.fx(), 1400.5);
  EXPECT_EQ(left.fy(), 1401.5);
  EXPECT_EQ(left.cx(), 960.25);
  EXPECT_EQ(left.cy(), 540.75);
  EXPECT_EQ(left.distortion()[0], -0.1);
  EXPECT_EQ(left.distortion()[4], 0.001);
  // The optical axis (camera z) is the vehicle's forward axis (body x).
  EXPECT_TRUE((rig.cameras[0].T_body_cam.linear() * Eigen::Vector3d::UnitZ())
                  .isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_EQ(rig.cameras[0].T_body_cam.translation(),
            Eigen::Vector3d(1.5, -0.3, -1.2));
  ASSERT_EQ(rig.stereo_pairs.size(), 1u);
  EXPECT_EQ(rig.stereo_pairs[0][0], 0);
  EXPECT_EQ(rig.stereo_pairs[0][1], 1);
  EXPECT_EQ(rig.FindCamera("right"), 1);
  EXPECT_EQ(rig.FindCamera("centre"), -1);
}

TEST(Rig, WriteThenReadIsExact) {
  TemporaryFolder folder;
  const Rig rig = SampleRig();
  WriteRig(rig, folder.Path("rig.yaml"));
  const Rig read = ReadRig(folder.Path("rig.yaml"), "rig.yaml");
  ASSERT_EQ(read.cameras.size(), rig.cameras.size());
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const Camera& a = rig.cameras[i].camera;
    const Camera& b = read.cameras[i].camera;
    EXPECT_EQ(a.name(), b.name());
    EXPECT_EQ(a.width(), b.width());
    EXPECT_EQ(a.height(), b.height());
    for (int k = 0; k < kNumIntrinsics; ++k) {
      EXPECT_EQ(a.intrinsics()[k], b.intrinsics()[k]) << k;
    }
    EXPECT_EQ(rig.cameras[i].T_body_cam.matrix(),
              read.cameras[i].T_body_cam.matrix());
  }
  EXPECT_EQ(read.stereo_pairs, rig.stereo_pairs);
  // Only rig.yaml: no temporary file left behind.
  EXPECT_EQ(folder.CountEntries(), 1);
}

TEST(Rig, WriteToAMissingFolderThrowsAndLeavesNothing) {
  TemporaryFolder folder;
  EXPECT_ANY_THROW(WriteRig(SampleRig(), folder.Path("missing/rig.yaml")));
  EXPECT_EQ(folder.CountEntries(), 0);
}

TEST(Rig, RejectsMalformedYamlWithItsLine) {
  EXPECT_THAT(ErrorOfParse("cameras:\n  - name: left\n    K: [1, 2\n"),
              HasSubstr("rig.yaml:"));
  EXPECT_THAT(ErrorOfParse("cameras:\n  - name: left\n    K: [1, 2\n"),
              HasSubstr("malformed YAML"));
  EXPECT_THAT(ErrorOfParse("cameras: [\n"), HasSubstr("malformed YAML"));
}

TEST(Rig, RejectsNonOrthonormalRotationOnItsLine) {
  const std::string text =
      RigText("0, 0, 1.01, 1.5,  1, 0, 0, -0.3,  0, 1, 0, -1.2,  0, 0, 0, 1");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:7: camera 'left' T_body_cam: rotation is "
                        "not orthonormal"));
}

TEST(Rig, RejectsAReflection) {
  const std::string text =
      RigText("0, 0, 1, 1.5,  1, 0, 0, -0.3,  0, -1, 0, -1.2,  0, 0, 0, 1");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:7: camera 'left' T_body_cam: rotation has "
                        "determinant -1"));
}

TEST(Rig, RejectsALastRowOtherThan0001) {
  const std::string text =
      RigText("0, 0, 1, 1.5,  1, 0, 0, -0.3,  0, 1, 0, -1.2,  0, 0, 1, 1");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:7: camera 'left' T_body_cam: last row must "
                        "be 0 0 0 1"));
}

TEST(Rig, RejectsAT_body_camOfWrongSize) {
  EXPECT_THAT(ErrorOfParse(RigText("0, 0, 1, 1.5")),
              HasSubstr("rig.yaml:7: camera 'left' T_body_cam must be a list "
                        "of exactly 16 numbers (it has 4)"));
}

TEST(Rig, RejectsUnknownCameraInStereoPair) {
  EXPECT_THAT(ErrorOfParse(RigText(kForward, "  - [left, centre]\n")),
              HasSubstr("rig.yaml:15: stereo pair names unknown camera "
                        "'centre' (cameras: left, right)"));
}

TEST(Rig, RejectsAStereoPairOfOneCamera) {
  EXPECT_THAT(ErrorOfParse(RigText(kForward, "  - [left, left]\n")),
              HasSubstr("rig.yaml:15: stereo pair uses camera 'left' twice"));
  EXPECT_THAT(ErrorOfParse(RigText(kForward, "  - [left]\n")),
              HasSubstr("rig.yaml:15: a stereo pair must be a list of two"));
}

TEST(Rig, RejectsDuplicateCameraNames) {
  std::string text = RigText();
  text = Replaced(text, "name: right", "name: left");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:8: duplicate camera name 'left'"));
}

TEST(Rig, RejectsSkewAndBadIntrinsics) {
  std::string skew = RigText();
  skew = Replaced(skew, "[1400.5, 0,", "[1400.5, 2,");
  EXPECT_THAT(ErrorOfParse(skew),
              HasSubstr("rig.yaml:5: camera 'left' K must be [fx, 0, cx, 0, "
                        "fy, cy, 0, 0, 1]"));
  std::string negative = RigText();
  negative = Replaced(negative, "1400.5", "-1400");
  EXPECT_THAT(ErrorOfParse(negative),
              HasSubstr("rig.yaml:5: camera 'left' K: fx and fy must be > 0"));
  std::string nan = RigText();
  nan = Replaced(nan, "960.25", ".nan");
  EXPECT_THAT(ErrorOfParse(nan),
              HasSubstr("rig.yaml:5: camera 'left' K[2] is not finite"));
  std::string text = RigText();
  text = Replaced(text, "960.25", "abc");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:5: camera 'left' K[2] is not a number"));
}

TEST(Rig, RejectsDistortionOtherThanFiveNumbers) {
  std::string text = RigText();
  text = Replaced(text, "[-0.1, 0.01, 0.0001, -0.0002, 0.001]",
                  "[-0.1, 0.01, 0.0001, -0.0002]");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:6: camera 'left' D must be a list of exactly "
                        "5 numbers (it has 4)"));
}

TEST(Rig, RejectsBadImageSize) {
  std::string text = RigText();
  text = Replaced(text, "width: 1920", "width: -5");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:3: camera 'left' width = -5: must be > 0"));
  text = RigText();
  text = Replaced(text, "height: 1080", "height: 10.5");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:4: camera 'left' height '10.5' is not an "
                        "integer"));
}

TEST(Rig, RejectsMissingKeysAndEmptyRigs) {
  std::string text = RigText();
  text = Replaced(text, "    D: [0, 0, 0, 0, 0]\n", "");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:8: camera 'right': missing key 'D'"));
  EXPECT_THAT(ErrorOfParse("stereo_pairs: []\n"),
              HasSubstr("rig.yaml:1: missing key 'cameras'"));
  EXPECT_THAT(ErrorOfParse("cameras: []\n"),
              HasSubstr("rig.yaml:1: 'cameras' must be a non-empty list"));
  EXPECT_THAT(ErrorOfParse("- 1\n- 2\n"),
              HasSubstr("rig.yaml:1: expected a mapping"));
}

TEST(Rig, ReadOfAMissingFileNamesIt) {
  TemporaryFolder folder;
  try {
    ReadRig(folder.Path("rig.yaml"), "rig.yaml");
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("rig.yaml: cannot open"));
  }
}

TEST(Rig, SuggestsTheImporterForOpenCvMatrices) {
  const std::string text = Replaced(
      RigText(), "K: [1400.5, 0, 960.25, 0, 1401.5, 540.75, 0, 0, 1]",
      "K: !!opencv-matrix {rows: 3, cols: 3, dt: d, data: [1, 0, 0, 0, 1, 0, "
      "0, 0, 1]}");
  EXPECT_THAT(ErrorOfParse(text),
              HasSubstr("rig.yaml:5: camera 'left' K must be a list of exactly "
                        "9 numbers (an OpenCV matrix?"));
}

// Files are untrusted: whatever the damage, the reader throws InputError
// naming rig.yaml, the line and the problem (never a yaml-cpp exception,
// never a crash), or reads a rig that holds together: named cameras with a
// positive size, stereo pairs of two distinct cameras of the rig.
TEST(Rig, TruncatedOrCorruptedFilesAreRefusedByLineOrReadSoundly) {
  const std::string text = RigText();
  const DamageCounts counts = ParseDamagedCopies(
      text, "rig.yaml", {'\0', '[', ':', '-', '\xff'},
      [](const std::string& damaged) {
        const Rig rig = ParseRig(damaged, "rig.yaml");
        EXPECT_GE(rig.cameras.size(), 1u);
        EXPECT_LE(rig.cameras.size(), 2u);
        for (const RigCamera& camera : rig.cameras) {
          EXPECT_FALSE(camera.camera.name().empty());
          EXPECT_EQ(rig.FindCamera(camera.camera.name()),
                    &camera - rig.cameras.data());
        }
        for (const std::array<int, 2>& pair : rig.stereo_pairs) {
          EXPECT_NE(pair[0], pair[1]);
          for (int camera : pair) {
            EXPECT_GE(camera, 0);
            EXPECT_LT(camera, static_cast<int>(rig.cameras.size()));
          }
        }
      });
  EXPECT_GT(counts.refused, 0);
  EXPECT_GT(counts.parsed, 0);
  // Cut before the right camera's T_body_cam: that camera, on its line.
  EXPECT_THAT(ErrorOfParse(text.substr(0, text.rfind("    T_body_cam"))),
              HasSubstr("rig.yaml:"));
}

// A NUL in a quoted value used to cut the message at it ("width '19"):
// control bytes are shown escaped, the message keeps its problem.
TEST(Rig, ControlBytesInAQuotedValueAreShownEscaped) {
  std::string text = RigText();
  text[text.find("1920") + 2] = '\0';
  const std::string message = ErrorOfParse(text);
  EXPECT_THAT(message, HasSubstr("rig.yaml:3: camera 'left' width '19\\x00"));
  EXPECT_THAT(message, HasSubstr("' is not an integer"));
}

// --- OpenCV stereoCalibrate import ---------------------------------------

struct OpenCvCalibration {
  cv::Mat K1 = (cv::Mat_<double>(3, 3) << 1400, 0, 960, 0, 1401, 540, 0, 0, 1);
  cv::Mat D1 = (cv::Mat_<double>(1, 5) << -0.1, 0.02, 1e-4, -1e-4, 0.003);
  cv::Mat K2 = (cv::Mat_<double>(3, 3) << 1395, 0, 955, 0, 1396, 545, 0, 0, 1);
  cv::Mat D2 = (cv::Mat_<double>(1, 5) << -0.11, 0.021, 2e-4, -2e-4, 0.002);
  cv::Mat R;
  cv::Mat T = (cv::Mat_<double>(3, 1) << -0.6, 0.01, 0.005);
  int width = 1920;  // 0: not written
  int height = 1080;

  OpenCvCalibration() {
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.1, 1.0, 0.05).normalized())
            .toRotationMatrix();
    R = cv::Mat(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R.at<double>(r, c) = rotation(r, c);
    }
  }

  std::string Write(const std::string& path) const {
    cv::FileStorage storage(path, cv::FileStorage::WRITE);
    if (width > 0) storage << "image_width" << width;
    if (height > 0) storage << "image_height" << height;
    storage << "K1" << K1 << "D1" << D1 << "K2" << K2 << "D2" << D2 << "R" << R
            << "T" << T;
    storage.release();
    return path;
  }
};

std::string ErrorOfImport(const std::string& path, int width = 0,
                          int height = 0) {
  try {
    ImportOpenCvStereo(path, width, height, Eigen::Isometry3d::Identity());
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no InputError)";
}

TEST(ImportOpenCvStereo, PlacesTheRightCameraByTheInverseOfRT) {
  TemporaryFolder folder;
  const OpenCvCalibration calibration;
  for (const char* name : {"stereo.yaml", "stereo.xml"}) {
    const std::string path = calibration.Write(folder.Path(name));
    Eigen::Isometry3d T_body_left = Eigen::Isometry3d::Identity();
    T_body_left.linear() =
        ParseRig(RigText(), "rig.yaml").cameras[0].T_body_cam.linear();
    T_body_left.translation() = Eigen::Vector3d(1.5, -0.3, -1.2);
    const Rig rig = ImportOpenCvStereo(path, 0, 0, T_body_left);
    ASSERT_EQ(rig.cameras.size(), 2u) << name;
    EXPECT_EQ(rig.cameras[0].camera.name(), "left");
    EXPECT_EQ(rig.cameras[1].camera.name(), "right");
    EXPECT_EQ(rig.cameras[0].camera.width(), 1920);
    EXPECT_EQ(rig.cameras[1].camera.height(), 1080);
    EXPECT_EQ(rig.cameras[1].camera.fx(), 1395.0);
    EXPECT_EQ(rig.cameras[1].camera.cy(), 545.0);
    EXPECT_EQ(rig.cameras[0].camera.distortion()[4], 0.003);
    ASSERT_EQ(rig.stereo_pairs.size(), 1u);
    EXPECT_EQ(rig.stereo_pairs[0], (std::array<int, 2>{0, 1}));

    // A point seen by the left camera, taken through the body frame into
    // the right camera, lands where OpenCV puts it: p_right = R p_left + T.
    const Eigen::Vector3d p_left(0.7, -0.4, 12.0);
    const Eigen::Vector3d p_body = rig.cameras[0].T_body_cam * p_left;
    const Eigen::Vector3d p_right =
        rig.cameras[1].T_body_cam.inverse() * p_body;
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = calibration.R.at<double>(r, c);
    }
    const Eigen::Vector3d expected =
        R * p_left + Eigen::Vector3d(-0.6, 0.01, 0.005);
    EXPECT_LT((p_right - expected).norm(), 1e-12) << name;
  }
}

TEST(ImportOpenCvStereo, TakesTheImageSizeFromArgumentsWhenTheFileHasNone) {
  TemporaryFolder folder;
  OpenCvCalibration calibration;
  calibration.width = 0;
  calibration.height = 0;
  const std::string path = calibration.Write(folder.Path("stereo.yaml"));
  const Rig rig =
      ImportOpenCvStereo(path, 640, 480, Eigen::Isometry3d::Identity());
  EXPECT_EQ(rig.cameras[0].camera.width(), 640);
  EXPECT_EQ(rig.cameras[1].camera.height(), 480);
  EXPECT_THAT(ErrorOfImport(path),
              HasSubstr("stereo.yaml: image size unknown"));
}

TEST(ImportOpenCvStereo, AcceptsZeroExtraCoefficientsAndFourCoefficients) {
  TemporaryFolder folder;
  OpenCvCalibration calibration;
  calibration.D1 = cv::Mat::zeros(1, 8, CV_64F);
  calibration.D1.at<double>(0) = -0.2;
  calibration.D1.at<double>(4) = 0.05;
  calibration.D2 = (cv::Mat_<double>(4, 1) << 0.1, 0.2, 0.3, 0.4);
  const Rig rig = ImportOpenCvStereo(calibration.Write(folder.Path("s.yaml")),
                                     0, 0, Eigen::Isometry3d::Identity());
  EXPECT_EQ(rig.cameras[0].camera.distortion()[0], -0.2);
  EXPECT_EQ(rig.cameras[0].camera.distortion()[4], 0.05);
  EXPECT_EQ(rig.cameras[1].camera.distortion()[3], 0.4);
  EXPECT_EQ(rig.cameras[1].camera.distortion()[4], 0.0);
}

TEST(ImportOpenCvStereo, RejectsRationalDistortion) {
  TemporaryFolder folder;
  OpenCvCalibration calibration;
  calibration.D2 = cv::Mat::zeros(1, 14, CV_64F);
  calibration.D2.at<double>(5) = 0.01;  // k4 of the rational model
  const std::string path = calibration.Write(folder.Path("s.yaml"));
  const std::string error = ErrorOfImport(path);
  EXPECT_THAT(error, HasSubstr("s.yaml: 'D2' has 14 coefficients"));
  EXPECT_THAT(error, HasSubstr("only [k1, k2, p1, p2, k3] is supported"));
}

TEST(ImportOpenCvStereo, RejectsMissingMatricesAndMillimetreBaselines) {
  TemporaryFolder folder;
  OpenCvCalibration calibration;
  calibration.T = (cv::Mat_<double>(3, 1) << -600.0, 1.0, 0.5);
  EXPECT_THAT(ErrorOfImport(calibration.Write(folder.Path("mm.yaml"))),
              HasSubstr("mm.yaml: baseline |T| = 600"));
  const std::string partial = folder.Write(
      "partial.yaml", "%YAML:1.0\n---\nimage_width: 10\nimage_height: 10\n");
  EXPECT_THAT(ErrorOfImport(partial),
              HasSubstr("partial.yaml: missing matrix 'K1'"));
  const std::string garbage = folder.Write("garbage.yaml", "\x01\x02{{{[[[");
  EXPECT_THAT(ErrorOfImport(garbage), HasSubstr("garbage.yaml: "));
  EXPECT_THAT(ErrorOfImport(folder.Path("absent.yaml")),
              HasSubstr("absent.yaml: cannot open"));
}

}  // namespace
}  // namespace zebrageo
