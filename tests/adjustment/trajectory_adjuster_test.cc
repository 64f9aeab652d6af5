#include "adjustment/trajectory_adjuster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <set>

#include "survey/input_error.h"
#include "tests/adjustment/pose_errors.h"
#include "tests/support/synthetic_survey.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

struct Fixture {
  SyntheticSurvey survey;
  Trajectory trajectory;
  AdjustmentInput Input() const {
    return SyntheticAdjustmentInput(survey, trajectory);
  }
};

Fixture MakeFixture(const SyntheticSurveyOptions& options) {
  Fixture f;
  f.survey = MakeSyntheticSurvey(options);
  f.trajectory = Trajectory(f.survey.measured_samples, f.survey.frame);
  return f;
}

// 330 exposures (1 km at 10 m/s), a crossing every 80 m, 2 m drift.
SyntheticSurveyOptions KilometreOptions() {
  SyntheticSurveyOptions options;
  options.num_exposures = 330;
  options.database_offset_m = 0.03;
  return options;
}

TEST(TrajectoryAdjuster, RecoversTwoMetreDriftToCentimetres) {
  SyntheticSurveyOptions options = KilometreOptions();
  options.tie_points_per_exposure = 6;
  const Fixture f = MakeFixture(options);
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_GT(before.rmse_horizontal_m, 0.5);
  EXPECT_LT(after.rmse_horizontal_m, 0.06);
  EXPECT_LT(after.rmse_vertical_m, 0.05);
  EXPECT_LT(after.rmse_attitude_deg, 0.04);
  EXPECT_LT(after.rmse_attitude_deg, before.rmse_attitude_deg);
  EXPECT_EQ(result.summary.num_rejected_points, 0);
  EXPECT_GT(result.summary.num_tie_tracks, 100);
  // One pose per image, one corrected sample per input sample, same times.
  EXPECT_EQ(result.camera_poses.size(), f.survey.exposures.images.size());
  ASSERT_EQ(result.corrected_samples.size(), f.survey.measured_samples.size());
  for (size_t i = 0; i < result.corrected_samples.size(); ++i) {
    ASSERT_EQ(result.corrected_samples[i].time,
              f.survey.measured_samples[i].time);
  }
  EXPECT_TRUE(result.summary.covariance_computed);
  EXPECT_GT(result.summary.median_posterior_sd_horizontal_m, 0.0);
  EXPECT_LT(result.summary.median_posterior_sd_horizontal_m, 0.2);
}

TEST(TrajectoryAdjuster, CheckPointsAreHeldOutAndMeasureAnHonestAccuracy) {
  const Fixture f = MakeFixture(KilometreOptions());
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_GE(result.summary.num_check_crossings, 2);
  EXPECT_GE(result.summary.num_control_crossings, 8);
  std::set<std::string> check, control;
  for (const ControlPointResult& p : result.control_points) {
    (p.status == ControlStatus::kCheck ? check : control).insert(p.crossing_id);
  }
  for (const std::string& c : check) EXPECT_EQ(control.count(c), 0u) << c;
  // The check RMSE holds the trajectory error and the database error
  // (2 cm vertex noise, 3 cm crossing offsets): it must be of that size,
  // neither hidden nor inflated.
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  const double database_h = std::sqrt(2.0) * std::hypot(0.02, 0.03);
  const double expected = std::hypot(after.rmse_horizontal_m, database_h);
  EXPECT_GT(result.summary.check_rmse_horizontal_m, 0.4 * expected);
  EXPECT_LT(result.summary.check_rmse_horizontal_m, 2.5 * expected);
  // The database's part, per the adjustment's model of it, and the
  // trajectory error left once it is removed.
  const AdjustmentSummary& s = result.summary;
  EXPECT_EQ(s.num_check_points_evaluated, s.num_check_points);
  EXPECT_GT(s.check_database_rms_horizontal_m, 0.0);
  EXPECT_NEAR(
      std::hypot(s.check_implied_trajectory_horizontal_m,
                 s.check_database_rms_horizontal_m),
      std::max(s.check_rmse_horizontal_m, s.check_database_rms_horizontal_m),
      1e-9);
  EXPECT_LE(s.check_implied_trajectory_horizontal_m, s.check_rmse_horizontal_m);
}

