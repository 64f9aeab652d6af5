// The import, export and report commands refuse what the next command
// would refuse (issue 48), on the real binary: the exit code, a message
// naming the cause, and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>

#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// A stereo camchain; `cam1_resolution` may differ from cam0's.
std::string Camchain(const std::string& cam1_resolution = "[1280, 960]",
                     bool with_cam1 = true) {
  std::string text =
      "cam0:\n  camera_model: pinhole\n  intrinsics: [1100, 1100, 640, 480]\n"
      "  distortion_model: radtan\n  distortion_coeffs: [-0.1, 0.08, 0, 0]\n"
      "  resolution: [1280, 960]\n";
  if (with_cam1) {
    text +=
        "cam1:\n  T_cn_cnm1:\n  - [1, 0, 0, -0.8]\n  - [0, 1, 0, 0]\n"
        "  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n  camera_model: pinhole\n"
        "  intrinsics: [1100, 1100, 640, 480]\n  distortion_model: radtan\n"
        "  distortion_coeffs: [-0.1, 0.08, 0, 0]\n  resolution: " +
        cam1_resolution + "\n";
  }
  return text;
}

std::string RosCameraInfo(int width, int height, double tx) {
  return "image_width: " + std::to_string(width) +
         "\nimage_height: " + std::to_string(height) +
         "\ncamera_matrix: {rows: 3, cols: 3, data: [1100, 0, 640, 0, 1100, "
         "480, 0, 0, 1]}\ndistortion_model: plumb_bob\n"
         "distortion_coefficients: {rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\n"
         "rectification_matrix: {rows: 3, cols: 3, data: [1, 0, 0, 0, 1, 0, "
         "0, 0, 1]}\nprojection_matrix: {rows: 3, cols: 4, data: [1100, 0, "
         "640, " +
         std::to_string(tx) + ", 0, 1100, 480, 0, 0, 0, 1, 0]}\n";
}

class ImportErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    camchain_ = tmp_.Write("in/camchain.yaml", Camchain());
    left_ = tmp_.Write("in/left.yaml", RosCameraInfo(1280, 960, 0.0));
    right_ = tmp_.Write("in/right.yaml", RosCameraInfo(1280, 960, -880.0));
    std::mt19937 rng(48);
    std::string bytes(64 * 1024, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
    random_ = tmp_.Write("in/random.bin", bytes);
    fs::create_directories(tmp_.Path("out"));
  }

  // Runs zebrageo; expects `status` and a message holding every one of
  // `needles`, and nothing written into out/.
  void ExpectRefused(const std::string& arguments, int status,
                     const std::vector<std::string>& needles) {
    const int got =
        RunZebrageo(arguments, tmp_.Path("stdout"), tmp_.Path("stderr"));
    const std::string err = ReadWholeFile(tmp_.Path("stderr"));
    EXPECT_EQ(got, status) << arguments << "\n" << err;
    for (const std::string& needle : needles) {
      EXPECT_NE(err.find(needle), std::string::npos)
          << arguments << "\nmessage lacks '" << needle << "':\n"
          << err;
    }
    EXPECT_TRUE(FilesUnder(tmp_.Path("out")).empty()) << arguments;
    EXPECT_FALSE(fs::exists(tmp_.Path("missing"))) << arguments;
  }

  std::string Out(const std::string& name) const {
    return " -o " + Quote(tmp_.Path("out/" + name));
  }

  TemporaryFolder tmp_;
  std::string camchain_, left_, right_, random_;
};

