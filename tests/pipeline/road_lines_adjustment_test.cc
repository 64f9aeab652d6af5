// AdjustByRoadLinesAlone (pipeline/adjustment_pass.h): the trajectory the road
// lines alone correct, on which the second registration pass searches when the
// adjustment had too few crossings. A synthetic survey drifting by a metre,
// two lane lines painted along its true path and drawn so in the database,
// their points reconstructed ideally from the true poses. And the report
// of a survey whose last stretch only road lines control (issue 51).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pipeline/adjust_outputs.h"
#include "pipeline/adjustment_pass.h"
#include "pipeline/report_stage.h"
#include "tests/support/synthetic_survey.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

// Lines at these distances left of the true path (metres), on the road 2 m
// below the body origin.
const std::vector<double> kLateralM = {-1.7, 1.8};
constexpr double kBelowBodyM = 2.0;

Eigen::Vector3d LeftOf(const Pose& pose) {
  const Eigen::Vector3d forward = pose.q_enu_body * Eigen::Vector3d::UnitX();
  const Eigen::Vector2d flat = forward.head<2>().normalized();
  return Eigen::Vector3d(-flat.y(), flat.x(), 0.0);
}

// The point of line `k` beside the true path at `time`; false outside it.
bool PaintedAt(const Trajectory& truth, int k, double time,
               Eigen::Vector3d* p_enu) {
  Pose pose;
  if (!truth.InterpolatePose(time, &pose)) return false;
  *p_enu = pose.p_enu + kLateralM[k] * LeftOf(pose) -
           kBelowBodyM * Eigen::Vector3d::UnitZ();
  return true;
}

// The database lines through the painted points, one per sample.
std::vector<RoadmarkLine> DatabaseLines(const SyntheticSurvey& survey) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  std::vector<RoadmarkLine> lines;
  for (size_t k = 0; k < kLateralM.size(); ++k) {
    RoadmarkLine line;
    line.id = "lane-" + std::to_string(k);
    line.type = "lane_solid";
    line.sigma_xy_m = 0.03;
    line.sigma_z_m = 0.03;
    for (const TrajectorySample& s : survey.truth_samples) {
      Eigen::Vector3d p;
      if (PaintedAt(truth, static_cast<int>(k), s.time, &p)) {
        line.points.push_back(survey.frame.GeodeticFromEnu(p));
      }
    }
    lines.push_back(line);
  }
  return lines;
}

// What the road-line stage would reconstruct: the painted points beside
// where the vehicle will be 0.5 to 1.1 s later (5 to 11 m ahead), exact in
// the body frame of the true pose.
std::vector<ReconstructedLinePoint> IdealLinePoints(
    const SyntheticSurvey& survey) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  std::vector<ReconstructedLinePoint> points;
  int64_t line_id = 0;
  for (const Exposure& e : survey.exposures.exposures) {
    Pose pose;
    if (!truth.InterpolatePose(e.time, &pose)) continue;
    for (int line = 0; line < static_cast<int>(kLateralM.size()); ++line) {
      ++line_id;
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector3d p_enu;
        if (!PaintedAt(truth, line, e.time + 0.5 + 0.2 * k, &p_enu)) continue;
        ReconstructedLinePoint p;
        p.exposure_id = e.exposure_id;
        p.line_id = line_id;
        p.type = RoadLineType::kLaneSolid;
        p.point = k;
        p.p_body = pose.q_enu_body.inverse() * (p_enu - pose.p_enu);
        p.covariance_body = Eigen::Matrix3d::Identity() * 1e-4;
        points.push_back(p);
      }
    }
  }
  return points;
}

