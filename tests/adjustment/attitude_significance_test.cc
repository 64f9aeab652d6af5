// The attitude corrections the control does not determine are held at the
// input's (AdjustmentOptions::attitude_significance, issue 17: "attitude
// made worse" on surveys with one or two crossings); those it determines
// are kept.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "adjustment/trajectory_adjuster.h"
#include "tests/adjustment/pose_errors.h"
#include "tests/support/synthetic_survey.h"

namespace zebrageo {
namespace {

struct Fixture {
  SyntheticSurvey survey;
  Trajectory trajectory;
  explicit Fixture(const SyntheticSurveyOptions& options)
      : survey(MakeSyntheticSurvey(options)),
        trajectory(survey.measured_samples, survey.frame) {}
  AdjustmentInput Input() const {
    return SyntheticAdjustmentInput(survey, trajectory);
  }
};

// One crossing measures the heading only with the cross-track drift's rate:
// every attitude axis keeps the INS's, exactly, while the position is
// corrected.
TEST(AttitudeSignificance, OneCrossingKeepsTheInputAttitude) {
  SyntheticSurveyOptions options;
  options.num_exposures = 30;  // 90 m at 10 m/s
  options.crossing_spacing_m = 200.0;
  options.heading_drift_deg = 0.1;
  const Fixture f(options);
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  ASSERT_EQ(
      result.summary.num_control_crossings + result.summary.num_check_crossings,
      1);
  EXPECT_EQ(result.summary.attitude_held, Eigen::Vector3i::Ones());
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  std::cout << "one crossing: attitude " << before.rmse_attitude_deg << " -> "
            << after.rmse_attitude_deg << " deg, horizontal "
            << before.rmse_horizontal_m << " -> " << after.rmse_horizontal_m
            << " m\n";
  EXPECT_NEAR(after.rmse_attitude_deg, before.rmse_attitude_deg, 1e-6);
  EXPECT_LT(after.rmse_horizontal_m, 0.5 * before.rmse_horizontal_m);
}

// A kilometre with a crossing every 80 m and tie points, the INS's heading
// drifting by 0.3 degrees: the control determines the heading, which is
// corrected.
TEST(AttitudeSignificance, ADeterminedHeadingErrorIsCorrected) {
  SyntheticSurveyOptions options;
  options.num_exposures = 330;
  options.database_offset_m = 0.03;
  options.tie_points_per_exposure = 6;
  options.heading_drift_deg = 0.3;
  const Fixture f(options);
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  std::cout << "heading drift 0.3 deg: attitude " << before.rmse_attitude_deg
            << " -> " << after.rmse_attitude_deg << " deg; significance "
            << result.summary.attitude_significance.transpose() << "\n";
  EXPECT_EQ(result.summary.attitude_held[2], 0);
  EXPECT_GE(result.summary.attitude_significance[2], 2.0);
  EXPECT_LT(after.rmse_attitude_deg, 0.5 * before.rmse_attitude_deg);
}

// Disabled (0): every axis is adjusted, none held.
TEST(AttitudeSignificance, ZeroDisablesTheTest) {
  SyntheticSurveyOptions options;
  options.num_exposures = 40;
  const Fixture f(options);
  AdjustmentOptions adjustment;
  adjustment.model.attitude_significance = 0.0;
  const AdjustmentResult result = AdjustTrajectory(adjustment, f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_EQ(result.summary.attitude_held, Eigen::Vector3i::Zero());
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_GT(std::abs(after.rmse_attitude_deg - before.rmse_attitude_deg), 1e-4);
}

TEST(AttitudeSignificance, NegativeThresholdIsRejectedByCheck) {
  AdjustmentOptions options;
  options.model.attitude_significance = -1.0;
  EXPECT_EQ(options.Check(), "model.attitude_significance = -1: must be >= 0");
}

}  // namespace
}  // namespace zebrageo
