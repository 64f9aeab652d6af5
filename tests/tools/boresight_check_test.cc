// Issue 47's boresight check through `zebrageo run`: field case
// amiens-short with both cameras' mount turned by the rotation its rig's
// import loses (E = Rz(-0.95 deg) * Rx(0.65 deg), T_body_cam' = E *
// T_body_cam: a rig without the mount angles). Before the check the run
// ended with exit 0, 74 of 112 vertex matches wrong and the attitude
// 0.009 -> 0.163 deg. Now it must end either with the misalignment
// estimated (within 0.2 deg of the truth on every axis it applies), no
// wrong match and a result no worse than the input (H; the cameras'
// attitude within 0.25 deg of the truth, the input's off by 1.15 deg), or
// with exit 1 and a message naming rig.yaml. Skipped, with the reason, where
// the case or the scorer is absent. The correct rigs' runs (no false alarm) are
// in field_cases_test.
//
// A small unstated yaw (0.3 deg), below what the images' check flags
// (their yaw -0.47 +- 0.14 deg, the check's bias -0.17 included): the
// adjustment turned the body's heading instead (heading error vs truth
// 0.004 -> 0.054 deg, exit 0). It must end no worse than the input:
// heading within 0.01 deg of the input's error, H and V no worse, 0 wrong
// matches, or exit 1 naming rig.yaml.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "survey/math_util.h"
#include "survey/rig.h"
#include "survey/trajectory.h"
#include "tests/survey/test_util.h"
#include "tests/tools/cli_util.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

std::string CaseFolder() {
  const std::string datasets = SharedDatasetsFolder();
  return datasets.empty() ? "" : datasets + "/field-cases/amiens-short";
}

// The case in `folder` with every camera's mount turned by E (images and
// truth linked, never copied).
void WriteTurnedCase(const Eigen::Matrix3d& E, const std::string& folder) {
  fs::create_directories(folder);
  for (const auto& entry : fs::directory_iterator(CaseFolder())) {
    const fs::path target = fs::path(folder) / entry.path().filename();
    if (entry.is_directory()) {
      fs::create_directory_symlink(entry.path(), target);
    } else if (entry.path().filename() != "rig.yaml") {
      fs::copy_file(entry.path(), target);
    }
  }
  Rig rig = ReadRig(CaseFolder() + "/rig.yaml", "rig.yaml");
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = E;
  for (RigCamera& camera : rig.cameras) {
    camera.T_body_cam = turn * camera.T_body_cam;
  }
  WriteRig(rig, folder + "/rig.yaml");
}

// Scores `results` against the case as shipped, whose rig is the truth (the
// scorer places the true cameras with the survey's rig.yaml): no wrong
// vertex match, poses no worse than the input and H within 10 cm. Returns
// the poses scorer's text.
std::string ExpectNoWrongMatchNoWorse(const std::string& results,
                                      const TemporaryFolder& folder) {
  const Score match = ScoreResults("match", CaseFolder(), results,
                                   "--max-wrong 0", folder.Path("match.out"));
  std::cout << match.text;
  EXPECT_TRUE(match.passed);
  const Score poses = ScoreResults("poses", CaseFolder(), results,
                                   "--not-worse", folder.Path("poses.out"));
  std::cout << poses.text;
  EXPECT_TRUE(poses.passed);
  EXPECT_LE(HorizontalAfterM(poses.text), 0.10);
  return poses.text;
}