TEST_F(ImportErrors, NonFiniteMountNumbersAreUsageErrorsNamingTheOption) {
  ExpectRefused("import-kalibr " + Quote(camchain_) + " --lever-arm nan 0 0" +
                    Out("rig.yaml"),
                2, {"--lever-arm", "'nan' is not a finite number"});
  ExpectRefused("import-opencv-stereo " + Quote(camchain_) +
                    " --pitch-down-deg inf" + Out("rig.yaml"),
                2, {"--pitch-down-deg", "'inf' is not a finite number"});
  ExpectRefused("import-ros-camera-info " + Quote(left_) + " " + Quote(right_) +
                    " --mount-yaw-deg 1e400" + Out("rig.yaml"),
                2, {"--mount-yaw-deg"});
  ExpectRefused("import-kalibr " + Quote(camchain_) + " --mount-roll-deg 200" +
                    Out("rig.yaml"),
                2, {"--mount-roll-deg", "outside [-180, 180]"});
  ExpectRefused("import-kalibr " + Quote(camchain_) +
                    " --lever-arm 1520 -400 -1850" + Out("rig.yaml"),
                2, {"--lever-arm", "outside [-100, 100]"});
  ExpectRefused("import-kalibr " + Quote(camchain_) +
                    " --mount-rotation 0,0,1,1,0,0,0,-1,0" + Out("rig.yaml"),
                2, {"--mount-rotation", "reflection"});
  ExpectRefused("import-kalibr " + Quote(camchain_) +
                    " --pitch-down-deg 20 --mount-pitch-deg -20" +
                    Out("rig.yaml"),
                2, {"--pitch-down-deg", "--mount-pitch-deg"});
}

TEST_F(ImportErrors, NonFiniteImportAndInitNumbersAreUsageErrors) {
  for (const char* value : {"nan", "inf", "-1", "0"}) {
    ExpectRefused("import-kalibr " + Quote(camchain_) + " --max-fit-error-px " +
                      value + Out("rig.yaml"),
                  2, {"--max-fit-error-px"});
    ExpectRefused("import-ros-camera-info " + Quote(left_) + " " +
                      Quote(right_) + " --max-fit-error-px " + value +
                      Out("rig.yaml"),
                  2, {"--max-fit-error-px"});
  }
  const std::string init =
      "init " + Quote(tmp_.Path("out/survey")) + " --images " +
      Quote(tmp_.Path("in")) + " --trajectory " + Quote(random_) +
      " --calibration " + Quote(camchain_) + " --roadmarks " + Quote(random_);
  ExpectRefused(init + " --max-fit-error-px nan", 2,
                {"--max-fit-error-px", "'nan' is not a finite number"});
  ExpectRefused(init + " --pair-max-dt nan", 2,
                {"--pair-max-dt", "'nan' is not a finite number"});
  ExpectRefused(init + " --exif-utc-offset inf", 2,
                {"--exif-utc-offset", "'inf' is not a finite number"});
  ExpectRefused(init + " --lever-arm 0 nan 0", 2,
                {"--lever-arm", "'nan' is not a finite number"});
  // The survey folder: not a file, nor inside one.
  const std::string args = init.substr(init.find(" --images"));
  ExpectRefused("init " + Quote(camchain_) + args, 2,
                {"survey: ", "camchain.yaml is a file, not a folder"});
  ExpectRefused("init " + Quote(camchain_ + "/survey") + args, 2,
                {"camchain.yaml is a file: the folder", "cannot be created"});
}

TEST_F(ImportErrors, AMissingOrMismatchedCameraNamesTheFileAndKey) {
  const std::string mono =
      tmp_.Write("in/mono.yaml", Camchain("[1280, 960]", false));
  ExpectRefused("import-kalibr " + Quote(mono) + Out("rig.yaml"), 1,
                {"mono.yaml:2:", "cam0 only", "cam1"});
  const std::string mixed = tmp_.Write("in/mixed.yaml", Camchain("[640, 480]"));
  ExpectRefused("import-kalibr " + Quote(mixed) + Out("rig.yaml"), 1,
                {"mixed.yaml:17:", "cam1: resolution 640x480 differs"});
  const std::string small =
      tmp_.Write("in/small_right.yaml", RosCameraInfo(640, 480, -440.0));
  ExpectRefused("import-ros-camera-info " + Quote(left_) + " " + Quote(small) +
                    Out("rig.yaml"),
                1, {"small_right.yaml:1:", "image_width/image_height 640x480"});
}

