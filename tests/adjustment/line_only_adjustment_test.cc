// Road lines as the only control (no zebra crossing matched): the
// trajectory is corrected across the lines and in height, along-track and
// in attitude it keeps the input's, and the error model is fitted on what
// the lines show (line_discrepancies.h), so that a metre of cross-track
// drift is followed, not held near the input by the model's floor.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "tests/support/synthetic_survey.h"

namespace zebrageo {
namespace {

// Line points at `lateral_m` (left of the vehicle, metres) painted on the
// road 6 to 12 m ahead of every exposure, from the TRUE pose (a perfect
// reconstruction in the body frame), matched to a database line through
// them with `db_noise_m` per point.
std::vector<LineControlPoint> IdealLinePoints(
    const SyntheticSurvey& survey, const std::vector<double>& lateral_m,
    double db_noise_m) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, db_noise_m);
  std::vector<LineControlPoint> points;
  for (const Exposure& e : survey.exposures.exposures) {
    Pose pose;
    if (!truth.InterpolatePose(e.time, &pose)) continue;
    const Eigen::Vector3d forward = pose.q_enu_body * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d flat =
        Eigen::Vector3d(forward.x(), forward.y(), 0.0).normalized();
    const Eigen::Vector3d left(-flat.y(), flat.x(), 0.0);
    for (double lateral : lateral_m) {
      for (double ahead : {6.0, 9.0, 12.0}) {
        // On the road (2 m below the body origin), climbing with it.
        const Eigen::Vector3d p_enu =
            pose.p_enu + ahead * forward / forward.head<2>().norm() +
            lateral * left - 2.0 * Eigen::Vector3d::UnitZ();
        LineControlPoint p;
        p.time = e.time;
        p.p_body = pose.q_enu_body.inverse() * (p_enu - pose.p_enu);
        p.db_point_enu =
            p_enu + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
        p.across_enu = left;
        p.along_enu = flat;
        p.grade = forward.z() / forward.head<2>().norm();
        p.sqrt_information =
            Eigen::Vector2d(1.0 / 0.03, 1.0 / 0.03).asDiagonal();
        points.push_back(p);
      }
    }
  }
  return points;
}

// RMS along-track, cross-track and vertical position error of the samples
// `poses` (at `samples`' times) against the truth.
Eigen::Vector3d TrackErrors(const SyntheticSurvey& survey,
                            const std::vector<TrajectorySample>& samples,
                            const std::vector<Pose>& poses) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    Pose true_pose;
    if (!truth.InterpolatePose(samples[i].time, &true_pose)) continue;
    const Eigen::Vector3d forward =
        true_pose.q_enu_body * Eigen::Vector3d::UnitX();
    const Eigen::Vector2d flat = forward.head<2>().normalized();
    const Eigen::Vector2d left(-flat.y(), flat.x());
    const Eigen::Vector3d d = poses[i].p_enu - true_pose.p_enu;
    sum += Eigen::Vector3d(std::pow(d.head<2>().dot(flat), 2),
                           std::pow(d.head<2>().dot(left), 2), d.z() * d.z());
    ++n;
  }
  return (sum / std::max(n, 1)).cwiseSqrt();
}

class LineOnlyAdjustment : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticSurveyOptions options;
    options.num_exposures = 100;  // 300 m
    options.drift_horizontal_m = 1.0;
    options.drift_vertical_m = 0.2;
    options.drift_period_s = 30.0;
    survey_ = MakeSyntheticSurvey(options);
    trajectory_ = Trajectory(survey_.measured_samples, survey_.frame);
    lines_ = IdealLinePoints(survey_, {-1.7, 1.8}, 0.02);
  }
  AdjustmentResult Adjust(const AdjustmentOptions& options) {
    AdjustmentInput input = SyntheticAdjustmentInput(survey_, trajectory_);
    input.matches = &no_matches_;
    input.line_points = &lines_;
    return AdjustTrajectory(options, input);
  }
  Eigen::Vector3d InputErrors() const {
    return TrackErrors(survey_, survey_.measured_samples, trajectory_.poses());
  }
  SyntheticSurvey survey_;
  Trajectory trajectory_;
  std::vector<LineControlPoint> lines_;
  std::vector<VertexMatch> no_matches_;
};