// RMS along-track and cross-track error of `samples` against the truth.
Eigen::Vector2d TrackErrors(const SyntheticSurvey& survey,
                            const std::vector<TrajectorySample>& samples) {
  const Trajectory truth(survey.truth_samples, survey.frame);
  const Trajectory corrected(samples, survey.frame);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  for (const TrajectorySample& s : samples) {
    Pose true_pose, pose;
    if (!truth.InterpolatePose(s.time, &true_pose) ||
        !corrected.InterpolatePose(s.time, &pose)) {
      continue;
    }
    const Eigen::Vector3d d = pose.p_enu - true_pose.p_enu;
    const Eigen::Vector3d left = LeftOf(true_pose);
    const Eigen::Vector3d ahead(left.y(), -left.x(), 0.0);
    sum += Eigen::Vector2d(std::pow(d.dot(ahead), 2), std::pow(d.dot(left), 2));
    ++n;
  }
  return (sum / std::max(n, 1)).cwiseSqrt();
}

class RoadLinesAdjustmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticSurveyOptions options;
    options.num_exposures = 60;  // 180 m
    options.drift_horizontal_m = 1.0;
    options.drift_period_s = 30.0;
    survey_ = MakeSyntheticSurvey(options);
    data_.rig = survey_.rig;
    data_.frame = survey_.frame;
    data_.trajectory = Trajectory(survey_.measured_samples, survey_.frame);
    data_.exposures = survey_.exposures;
    data_.roadmarks = survey_.database;
    data_.roadmarks.lines = DatabaseLines(survey_);
    data_.vertices = survey_.vertices;
    // The zebra matches are left out whatever the data hold.
    data_.matches = survey_.matches;
    points_ = IdealLinePoints(survey_);
  }
  SyntheticSurvey survey_;
  AdjustmentData data_;
  std::vector<ReconstructedLinePoint> points_;
};

TEST_F(RoadLinesAdjustmentTest, CorrectsAcrossTheTrackAndKeepsAlongIt) {
  const std::optional<RoadLinesAdjustment> lines =
      AdjustByRoadLinesAlone(data_, &points_, AdjustmentOptions(), {});
  ASSERT_TRUE(lines.has_value());
  EXPECT_TRUE(lines->record.usable);
  EXPECT_TRUE(lines->record.road_lines_only);
  EXPECT_TRUE(lines->record.posterior_sd_computed);
  EXPECT_EQ(lines->record.counts.control_crossings, 0);
  ASSERT_EQ(lines->trajectory.size(), survey_.measured_samples.size());
  const Eigen::Vector2d before = TrackErrors(survey_, survey_.measured_samples);
  const Eigen::Vector2d after = TrackErrors(survey_, lines->trajectory);
  // Across the track, under a tenth of the second pass' 0.3 m gate (half
  // a band period is 0.5 m); along it, the input's error (no line holds it).
  EXPECT_GT(before.y(), 0.2);
  EXPECT_LT(after.y(), 0.03);
  EXPECT_NEAR(after.x(), before.x(), 0.02);
}

TEST_F(RoadLinesAdjustmentTest, NothingWithoutLinePointsOrWhenTurnedOff) {
  EXPECT_FALSE(AdjustByRoadLinesAlone(data_, nullptr, AdjustmentOptions(), {})
                   .has_value());
  const std::vector<ReconstructedLinePoint> none;
  EXPECT_FALSE(AdjustByRoadLinesAlone(data_, &none, AdjustmentOptions(), {})
                   .has_value());
  AdjustmentOptions off;
  off.road_lines.line_control_without_crossings = false;
  EXPECT_FALSE(AdjustByRoadLinesAlone(data_, &points_, off, {}).has_value());
  // A database without lines: nothing to correct with.
  data_.roadmarks.lines.clear();
  EXPECT_FALSE(AdjustByRoadLinesAlone(data_, &points_, AdjustmentOptions(), {})
                   .has_value());
}