TEST(BoresightCheck, AnUnstatedMountIsEstimatedOrRefusedNeverWorse) {
  if (!fs::exists(CaseFolder() + "/survey.yaml")) {
    GTEST_SKIP() << "../shared/datasets/field-cases/amiens-short is absent";
  }
  if (!fs::exists(Scorer())) {
    GTEST_SKIP() << Scorer() << " is absent: the run cannot be scored";
  }
  const Eigen::Matrix3d E =
      (Eigen::AngleAxisd(DegToRad(-0.95), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(DegToRad(0.65), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  TemporaryFolder folder;
  const std::string survey = folder.Path("turned");
  WriteTurnedCase(E, survey);
  const std::string results = folder.Path("results");
  const int code =
      RunZebrageo("--log-level warning run " + Quote(survey) + " -o " +
                      Quote(results) + " --threads 2 --allow-outside-paths",
                  folder.Path("out"), folder.Path("err"));
  const std::string err = ReadWholeFile(folder.Path("err"));
  std::cout << err;
  ASSERT_TRUE(code == 0 || code == 1) << code << ": " << err;
  EXPECT_NE(err.find("rig.yaml"), std::string::npos) << err;
  if (code == 1) {
    EXPECT_NE(err.find("roll"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(results + "/poses.csv"));
    return;
  }
  EXPECT_NE(err.find("diagnosis:"), std::string::npos) << err;
  std::ifstream report_file(results + "/report.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  const nlohmann::json& boresight = report.at("boresight");
  EXPECT_TRUE(boresight.at("applied").get<bool>());
  // The applied rotation undoes E, on the axes it applies.
  const Eigen::AngleAxisd truth(E.transpose());
  const Eigen::Vector3d truth_deg = RadToDeg(truth.angle()) * truth.axis();
  int axes_applied = 0;
  for (int k = 0; k < 3; ++k) {
    const std::string axis = k == 0 ? "roll" : k == 1 ? "pitch" : "yaw";
    const double applied = boresight.at(axis + "_applied_deg").get<double>();
    std::cout << "[ BORESIGHT] " << axis << " applied " << applied
              << " deg, truth " << truth_deg[k] << " deg\n";
    if (applied != 0.0) {
      ++axes_applied;
      EXPECT_NEAR(applied, truth_deg[k], 0.2) << axis;
    }
  }
  EXPECT_GE(axes_applied, 2);
  const std::string poses_text = ExpectNoWrongMatchNoWorse(results, folder);
  // The cameras' attitude: the input's, with the rig as given, is off by
  // E's angle (1.15 deg); the result must be far closer to the truth.
  std::smatch attitude;
  ASSERT_TRUE(std::regex_search(poses_text, attitude,
                                std::regex(R"(after: .* att ([0-9.]+) deg;)")))
      << poses_text;
  EXPECT_LE(std::stod(attitude[1].str()), 0.25);
}

// RMS over the samples of `results` of the heading's departure from the
// truth's (degrees).
double HeadingRmsDeg(const std::string& trajectory_csv,
                     const std::string& truth_csv) {
  const std::vector<TrajectorySample> samples =
      ReadTrajectorySamples(trajectory_csv, trajectory_csv);
  const std::vector<TrajectorySample> truth =
      ReadTrajectorySamples(truth_csv, truth_csv);
  double sum = 0.0;
  int count = 0;
  size_t j = 0;
  for (const TrajectorySample& sample : samples) {
    while (j < truth.size() && truth[j].time < sample.time - 1e-6) ++j;
    if (j == truth.size() || std::abs(truth[j].time - sample.time) > 1e-6) {
      continue;
    }
    const double d = std::remainder(
        sample.attitude.heading - truth[j].attitude.heading, 2.0 * M_PI);
    sum += d * d;
    ++count;
  }
  EXPECT_GT(count, 10) << trajectory_csv;
  return count > 0 ? RadToDeg(std::sqrt(sum / count)) : 1e9;
}

TEST(SmallMountYaw, EndsNoWorseThanTheInputOrExits1) {
  if (!fs::exists(CaseFolder() + "/survey.yaml")) {
    GTEST_SKIP() << "../shared/datasets/field-cases/amiens-short is absent";
  }
  if (!fs::exists(Scorer())) {
    GTEST_SKIP() << Scorer() << " is absent: the run cannot be scored";
  }
  TemporaryFolder folder;
  const std::string survey = folder.Path("turned");
  WriteTurnedCase(
      Eigen::AngleAxisd(DegToRad(0.3), Eigen::Vector3d::UnitZ()).matrix(),
      survey);
  const std::string results = folder.Path("results");
  // The second look after the adjustment (pipeline/mount_attitude_check.h;
  // on by default, stated so that the test holds it whatever the default).
  const std::string options = folder.Path("options.json");
  std::ofstream(options) << R"({"boresight": {"attitude": {"enabled": true}}})";
  const int code = RunZebrageo(
      "--log-level warning run " + Quote(survey) + " -o " + Quote(results) +
          " --options " + Quote(options) + " --threads 2 --allow-outside-paths",
      folder.Path("out"), folder.Path("err"));
  const std::string err = ReadWholeFile(folder.Path("err"));
  std::cout << err;
  ASSERT_TRUE(code == 0 || code == 1) << code << ": " << err;
  if (code == 1) {
    EXPECT_NE(err.find("rig.yaml"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(results + "/poses.csv"));
    return;
  }
  // Whatever the run did about the mount, it says so.
  EXPECT_NE(err.find("rig.yaml"), std::string::npos) << err;
  const double input_deg = HeadingRmsDeg(
      CaseFolder() + "/trajectory.csv", CaseFolder() + "/truth/trajectory.csv");
  const double after_deg =
      HeadingRmsDeg(results + "/trajectory_corrected.csv",
                    CaseFolder() + "/truth/trajectory.csv");
  std::cout << "[ HEADING  ] RMS vs truth: input " << input_deg
            << " deg, after " << after_deg << " deg\n";
  EXPECT_LE(after_deg, input_deg + 0.01);
  ExpectNoWrongMatchNoWorse(results, folder);
}

}  // namespace
}  // namespace zebrageo