TEST_F(LineOnlyAdjustment, CorrectsAcrossAndInHeightKeepsAlongTrack) {
  const AdjustmentResult result = Adjust(AdjustmentOptions());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_TRUE(result.summary.corrected);
  EXPECT_TRUE(result.summary.line_control_only);
  EXPECT_EQ(result.summary.num_control_crossings, 0);
  const Eigen::Vector3d before = InputErrors();
  const Eigen::Vector3d after =
      TrackErrors(survey_, result.corrected_samples, result.corrected_poses);
  std::cout << "along/cross/up RMS before " << before.transpose()
            << " m, after " << after.transpose() << " m\n";
  // The drift is there to be corrected: decimetres across and in height.
  ASSERT_GT(before.y(), 0.2);
  ASSERT_GT(before.z(), 0.05);
  EXPECT_LT(after.y(), 0.04);
  EXPECT_LT(after.z(), 0.04);
  // Nothing measures along-track: it stays the input's, to a few
  // millimetres (a weak prior there would let the lines' grade term move it
  // by decimetres).
  EXPECT_NEAR(after.x(), before.x(), 0.005);
  // The posterior sd says so: horizontally it is the size of the drift the
  // lines show (along-track), not the model's floor.
  ASSERT_TRUE(result.summary.covariance_computed);
  EXPECT_GT(result.summary.median_posterior_sd_horizontal_m, 0.1);
  EXPECT_LT(result.summary.median_posterior_sd_vertical_m, 0.05);
}

// A crossing the lines contradict (its database copy a metre across the
// road) is rejected in the blunder loop; the lines alone then hold the
// trajectory as when nothing was matched: along the track it stays the
// input's (a height misfit on the grade must not move it).
TEST_F(LineOnlyAdjustment, ACrossingRejectedLeavesTheLinesAloneAsWithout) {
  ASSERT_FALSE(survey_.matches.empty());
  const std::string crossing = survey_.matches.front().crossing_id;
  std::vector<VertexMatch> matches;
  for (const VertexMatch& m : survey_.matches) {
    if (m.crossing_id == crossing) matches.push_back(m);
  }
  RoadmarkDatabase moved = survey_.database;
  for (RoadmarkBand& band : moved.bands) {
    if (band.crossing_id != crossing) continue;
    for (Geodetic& corner : band.corners) {
      corner = survey_.frame.GeodeticFromEnu(
          survey_.frame.EnuFromGeodetic(corner) + Eigen::Vector3d(0, 1.0, 0));
    }
  }
  AdjustmentInput input = SyntheticAdjustmentInput(survey_, trajectory_);
  input.matches = &matches;
  input.roadmarks = &moved;
  input.line_points = &lines_;
  const AdjustmentResult result = AdjustTrajectory(AdjustmentOptions(), input);
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  ASSERT_EQ(result.summary.num_control_crossings, 0)
      << "the shifted crossing was kept: " << result.summary.BriefReport();
  EXPECT_TRUE(result.summary.line_control_only);
  const Eigen::Vector3d before = InputErrors();
  const Eigen::Vector3d after =
      TrackErrors(survey_, result.corrected_samples, result.corrected_poses);
  EXPECT_NEAR(after.x(), before.x(), 0.005);
  EXPECT_LT(after.y(), 0.04);
  EXPECT_LT(after.z(), 0.04);
}

TEST_F(LineOnlyAdjustment, CanBeTurnedOff) {
  AdjustmentOptions options;
  options.road_lines.line_control_without_crossings = false;
  const AdjustmentResult result = Adjust(options);
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_FALSE(result.summary.corrected);
  EXPECT_FALSE(result.summary.line_control_only);
  const Eigen::Vector3d before = InputErrors();
  const Eigen::Vector3d after =
      TrackErrors(survey_, result.corrected_samples, result.corrected_poses);
  EXPECT_NEAR((after - before).norm(), 0.0, 1e-6);
}

TEST(LineOnlyAdjustmentOptions, CheckNamesTheBadValue) {
  AdjustmentOptions options;
  options.road_lines.line_discrepancy_bin_s = 0.0;
  EXPECT_NE(options.Check().find("line_discrepancy_bin_s"), std::string::npos);
  options = AdjustmentOptions();
  options.road_lines.line_discrepancy_min_points = 0;
  EXPECT_NE(options.Check().find("line_discrepancy_min_points"),
            std::string::npos);
}

}  // namespace
}  // namespace zebrageo