TEST_F(ImportErrors, DevicesAndRandomBytesAreNotTheirFormat) {
  for (const std::string& input : {std::string("/dev/zero"), random_}) {
    ExpectRefused("import-trajectory " + Quote(input) + " --format csv" +
                      Out("trajectory.csv"),
                  1, {input, "not a delimited trajectory file"});
    ExpectRefused("import-trajectory " + Quote(input) + " --format novatel" +
                      Out("trajectory.csv"),
                  1, {input, "not a NovAtel ASCII log"});
    ExpectRefused("import-trajectory " + Quote(input) + " --format sbet" +
                      Out("trajectory.csv"),
                  1, {input, "not an SBET file"});
    ExpectRefused("import-kalibr " + Quote(input) + Out("rig.yaml"), 1,
                  {input, "not a Kalibr camchain file"});
    ExpectRefused("import-ros-camera-info " + Quote(input) + " " +
                      Quote(right_) + Out("rig.yaml"),
                  1, {input, "not a ROS camera_info file"});
    ExpectRefused("import-opencv-stereo " + Quote(input) + Out("rig.yaml"), 1,
                  {input, "not an OpenCV calibration file"});
  }
  // Another tool's calibration, and a calibration too large to be one.
  ExpectRefused("import-opencv-stereo " + Quote(camchain_) + Out("rig.yaml"), 1,
                {"camchain.yaml: not an OpenCV calibration file",
                 "OpenCV cannot parse it"});
  const std::string huge =
      tmp_.Write("in/huge.yaml", "%YAML:1.0\n" + std::string(2 << 20, ' '));
  ExpectRefused("import-opencv-stereo " + Quote(huge) + Out("rig.yaml"), 1,
                {"huge.yaml: not an OpenCV calibration file", "bytes, more"});
  // Text without a NUL byte that is no calibration.
  const std::string text = tmp_.Write("in/notes.txt", "just some notes\n");
  ExpectRefused("import-kalibr " + Quote(text) + Out("rig.yaml"), 1,
                {"not a Kalibr camchain file"});
  ExpectRefused("import-ros-camera-info " + Quote(text) + " " + Quote(right_) +
                    Out("rig.yaml"),
                1, {"not a ROS camera_info file"});
}

TEST_F(ImportErrors, OutputsInAFolderOrAMissingFolderAreUsageErrors) {
  const std::string missing = Quote(tmp_.Path("missing/rig.yaml"));
  ExpectRefused("import-kalibr " + Quote(camchain_) + " -o " + missing, 2,
                {"--output", "missing", "does not exist"});
  ExpectRefused("import-trajectory " + Quote(random_) + " --format sbet -o " +
                    Quote(tmp_.Path("missing/trajectory.csv")),
                2, {"--output", "does not exist"});
  ExpectRefused(
      "import-kalibr " + Quote(camchain_) + " -o " + Quote(tmp_.Path("out")), 2,
      {"--output", "is a folder"});
  // export-gcp checks -o before reading the survey or the results.
  for (const char* format : {"odm", "metashape", "gpkg"}) {
    ExpectRefused(std::string("export-gcp survey results --format ") + format +
                      " -o " + Quote(tmp_.Path("out")),
                  2, {"--output", "is a folder"});
    ExpectRefused(std::string("export-gcp survey results --format ") + format +
                      " -o " + Quote(tmp_.Path("missing/gcp.txt")),
                  2, {"--output", "does not exist"});
  }
}

TEST_F(ImportErrors, ReportOnAnEmptyResultsFolderIsRefused) {
  ExpectRefused("report survey -o " + Quote(tmp_.Path("out")), 2,
                {"holds no stage output", "zebrageo run"});
  ExpectRefused("report survey -o " + Quote(tmp_.Path("missing")), 2,
                {"is not a results folder"});
}

}  // namespace
}  // namespace zebrageo