// Crossings control the first 130 m of a 300 m survey, road lines alone
// the rest: they hold it across and in height, never along. The
// adjustment's posterior sd says so, and report.json names the stretch.
TEST(WeaklyHeldStretches, ReportNamesTheStretchWithoutAlongTrackControl) {
  SyntheticSurveyOptions options;
  options.num_exposures = 100;  // 300 m, crossings at 40, 120, 200, 280 m
  options.drift_horizontal_m = 1.0;
  options.drift_period_s = 30.0;
  const SyntheticSurvey survey = MakeSyntheticSurvey(options);
  std::vector<std::string> crossings;
  for (const RoadmarkBand& band : survey.database.bands) {
    if (crossings.empty() || crossings.back() != band.crossing_id) {
      crossings.push_back(band.crossing_id);
    }
  }
  ASSERT_GE(crossings.size(), 4u);
  const std::set<std::string> control = {crossings[0], crossings[1]};
  AdjustmentData data;
  data.rig = survey.rig;
  data.frame = survey.frame;
  data.trajectory = Trajectory(survey.measured_samples, survey.frame);
  data.exposures = survey.exposures;
  data.roadmarks = survey.database;
  data.roadmarks.lines = DatabaseLines(survey);
  data.vertices = survey.vertices;
  for (const VertexMatch& m : survey.matches) {
    if (control.count(m.crossing_id)) data.matches.push_back(m);
  }
  const std::vector<ReconstructedLinePoint> points = IdealLinePoints(survey);
  const AdjustmentOptions adjustment;
  const AdjustmentPass pass = AdjustWithRoadLines(
      data, data.Input(), adjustment, LineRegistrationOptions(), &points);
  ASSERT_TRUE(pass.result.summary.IsUsable()) << pass.result.summary.message;
  ASSERT_TRUE(pass.lines.has_value());
  const AdjustmentRecord record =
      AdjustmentRecordOf(data, adjustment, pass.result, nullptr);
  ASSERT_TRUE(record.posterior_sd_computed);

  TemporaryFolder folder;
  WriteSyntheticSurvey(survey, folder.Path("survey"), folder.Path("results"));
  WriteAdjustmentRecord(record, folder.Path("results/adjustment.json"));
  SurveyLoadOptions load_options;
  load_options.require_images = false;
  const Survey loaded = LoadSurvey(folder.Path("survey"), load_options);
  ReportInputs inputs;
  inputs.survey = &loaded;
  inputs.results_folder = folder.Path("results");
  const nlohmann::json report = BuildReport(inputs, ReportOptions());

  // The last control crossing lies 120 m in (t0 + 12 s); its bands are
  // seen up to 16 m ahead. From about 30 m past it to the end, along-track
  // is free.
  const double t0 = survey.measured_samples.front().time;
  const double t_end = survey.measured_samples.back().time;
  bool along_named = false;
  for (const nlohmann::json& s : report.at("weakly_held_stretches")) {
    const double begin = s.at("begin_time_s").get<double>();
    const double end = s.at("end_time_s").get<double>();
    const std::string axis = s.at("axis").get<std::string>();
    if (axis == "along_track" && end > t_end - 1.0) {
      along_named = true;
      EXPECT_GT(begin, t0 + 12.0);
      EXPECT_LT(begin, t0 + 17.0);
      EXPECT_GT(s.at("length_m").get<double>(), 130.0);
      EXPECT_TRUE(s.at("held_by_no_control").get<bool>());
      // With the adjustment's posterior sd there.
      EXPECT_GT(s.at("max_sd_m").get<double>(), 0.0);
      EXPECT_GE(s.at("max_sd_m").get<double>(),
                s.at("median_sd_m").get<double>());
    }
    // Road lines hold cross-track and height to the end.
    if (axis != "along_track") {
      EXPECT_LT(end, t0 + 25.0) << s.dump();
    }
    // The crossings hold every axis where they are.
    EXPECT_GT(begin, t0 + 10.0) << s.dump();
  }
  EXPECT_TRUE(along_named) << report.at("weakly_held_stretches").dump();
  bool warned = false;
  for (const nlohmann::json& w : report.at("warnings")) {
    warned = warned || w.get<std::string>().find(
                           "along-track position is held by no "
                           "control") != std::string::npos;
  }
  EXPECT_TRUE(warned) << report.at("warnings").dump();
}

}  // namespace
}  // namespace zebrageo