TEST(TrajectoryAdjuster, NoCheckCrossingMeansNoCheckFigure) {
  const Fixture f = MakeFixture(KilometreOptions());
  AdjustmentOptions options;
  options.control.check_crossing_share = 0.0;
  const AdjustmentResult result = AdjustTrajectory(options, f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_EQ(result.summary.num_check_crossings, 0);
  // Reported as null (adjustment_io), not as a perfect 0.
  EXPECT_EQ(result.summary.num_check_points_evaluated, 0);
}

TEST(TrajectoryAdjuster, WrongControlPointsAreFlaggedAndRemoved) {
  Fixture f = MakeFixture(KilometreOptions());
  // A digitising blunder on one vertex (0.6 m) and a whole crossing 1.5 m
  // away from where it is (a wrong match).
  const Eigen::Vector3d shift(0.4, -0.45, 0.0);
  for (RoadmarkBand& band : f.survey.database.bands) {
    if (band.crossing_id == "X4" && band.band == 2) {
      const Eigen::Vector3d p = f.survey.frame.EnuFromGeodetic(band.corners[1]);
      band.corners[1] = f.survey.frame.GeodeticFromEnu(p + shift);
    }
    if (band.crossing_id == "X9") {
      for (Geodetic& corner : band.corners) {
        const Eigen::Vector3d p = f.survey.frame.EnuFromGeodetic(corner);
        corner =
            f.survey.frame.GeodeticFromEnu(p + Eigen::Vector3d(1.2, 0.9, 0.0));
      }
    }
  }
  AdjustmentOptions options;
  options.control.check_crossing_share =
      0.0;  // every crossing in the adjustment
  const AdjustmentResult result = AdjustTrajectory(options, f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  int rejected_x9 = 0, total_x9 = 0, rejected_other = 0;
  bool blunder_rejected = false;
  for (const ControlPointResult& p : result.control_points) {
    const bool rejected = p.status == ControlStatus::kRejected;
    if (p.crossing_id == "X9") {
      ++total_x9;
      rejected_x9 += rejected;
    } else if (p.crossing_id == "X4" && p.band == 2 && p.db_vertex == 1) {
      blunder_rejected = rejected;
      EXPECT_GT(p.normalized_residual, options.blunders.blunder_threshold);
    } else {
      rejected_other += rejected;
    }
  }
  EXPECT_TRUE(blunder_rejected);
  EXPECT_GT(total_x9, 0);
  EXPECT_EQ(rejected_x9, total_x9);
  EXPECT_LE(rejected_other, 2);
  EXPECT_FALSE(result.summary.warnings.empty());
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_LT(after.rmse_horizontal_m, 0.08);
}

// The demo preset's failure: the vertical drift is a few centimetres and
// the database's crossings are 5-15 cm off. Followed blindly, the control
// moves the trajectory vertically by the database's error; the GNSS/INS
// sigma estimated from the control (variance components) must see that
// the vertical discrepancies are the database's and leave the vertical
// alone, while the horizontal drift is corrected.
TEST(TrajectoryAdjuster, DatabaseErrorLargerThanTheDriftDoesNotMakeItWorse) {
  SyntheticSurveyOptions options;
  options.num_exposures = 200;
  options.drift_horizontal_m = 0.5;
  options.drift_vertical_m = 0.02;
  // Per axis, the adjustment's crossing_offset_sigma_m (the contract's "5
  // to 15 cm off").
  options.database_offset_m = 0.07;
  const Fixture f = MakeFixture(options);
  AdjustmentOptions adjustment;
  adjustment.control.check_crossing_share = 0.0;
  const AdjustmentResult result = AdjustTrajectory(adjustment, f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_LT(after.rmse_horizontal_m, 0.5 * before.rmse_horizontal_m);
  EXPECT_LE(after.rmse_vertical_m, before.rmse_vertical_m + 0.005);
  // The process it settled on: a horizontal drift (no shrinkage: several
  // times the drift), no vertical one (the floor).
  EXPECT_GT(result.summary.position_sigma_m.x(), 0.1);
  EXPECT_LT(result.summary.position_sigma_m.z(), 0.06);

  // Believing the GNSS/INS no better than 1 m follows the database instead:
  // the test above can fail.
  adjustment.model.estimate_position_model = false;
  const AdjustmentResult blind = AdjustTrajectory(adjustment, f.Input());
  ASSERT_TRUE(blind.summary.IsUsable()) << blind.summary.message;
  const PoseErrors followed = ScorePoses(f.survey, blind.camera_poses);
  EXPECT_GT(followed.rmse_vertical_m, after.rmse_vertical_m + 0.005);
}

// Check crossings: held out of a first adjustment (their residuals), then
// control in the final one, which is then as good as with every crossing.
TEST(TrajectoryAdjuster, CheckCrossingsAreControlInTheFinalAdjustment) {
  const Fixture f = MakeFixture(KilometreOptions());
  AdjustmentOptions options;
  const AdjustmentResult final_result = AdjustTrajectory(options, f.Input());
  options.control.check_points_in_final = false;
  const AdjustmentResult held_out = AdjustTrajectory(options, f.Input());
  options.control.check_crossing_share = 0.0;
  const AdjustmentResult all = AdjustTrajectory(options, f.Input());
  ASSERT_TRUE(final_result.summary.IsUsable());
  ASSERT_TRUE(held_out.summary.IsUsable());
  ASSERT_TRUE(all.summary.IsUsable());
  EXPECT_TRUE(final_result.summary.check_points_in_final);
  EXPECT_FALSE(held_out.summary.check_points_in_final);
  // Same held-out residuals in both.
  EXPECT_NEAR(final_result.summary.check_rmse_horizontal_m,
              held_out.summary.check_rmse_horizontal_m, 1e-6);
  EXPECT_GT(final_result.summary.num_check_points, 0);
  const double e_final =
      ScorePoses(f.survey, final_result.camera_poses).rmse_horizontal_m;
  const double e_all = ScorePoses(f.survey, all.camera_poses).rmse_horizontal_m;
  EXPECT_NEAR(e_final, e_all, 0.002);
}

TEST(TrajectoryAdjuster, SelfCalibrationRecoversALeverArmError) {
  Fixture f = MakeFixture(KilometreOptions());
  // rig.yaml's left lever arm is 4 cm off the truth the data were made with.
  const Eigen::Vector3d truth =
      f.survey.rig.cameras[0].T_body_cam.translation();
  f.survey.rig.cameras[0].T_body_cam.translation() +=
      Eigen::Vector3d(0.0, 0.04, 0.0);
  AdjustmentOptions options;
  options.rig_calibration.self_calibrate_rig = true;
  options.rig_calibration.lever_arm_sigma_m = 0.05;
  const AdjustmentResult result = AdjustTrajectory(options, f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  ASSERT_EQ(result.T_body_cam.size(), 2u);
  // The stereo baseline is what the images measure: the error shrinks.
  EXPECT_LT((result.T_body_cam[0].translation() - truth).norm(), 0.8 * 0.04);
}

// Crossings 120 m apart, no tie points and a heading drift of 0.15 degrees:
// between the crossings the vehicle's direction of travel holds its heading.
TEST(TrajectoryAdjuster, VehicleMotionHoldsTheHeadingBetweenCrossings) {
  SyntheticSurveyOptions survey_options = KilometreOptions();
  survey_options.crossing_spacing_m = 120.0;
  survey_options.heading_drift_deg = 0.15;
  const Fixture f = MakeFixture(survey_options);
  // The constraint's effect on the heading itself: the significance test
  // (attitude_significance_test.cc) holds this heading correction, at 1.7
  // posterior sd, at the input's.
  AdjustmentOptions with;
  with.model.attitude_significance = 0.0;
  AdjustmentOptions without = with;
  without.vehicle_motion.sideslip_sigma_rad = 0.0;
  const AdjustmentResult a = AdjustTrajectory(without, f.Input());
  const AdjustmentResult b = AdjustTrajectory(with, f.Input());
  ASSERT_TRUE(a.summary.IsUsable()) << a.summary.message;
  ASSERT_TRUE(b.summary.IsUsable()) << b.summary.message;
  EXPECT_EQ(a.summary.num_vehicle_motion, 0);
  EXPECT_GT(b.summary.num_vehicle_motion, 900);
  const PoseErrors error_without = ScorePoses(f.survey, a.camera_poses);
  const PoseErrors error_with = ScorePoses(f.survey, b.camera_poses);
  // Heading error of the corrected samples.
  auto heading_rmse_deg = [&](const AdjustmentResult& r) {
    double sum = 0.0;
    for (size_t i = 0; i < r.corrected_samples.size(); ++i) {
      const double d =
          std::remainder(r.corrected_samples[i].attitude.heading -
                             f.survey.truth_samples[i].attitude.heading,
                         2.0 * M_PI);
      sum += d * d;
    }
    return std::sqrt(sum / r.corrected_samples.size()) * 180.0 / M_PI;
  };
  std::cout << "attitude " << error_without.rmse_attitude_deg << " -> "
            << error_with.rmse_attitude_deg << " deg, heading "
            << heading_rmse_deg(a) << " -> " << heading_rmse_deg(b)
            << " deg, horizontal " << error_without.rmse_horizontal_m << " -> "
            << error_with.rmse_horizontal_m << " m\n";
  // Without road lines the positions between crossings are interpolated,
  // so the direction of travel is only as good as they are: a modest gain
  // here (the presets, with lines, gain far more).
  EXPECT_LT(heading_rmse_deg(b), 0.9 * heading_rmse_deg(a));
  EXPECT_LT(error_with.rmse_attitude_deg, error_without.rmse_attitude_deg);
  EXPECT_LT(error_with.rmse_horizontal_m,
            1.15 * error_without.rmse_horizontal_m);
  // The synthetic INS sits on the axle, aligned with the vehicle. The
  // misalignment trades off with the INS's mean heading error (0.15 deg of
  // drift here); the constraints, counted once per second of sideslip
  // correlation rather than each at 10 Hz, hold it to a few hundredths.
  EXPECT_LT(std::abs(b.summary.vehicle_yaw_misalignment_deg), 0.03);
  EXPECT_LT(std::abs(b.summary.vehicle_axle_offset_m), 0.5);
  bool reported = false;
  for (const ObservationRms& rms : b.summary.rms) {
    if (rms.type != "vehicle_lateral_slip") continue;
    reported = true;
    EXPECT_LT(rms.after, rms.before);
  }
  EXPECT_TRUE(reported);
}

// SURVEY_FORMAT.md allows 10 Hz to 200 Hz. At 10 Hz the body's roll on its
// suspension (0.11 degrees at 1.5 Hz in the synthetic survey) changes the
// angular rate from one step to the next by about 0.1 degree: the motion
// of the vehicle, not a jump of the solution, and it must not be "removed".
TEST(TrajectoryAdjuster, TenHertzBodyOscillationIsNotAJump) {
  SyntheticSurveyOptions options = KilometreOptions();
  options.trajectory_rate_hz = 10.0;
  const Fixture f = MakeFixture(options);
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_EQ(result.summary.num_jumps, 0);
  const PoseErrors before = ScorePoses(f.survey, InputCameraPoses(f.survey));
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_LT(after.rmse_horizontal_m, 0.08);
  // Its heading correction is not significant (attitude_significance): the
  // attitude may stay the input's, never worse.
  EXPECT_LE(after.rmse_attitude_deg, before.rmse_attitude_deg + 1e-6);
}

// GNSS coming back after an outage: the solution steps by 0.2 m between two
// samples. The step is found and corrected as continuous INS motion.
TEST(TrajectoryAdjuster, GnssReturnJumpIsFoundAndBridged) {
  SyntheticSurveyOptions options = KilometreOptions();
  options.trajectory_rate_hz = 100.0;
  Fixture f = MakeFixture(options);
  std::vector<TrajectorySample> samples = f.survey.measured_samples;
  const double jump_time = samples[samples.size() / 2].time;
  for (TrajectorySample& sample : samples) {
    if (sample.time < jump_time) continue;
    // 0.2 m east, through the local frame.
    Eigen::Vector3d p = f.survey.frame.EnuFromGeodetic(sample.position);
    p.x() += 0.2;
    sample.position = f.survey.frame.GeodeticFromEnu(p);
  }
  f.trajectory = Trajectory(samples, f.survey.frame);
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable()) << result.summary.message;
  EXPECT_GE(result.summary.num_jumps, 1);
  EXPECT_LE(result.summary.num_jumps, 3);
  const PoseErrors after = ScorePoses(f.survey, result.camera_poses);
  EXPECT_LT(after.rmse_horizontal_m, 0.08);
}

TEST(TrajectoryAdjuster, WithoutControlReturnsTheInputTrajectoryAndWarns) {
  Fixture f = MakeFixture(KilometreOptions());
  f.survey.matches.clear();
  const AdjustmentResult result =
      AdjustTrajectory(AdjustmentOptions(), f.Input());
  ASSERT_TRUE(result.summary.IsUsable());
  ASSERT_FALSE(result.summary.warnings.empty());
  EXPECT_NE(result.summary.warnings[0].find("no control"), std::string::npos);
  const Trajectory measured(f.survey.measured_samples, f.survey.frame);
  ASSERT_EQ(result.corrected_poses.size(), measured.poses().size());
  for (size_t i = 0; i < measured.poses().size(); ++i) {
    EXPECT_LT(
        (result.corrected_poses[i].p_enu - measured.poses()[i].p_enu).norm(),
        1e-9);
  }
}

TEST(TrajectoryAdjuster, InvalidOptionsGiveAnUnusableSummaryNamingTheField) {
  const Fixture f = MakeFixture(KilometreOptions());
  AdjustmentOptions options;
  options.model.knot_spacing_s = -1.0;
  const AdjustmentResult result = AdjustTrajectory(options, f.Input());
  EXPECT_FALSE(result.summary.IsUsable());
  EXPECT_NE(result.summary.message.find("knot_spacing_s = -1"),
            std::string::npos);
  EXPECT_TRUE(result.camera_poses.empty());
}

TEST(AdjustmentOptions, CheckNamesFieldValueAndConstraint) {
  AdjustmentOptions options;
  EXPECT_EQ(options.Check(), "");
  options.control.check_crossing_share = 1.0;
  EXPECT_EQ(options.Check(),
            "control.check_crossing_share = 1: must be in [0, 1)");
  options = AdjustmentOptions();
  options.solver.num_threads = 0;
  EXPECT_EQ(options.Check(), "solver.num_threads = 0: must be >= 1");
  options = AdjustmentOptions();
  options.control.vertex_sigma_px = 0.0;
  EXPECT_EQ(options.Check(), "control.vertex_sigma_px = 0: must be > 0");
}

}  // namespace
}  // namespace zebrageo
