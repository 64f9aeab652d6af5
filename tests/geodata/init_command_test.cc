// `zebrageo init` on a mapping engineer's kind of files: a small simulated
// survey's images converted to JPEG (quality 95) with their trigger times
// in EXIF (UTC calendar time, as a camera writes it), its trajectory as an
// Applanix SBET with its smrmsg, its rig as a Kalibr camchain with the
// left camera's mount in a mount file. The survey init writes has the
// original's rig and exposure times, and `run` scores like the PNG survey.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "survey/exposures.h"
#include "survey/rig.h"
#include "survey/trajectory.h"
#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr double kGpsWeek = 2300;  // 2024-02-04 to 2024-02-10
constexpr double kGpsEpochUnix = 315964800.0;
constexpr double kGpsMinusUtc2024 = 18.0;

std::string Number(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

void PutLittleEndian(double value, std::string* out) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 8; ++i)
    out->push_back(static_cast<char>(bits >> (8 * i)));
}

void Put16(int value, std::string* out) {
  out->push_back(static_cast<char>(value & 0xff));
  out->push_back(static_cast<char>((value >> 8) & 0xff));
}
void Put32(uint32_t value, std::string* out) {
  for (int i = 0; i < 4; ++i)
    out->push_back(static_cast<char>(value >> (8 * i)));
}

// An EXIF APP1 segment with DateTimeOriginal and SubSecTimeOriginal (a
// little-endian TIFF structure written here by hand, independently of the
// libexif reader under test).
std::string ExifSegment(const std::string& date_time,
                        const std::string& subsec) {
  std::string tiff = "II";
  Put16(42, &tiff);
  Put32(8, &tiff);  // IFD0
  Put16(1, &tiff);  // IFD0: the Exif IFD pointer only
  Put16(0x8769, &tiff);
  Put16(4, &tiff);  // LONG
  Put32(1, &tiff);
  Put32(26, &tiff);  // the Exif IFD's offset
  Put32(0, &tiff);   // no next IFD
  const uint32_t data = 26 + 2 + 2 * 12 + 4;
  Put16(2, &tiff);
  Put16(0x9003, &tiff);  // DateTimeOriginal, ASCII, 20
  Put16(2, &tiff);
  Put32(20, &tiff);
  Put32(data, &tiff);
  Put16(0x9291, &tiff);  // SubSecTimeOriginal
  Put16(2, &tiff);
  Put32(static_cast<uint32_t>(subsec.size() + 1), &tiff);
  Put32(data + 20, &tiff);
  Put32(0, &tiff);
  tiff += date_time + std::string(1, '\0') + subsec + std::string(1, '\0');
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  return std::string("\xff\xe1", 2) + static_cast<char>(length >> 8) +
         static_cast<char>(length & 0xff) + payload;
}

// The UTC calendar time of GPS second-of-week `t` of kGpsWeek, as EXIF
// writes it: "YYYY:MM:DD HH:MM:SS" and 6 digits of fraction.
std::pair<std::string, std::string> ExifTime(double t) {
  const double unix_time =
      kGpsEpochUnix + kGpsWeek * 604800.0 + t - kGpsMinusUtc2024;
  const std::time_t whole = static_cast<std::time_t>(std::floor(unix_time));
  std::tm utc{};
  gmtime_r(&whole, &utc);
  char date[32];
  std::strftime(date, sizeof(date), "%Y:%m:%d %H:%M:%S", &utc);
  char fraction[16];
  std::snprintf(
      fraction, sizeof(fraction), "%06d",
      static_cast<int>(std::lround((unix_time - whole) * 1e6)) % 1000000);
  return {date, fraction};
}

class InitCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new TemporaryFolder();
    survey_ = tmp_->Path("png");
    ASSERT_EQ(
        RunZebrageo("--log-level error simulate " + SmallSurveyArguments() +
                        " --set k3=0 -o " + Quote(survey_),
                    tmp_->Path("out"), tmp_->Path("err")),
        0)
        << ReadWholeFile(tmp_->Path("err"));
    rig_ = new Rig(ReadRig(survey_ + "/rig.yaml", "rig.yaml"));
    exposures_ = new ExposureTable(
        ReadExposures(survey_ + "/exposures.csv", "exposures.csv", *rig_));
    WriteRawFiles();
  }
  static void TearDownTestSuite() {
    delete exposures_;
    delete rig_;
    delete tmp_;
  }

  // raw/: what a mapping engineer has.
  static void WriteRawFiles() {
    const std::string raw = tmp_->Path("raw");
    for (const ExposureImage& image : exposures_->images) {
      const cv::Mat png =
          cv::imread(survey_ + "/" + image.image, cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(png.empty()) << image.image;
      std::vector<uchar> jpeg;
      ASSERT_TRUE(
          cv::imencode(".jpg", png, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
      const auto [date, fraction] = ExifTime(image.time);
      std::string bytes(jpeg.begin(), jpeg.end());
      bytes.insert(2, ExifSegment(date, fraction));
      // One folder, the camera in the name: 001000_left.jpg.
      const std::string name = fs::path(image.image).stem().string() + ".jpg";
      tmp_->Write("raw/images/" + name, bytes);
    }
    // SBET and smrmsg, one record per sample.
    const std::vector<TrajectorySample> samples =
        ReadTrajectorySamples(survey_ + "/trajectory.csv", "trajectory.csv");
    std::string sbet, smrmsg;
    constexpr double kArcMinutesPerRad = 180.0 * 60.0 / M_PI;
    for (const TrajectorySample& s : samples) {
      const double record[17] = {s.time,
                                 s.position.lat_deg * M_PI / 180.0,
                                 s.position.lon_deg * M_PI / 180.0,
                                 s.position.h_m,
                                 0,
                                 0,
                                 0,
                                 s.attitude.roll,
                                 s.attitude.pitch,
                                 s.attitude.heading,
                                 0,
                                 0,
                                 0,
                                 0,
                                 0,
                                 0,
                                 0};
      for (double v : record) PutLittleEndian(v, &sbet);
      const double rms[10] = {s.time,
                              s.sd_enu_m.y(),
                              s.sd_enu_m.x(),
                              s.sd_enu_m.z(),
                              0.01,
                              0.01,
                              0.01,
                              s.sd_attitude_rad.x() * kArcMinutesPerRad,
                              s.sd_attitude_rad.y() * kArcMinutesPerRad,
                              s.sd_attitude_rad.z() * kArcMinutesPerRad};
      for (double v : rms) PutLittleEndian(v, &smrmsg);
    }
    tmp_->Write("raw/sbet_mission.out", sbet);
    tmp_->Write("raw/smrmsg_mission.out", smrmsg);
    // Kalibr camchain (the survey has k3 = 0: radtan holds it).
    auto camera = [](const Camera& c) {
      const std::array<double, 5> d = c.distortion();
      return "  camera_model: pinhole\n  intrinsics: [" + Number(c.fx()) +
             ", " + Number(c.fy()) + ", " + Number(c.cx()) + ", " +
             Number(c.cy()) +
             "]\n  distortion_model: radtan\n"
             "  distortion_coeffs: [" +
             Number(d[0]) + ", " + Number(d[1]) + ", " + Number(d[2]) + ", " +
             Number(d[3]) + "]\n  resolution: [" + std::to_string(c.width()) +
             ", " + std::to_string(c.height()) + "]\n";
    };
    const Eigen::Isometry3d T_right_left =
        rig_->cameras[1].T_body_cam.inverse() * rig_->cameras[0].T_body_cam;
    std::ostringstream kalibr;
    kalibr << "cam0:\n"
           << camera(rig_->cameras[0].camera) << "cam1:\n  T_cn_cnm1:\n";
    for (int r = 0; r < 4; ++r) {
      kalibr << "  - [";
      for (int c = 0; c < 4; ++c) {
        kalibr << (c ? ", " : "") << Number(T_right_left.matrix()(r, c));
      }
      kalibr << "]\n";
    }
    kalibr << camera(rig_->cameras[1].camera);
    tmp_->Write("raw/camchain.yaml", kalibr.str());
    std::string mount = "T_body_cam: [";
    for (int i = 0; i < 16; ++i) {
      mount += (i ? ", " : "") +
               Number(rig_->cameras[0].T_body_cam.matrix()(i / 4, i % 4));
    }
    tmp_->Write("raw/mount.yaml", mount + "]\n");
  }

  std::string InitArguments(const std::string& survey) const {
    const std::string raw = tmp_->Path("raw");
    return "init " + Quote(survey) + " --images " + Quote(raw + "/images") +
           " --trajectory " + Quote(raw + "/sbet_mission.out") + " --smrmsg " +
           Quote(raw + "/smrmsg_mission.out") + " --calibration " +
           Quote(raw + "/camchain.yaml") + " --mount " +
           Quote(raw + "/mount.yaml") + " --roadmarks " +
           Quote(survey_ + "/roadmarks.geojson") +
           " --exposure-times exif --camera-pattern left=_left "
           "--camera-pattern right=_right";
  }

  static TemporaryFolder* tmp_;
  static std::string survey_;
  static Rig* rig_;
  static ExposureTable* exposures_;
};

TemporaryFolder* InitCommand::tmp_ = nullptr;
std::string InitCommand::survey_;
Rig* InitCommand::rig_ = nullptr;
ExposureTable* InitCommand::exposures_ = nullptr;

TEST_F(InitCommand, JpegSbetAndKalibrGiveTheSurveyAndItsScore) {
  const std::string jpeg = tmp_->Path("jpeg");
  ASSERT_EQ(
      RunZebrageo(InitArguments(jpeg), tmp_->Path("out"), tmp_->Path("err")), 0)
      << ReadWholeFile(tmp_->Path("err"));
  const std::string summary = ReadWholeFile(tmp_->Path("out"));
  EXPECT_NE(summary.find("paired by names (0 without a partner"),
            std::string::npos)
      << summary;
  // The rig: the original's (1e-9).
  const Rig rig = ReadRig(jpeg + "/rig.yaml", "rig.yaml");
  ASSERT_EQ(rig.cameras.size(), rig_->cameras.size());
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    EXPECT_LT((rig.cameras[c].T_body_cam.matrix() -
               rig_->cameras[c].T_body_cam.matrix())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-9);
    for (int k = 0; k < kNumIntrinsics; ++k) {
      EXPECT_NEAR(rig.cameras[c].camera.intrinsics()[k],
                  rig_->cameras[c].camera.intrinsics()[k], 1e-9);
    }
  }
  // The exposures: the same images at the same times (EXIF to 1 us).
  const ExposureTable table =
      ReadExposures(jpeg + "/exposures.csv", "exposures.csv", rig);
  ASSERT_EQ(table.images.size(), exposures_->images.size());
  ASSERT_EQ(table.exposures.size(), exposures_->exposures.size());
  for (size_t e = 0; e < table.exposures.size(); ++e) {
    EXPECT_NEAR(table.exposures[e].time, exposures_->exposures[e].time, 2e-6);
  }
  // Hard links into the survey, inside it as the contract wants.
  EXPECT_TRUE(fs::is_regular_file(
      jpeg + "/images/" +
      fs::path(exposures_->images[0].image).stem().string() + ".jpg"));
  // The scorer reads truth/ beside the survey's files.
  fs::copy(survey_ + "/truth", jpeg + "/truth", fs::copy_options::recursive);
  double h_after[2] = {0, 0};
  int index = 0;
  for (const std::string& survey : {survey_, jpeg}) {
    const std::string results = survey + "-results";
    ASSERT_EQ(RunZebrageo("--log-level error run " + Quote(survey) + " -o " +
                              Quote(results),
                          tmp_->Path("out"), tmp_->Path("err")),
              0)
        << ReadWholeFile(tmp_->Path("err"));
    const Score match = ScoreResults("match", survey, results, "--max-wrong 0",
                                     tmp_->Path("score"));
    EXPECT_TRUE(match.passed) << match.text;
    const Score poses =
        ScoreResults("poses", survey, results, "", tmp_->Path("score"));
    h_after[index++] = HorizontalAfterM(poses.text);
    std::cout << survey << ": " << poses.text;
  }
  EXPECT_GT(h_after[0], 0.0);
  EXPECT_GT(h_after[1], 0.0);
  // JPEG at quality 95 against PNG: measured 0.x cm apart (docs/results.md).
  EXPECT_NEAR(h_after[1], h_after[0], 0.01);
}

// Images already inside the survey folder, one subfolder per camera, named
// by their UTC stamp in nanoseconds (as ROS writes them), the right camera
// 100 us after the left: paired by time, named in place, not linked.
TEST_F(InitCommand, ImagesInsideTheSurveyNamedByUtcNanosecondsArePairedByTime) {
  const std::string survey = tmp_->Path("inside");
  for (const ExposureImage& image : exposures_->images) {
    const bool right = rig_->cameras[image.camera].camera.name() == "right";
    const double unix_time = kGpsEpochUnix + kGpsWeek * 604800.0 + image.time -
                             kGpsMinusUtc2024 + (right ? 100e-6 : 0.0);
    char name[64];
    std::snprintf(
        name, sizeof(name), "%lld.png",
        static_cast<long long>(std::llround(unix_time * 1e6)) * 1000LL);
    const fs::path to = fs::path(survey) / "cams" /
                        rig_->cameras[image.camera].camera.name() / name;
    fs::create_directories(to.parent_path());
    fs::create_hard_link(survey_ + "/" + image.image, to);
  }
  ASSERT_EQ(
      RunZebrageo("init " + Quote(survey) + " --images " +
                      Quote(survey + "/cams") + " --trajectory " +
                      Quote(survey_ + "/trajectory.csv") + " --calibration " +
                      Quote(survey_ + "/rig.yaml") + " --roadmarks " +
                      Quote(survey_ + "/roadmarks.geojson") +
                      " --exposure-times filename --time-unit ns "
                      "--time-clock unix",
                  tmp_->Path("out"), tmp_->Path("err")),
      0)
      << ReadWholeFile(tmp_->Path("err"));
  const std::string summary = ReadWholeFile(tmp_->Path("out"));
  EXPECT_NE(summary.find("paired by times (0 without a partner"),
            std::string::npos)
      << summary;
  EXPECT_NE(summary.find("images under cams/\n"), std::string::npos) << summary;
  EXPECT_FALSE(fs::exists(survey + "/images"));
  const Rig rig = ReadRig(survey + "/rig.yaml", "rig.yaml");
  const ExposureTable table =
      ReadExposures(survey + "/exposures.csv", "exposures.csv", rig);
  ASSERT_EQ(table.exposures.size(), exposures_->exposures.size());
  for (size_t e = 0; e < table.exposures.size(); ++e) {
    // The mean of the left and the right stamp: 50 us late.
    EXPECT_NEAR(table.exposures[e].time, exposures_->exposures[e].time + 50e-6,
                2e-6);
  }
}

TEST_F(InitCommand, GpsTimeTakenForUtcIsNamedAndNothingIsLeft) {
  const std::string survey = tmp_->Path("gps-clock");
  EXPECT_EQ(RunZebrageo(InitArguments(survey) + " --exif-clock gps",
                        tmp_->Path("out"), tmp_->Path("err")),
            1);
  const std::string err = ReadWholeFile(tmp_->Path("err"));
  EXPECT_NE(err.find("18 s later they would be inside"), std::string::npos)
      << err;
  EXPECT_NE(err.find("GPS - UTC"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(survey));
}

TEST_F(InitCommand, AnExistingSurveyIsNotOverwritten) {
  EXPECT_EQ(
      RunZebrageo(InitArguments(survey_), tmp_->Path("out"), tmp_->Path("err")),
      2);
  EXPECT_NE(ReadWholeFile(tmp_->Path("err")).find("already holds survey.yaml"),
            std::string::npos)
      << ReadWholeFile(tmp_->Path("err"));
}

}  // namespace
}  // namespace zebrageo
