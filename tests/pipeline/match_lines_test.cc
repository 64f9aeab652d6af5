// The road lines registered to the database (registration/
// line_registration.h) against a simulated survey's truth: a vehicle
// driving east between painted lane lines, the reconstructed line points
// exactly where the true trajectory puts them, one database line drawn
// 25 cm away from its paint (repainted).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/adjustment_pass.h"
#include "registration/line_registration.h"
#include "survey/results_lines.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

// The registration on `zebra`'s trajectory, its files written into
// `folder` as the adjust stage writes them (nothing when it is "").
std::vector<LineControlPoint> MatchLinesForAdjustment(
    const AdjustmentData& data, const AdjustmentOptions& options,
    const LineRegistrationOptions& registration, const AdjustmentResult& zebra,
    const std::vector<ReconstructedLinePoint>* points,
    const std::string& folder, std::vector<std::string>* warnings) {
  if (points == nullptr) return {};
  LineRegistration lines = RegisterRoadLines(
      *points, LineRegistrationInputOf(data, options, zebra), registration);
  warnings->insert(warnings->end(), lines.warnings.begin(),
                   lines.warnings.end());
  if (!folder.empty() && lines.record) {
    WriteLineMatches(lines.rows, folder + "/" + kLineMatchesFile);
    WriteLineControl(*lines.record, folder + "/" + kLineControlFile);
  }
  return lines.control;
}

constexpr double kSpeedMps = 10.0;
constexpr double kCameraHeightM = 2.0;

// The true pose at `time`, heading east: body (FRD) x forward = east, y
// right = south, z down.
Pose TruePose(double time) {
  Pose pose;
  pose.p_enu = Eigen::Vector3d(kSpeedMps * time, 0.0, kCameraHeightM);
  pose.q_enu_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  return pose;
}

struct PaintedLine {
  std::string id;
  std::string type;
  double north_m;           // where it is painted
  double database_north_m;  // where the database draws it
};

class MatchLinesForAdjustmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    lines_ = {{"L1", "lane_solid", 1.75, 1.75},
              {"L2", "lane_dashed", -1.75, -1.75},
              {"L3", "lane_solid", 5.25, 5.25},
              {"stale", "lane_solid", -5.0, -5.25}};
    data_.frame = LocalFrame(Geodetic{48.85, 2.35, 50.0});
    for (const PaintedLine& line : lines_) {
      RoadmarkLine db;
      db.id = line.id;
      db.type = line.type;
      db.sigma_xy_m = 0.03;
      db.sigma_z_m = 0.03;
      for (double east = -20.0; east <= 260.0; east += 20.0) {
        db.points.push_back(data_.frame.GeodeticFromEnu(
            Eigen::Vector3d(east, line.database_north_m, 0.0)));
      }
      data_.roadmarks.lines.push_back(db);
    }
    // The zebra-corrected trajectory is the truth, its posterior sd 2 cm.
    zebra_.summary.corrected = true;
    for (int i = 0; i <= 220; ++i) {
      TrajectorySample sample;
      sample.time = 0.1 * i;
      sample.sd_enu_m = Eigen::Vector3d(0.02, 0.02, 0.02);
      zebra_.corrected_samples.push_back(sample);
      zebra_.corrected_poses.push_back(TruePose(sample.time));
    }
    // One exposure every 0.5 s; each sees every line from 4 to 12 m ahead.
    std::vector<ReconstructedLinePoint>& points = points_;
    int64_t line_id = 0;
    for (int e = 0; e < 40; ++e) {
      Exposure exposure;
      exposure.exposure_id = 1000 + e;
      exposure.time = 0.5 * e;
      data_.exposures.exposures.push_back(exposure);
      const Pose pose = TruePose(exposure.time);
      for (const PaintedLine& line : lines_) {
        ++line_id;
        for (int k = 0; k < 5; ++k) {
          const Eigen::Vector3d p_enu(pose.p_enu.x() + 4.0 + 2.0 * k,
                                      line.north_m, 0.0);
          ReconstructedLinePoint p;
          p.exposure_id = exposure.exposure_id;
          p.line_id = line_id;
          p.type = line.type == "lane_dashed" ? RoadLineType::kLaneDashed
                                              : RoadLineType::kLaneSolid;
          p.point = k;
          p.p_body = pose.T_enu_body().inverse() * p_enu;
          p.covariance_body = Eigen::Matrix3d::Identity() * 1e-4;
          points.push_back(p);
        }
      }
    }
    points_per_line_ = 40 * 5;
  }

  std::vector<PaintedLine> lines_;
  AdjustmentData data_;
  AdjustmentResult zebra_;
  std::vector<ReconstructedLinePoint> points_;
  TemporaryFolder folder_;
  int points_per_line_ = 0;
};

TEST_F(MatchLinesForAdjustmentTest, ControlLiesOnThePaintAndTheStaleLineIsOut) {
  std::vector<std::string> warnings;
  const std::vector<LineControlPoint> control =
      MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_, &points_,
                              folder_.Path(), &warnings);

  // Nearly every point of the three true lines is control (the database
  // lines are long enough for all of them).
  EXPECT_GE(static_cast<int>(control.size()), 3 * points_per_line_ * 9 / 10);
  EXPECT_LE(static_cast<int>(control.size()), 3 * points_per_line_);
  for (const LineControlPoint& c : control) {
    // The point placed with the true pose lies on its database line: across
    // the line within 1 mm, at the database's height.
    const Eigen::Vector3d p_enu = TruePose(c.time).T_enu_body() * c.p_body;
    EXPECT_NEAR((p_enu - c.db_point_enu).dot(c.across_enu), 0.0, 1e-3);
    EXPECT_NEAR(p_enu.z() - c.db_point_enu.z(), 0.0, 1e-3);
    // Lane lines run with the vehicle: across them is cross-track (north).
    EXPECT_NEAR(std::abs(c.across_enu.y()), 1.0, 1e-6);
    EXPECT_GT(c.sqrt_information.row(0).norm(), 0.0);
    // Never the stale line's paint (5 m right of the vehicle).
    EXPECT_GT(p_enu.y(), -4.0);
  }
  ASSERT_FALSE(warnings.empty());
  EXPECT_THAT(warnings.back(), HasSubstr("road line stale (lane_solid)"));

  // The files of the contract say the same.
  const std::vector<LineMatch> rows =
      ReadLineMatches(folder_.Path(kLineMatchesFile), kLineMatchesFile);
  EXPECT_EQ(rows.size(), control.size());
  for (const LineMatch& row : rows) EXPECT_NE(row.db_line, "stale");
  const LineControlRecord summary =
      ReadLineControl(folder_.Path(kLineControlFile), kLineControlFile);
  EXPECT_EQ(summary.reconstructed_points, 4 * points_per_line_);
  EXPECT_EQ(summary.used_points, static_cast<int64_t>(control.size()));
  ASSERT_EQ(summary.rejected_lines.size(), 1u);
  EXPECT_EQ(summary.rejected_lines[0].db_line, "stale");
  EXPECT_NEAR(std::abs(summary.rejected_lines[0].offset_m), 0.25, 0.02);
  ASSERT_FALSE(summary.stretches.empty());
  EXPECT_GT(summary.stretches[0].cross_track_points, 0);
}

// No zebra crossing corrected the trajectory, which is 1.6 m off to the
// right: nearer the next line than its own for a nearest-line match (the
// lanes are 3.5 m wide). The lines voting together find the offset, and
// every control point lies on the line it was painted as.
TEST_F(MatchLinesForAdjustmentTest, WithoutZebraControlTheLinesFindTheOffset) {
  zebra_.summary.corrected = false;
  for (Pose& pose : zebra_.corrected_poses) pose.p_enu.y() -= 1.6;
  std::vector<std::string> warnings;
  const std::vector<LineControlPoint> control =
      MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_, &points_,
                              folder_.Path(), &warnings);
  EXPECT_GE(static_cast<int>(control.size()), 3 * points_per_line_ * 8 / 10);
  for (const LineControlPoint& c : control) {
    const Eigen::Vector3d p_enu = TruePose(c.time).T_enu_body() * c.p_body;
    EXPECT_NEAR((p_enu - c.db_point_enu).dot(c.across_enu), 0.0, 1e-3);
    EXPECT_GT(p_enu.y(), -4.0);  // never the stale line
  }
}

// A dashed line 5.25 m to the left drawn dash by dash (3 m every 8 m), seen
// from every exposure between 4 and 12 m ahead: a dash inside that range is
// whole, its ends reconstructed 5 cm inside the painted ones (at half
// contrast, reconstruction/road_lines.h); one cut by the range by a metre
// or more is shorter. Returns how many whole dashes were seen.
int AddDashes(AdjustmentData* data, std::vector<ReconstructedLinePoint>* points,
              double north_m) {
  for (double east = 0.0; east < 260.0; east += 8.0) {
    RoadmarkLine db;
    db.id = "dash-" + std::to_string(static_cast<int>(east));
    db.type = "lane_dashed";
    db.sigma_xy_m = 0.03;
    db.sigma_z_m = 0.03;
    for (double x : {east, east + 3.0}) {
      db.points.push_back(
          data->frame.GeodeticFromEnu(Eigen::Vector3d(x, north_m, 0.0)));
    }
    data->roadmarks.lines.push_back(db);
  }
  int whole = 0;
  int64_t line_id = 100000;
  for (const Exposure& exposure : data->exposures.exposures) {
    const Pose pose = TruePose(exposure.time);
    const double near = pose.p_enu.x() + 4.0, far = pose.p_enu.x() + 12.0;
    for (double east = 0.0; east < 260.0; east += 8.0) {
      const double start = std::max(east, near);
      const double end = std::min(east + 3.0, far);
      const double cut = (start - east) + (east + 3.0 - end);
      if (end - start < 1.0 || (cut > 0.0 && cut < 1.0)) continue;
      if (cut == 0.0) ++whole;
      const double a = start + (start == east ? 0.05 : 0.0);
      const double b = end - (end == east + 3.0 ? 0.05 : 0.0);
      ++line_id;
      for (int k = 0; k < 4; ++k) {
        ReconstructedLinePoint p;
        p.exposure_id = exposure.exposure_id;
        p.line_id = line_id;
        p.type = RoadLineType::kLaneDashed;
        p.point = k;
        p.p_body = pose.T_enu_body().inverse() *
                   Eigen::Vector3d(a + (b - a) * k / 3.0, north_m, 0.0);
        p.covariance_body = Eigen::Matrix3d::Identity() * 1e-4;
        points->push_back(p);
      }
    }
  }
  return whole;
}

// Whole dashes hold the along-track position: one control point at each
// whole dash's centre, on its database dash's centre along the dash; cut
// dashes give none; the files say so.
TEST_F(MatchLinesForAdjustmentTest, WholeDashesControlTheAlongTrackPosition) {
  const int whole = AddDashes(&data_, &points_, 5.25 + 3.5);
  ASSERT_GT(whole, 20);
  std::vector<std::string> warnings;
  const std::vector<LineControlPoint> control =
      MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_, &points_,
                              folder_.Path(), &warnings);
  int along = 0;
  for (const LineControlPoint& c : control) {
    if (!c.along_track) continue;
    ++along;
    // The centre placed with the true pose lies on the database dash's
    // centre along the dash (east), whatever the inset of its ends.
    const Eigen::Vector3d p_enu = TruePose(c.time).T_enu_body() * c.p_body;
    EXPECT_NEAR(std::abs(c.across_enu.x()), 1.0, 1e-6);
    EXPECT_NEAR((p_enu - c.db_point_enu).dot(c.across_enu), 0.0, 1e-3);
    // Along only: the height is the dash points' to hold.
    EXPECT_GT(c.sqrt_information(0, 0), 0.0);
    EXPECT_EQ(c.sqrt_information.row(1).norm(), 0.0);
  }
  EXPECT_EQ(along, whole);
  int rows = 0;
  for (const LineMatch& row :
       ReadLineMatches(folder_.Path(kLineMatchesFile), kLineMatchesFile)) {
    if (!row.along) continue;
    ++rows;
    EXPECT_EQ(row.point, -1);
    EXPECT_NEAR(row.distance_m, 0.0, 1e-3);
  }
  EXPECT_EQ(rows, whole);
  int stretch_points = 0;
  for (const LineControlStretch& s :
       ReadLineControl(folder_.Path(kLineControlFile), kLineControlFile)
           .stretches) {
    stretch_points += s.along_track_points;
  }
  EXPECT_EQ(stretch_points, whole);
}

// The zebra-corrected trajectory 0.5 m behind along the track, its
// posterior sd 2 cm: a dash that far from where it says is not matched
// (its gate is 0.3 m); nor without zebra control at all.
TEST_F(MatchLinesForAdjustmentTest, NoDashOutsideTheAlongTrackGate) {
  AddDashes(&data_, &points_, 5.25 + 3.5);
  for (Pose& pose : zebra_.corrected_poses) pose.p_enu.x() -= 0.5;
  std::vector<std::string> warnings;
  for (const LineControlPoint& c :
       MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_, &points_,
                               folder_.Path(), &warnings)) {
    EXPECT_FALSE(c.along_track);
  }
  zebra_.summary.corrected = false;
  for (Pose& pose : zebra_.corrected_poses) pose.p_enu.x() += 0.5;
  for (const LineControlPoint& c :
       MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_, &points_,
                               folder_.Path(), &warnings)) {
    EXPECT_FALSE(c.along_track);
  }
}

// A crossing's near edge seen from the exposure at 9 s (the bands of
// 3 m from east 100, across north -2.5..2.5; seen 0.2 m east of where the
// database draws it): along-track control across the edge, unless the
// zebra front-end reconstructed the crossing's bands (it is control, or
// was refused) or the paint is on the wrong side.
TEST_F(MatchLinesForAdjustmentTest, ACrossingsEdgeControlsAlongTheTrack) {
  for (int b = 0; b < 5; ++b) {
    RoadmarkBand band;
    band.crossing_id = "Z1";
    band.band = b + 1;
    band.sigma_xy_m = 0.05;
    band.sigma_z_m = 0.1;
    const double n0 = 2.0 - b, n1 = n0 + 0.5;
    const Eigen::Vector3d corners[4] = {
        {100, n0, 0}, {103, n0, 0}, {103, n1, 0}, {100, n1, 0}};
    for (int k = 0; k < 4; ++k) {
      band.corners[k] = data_.frame.GeodeticFromEnu(corners[k]);
    }
    data_.roadmarks.bands.push_back(band);
  }
  const Pose pose = TruePose(9.0);
  // The paint is east of the near edge: running south, it is on the left.
  auto edge = [&](bool paint_on_the_left) {
    std::vector<ReconstructedLinePoint> points;
    for (int b = 0; b < 4; ++b) {
      ReconstructedLinePoint p;
      p.exposure_id = 1018;
      p.line_id = 9000;
      p.type = RoadLineType::kCrossingEdge;
      p.point = b;
      const double north = paint_on_the_left ? 2.25 - b : -0.75 + b;
      p.p_body = pose.T_enu_body().inverse() * Eigen::Vector3d(100.2, north, 0);
      p.covariance_body = Eigen::Matrix3d::Identity() * 1e-4;
      points.push_back(p);
    }
    return points;
  };
  auto edge_control = [&](const std::vector<ReconstructedLinePoint>& points) {
    std::vector<std::string> warnings;
    std::vector<LineControlPoint> along;
    for (const LineControlPoint& c : MatchLinesForAdjustment(
             data_, AdjustmentOptions(), {}, zebra_, &points, "", &warnings)) {
      if (c.along_track) along.push_back(c);
    }
    return along;
  };
  const std::vector<LineControlPoint> control = edge_control(edge(true));
  ASSERT_EQ(control.size(), 4u);
  for (const LineControlPoint& c : control) {
    EXPECT_NEAR(c.across_enu.x(), 1.0, 1e-6);
    EXPECT_NEAR(c.across_enu.dot(pose.T_enu_body() * c.p_body - c.db_point_enu),
                0.2, 1e-6);
    // At most what the database's sd allows for the whole edge.
    EXPECT_LT(c.sqrt_information(0, 0), 1.0 / (0.05 * std::sqrt(4.0)) + 1e-9);
    EXPECT_EQ(c.sqrt_information(1, 0), 0.0);
    EXPECT_EQ(c.sqrt_information(1, 1), 0.0);
  }
  EXPECT_TRUE(edge_control(edge(false)).empty());
  // Its bands reconstructed (from the exposure at 8.5 s): left out.
  ReconstructedVertex vertex;
  vertex.exposure_id = 1017;
  vertex.p_body =
      TruePose(8.5).T_enu_body().inverse() * Eigen::Vector3d(101.0, 0.25, 0);
  data_.vertices.push_back(vertex);
  EXPECT_TRUE(edge_control(edge(true)).empty());
}

TEST_F(MatchLinesForAdjustmentTest, NothingWithoutReconstructedLines) {
  std::vector<std::string> warnings;
  EXPECT_TRUE(MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_,
                                      nullptr, folder_.Path(), &warnings)
                  .empty());
  EXPECT_TRUE(warnings.empty());
  EXPECT_FALSE(std::filesystem::exists(folder_.Path(kLineMatchesFile)));
}

TEST_F(MatchLinesForAdjustmentTest, ADatabaseWithoutLinesIsAWarning) {
  data_.roadmarks.lines.clear();
  std::vector<std::string> warnings;
  EXPECT_TRUE(MatchLinesForAdjustment(data_, AdjustmentOptions(), {}, zebra_,
                                      &points_, folder_.Path(), &warnings)
                  .empty());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("no lines"));
}

}  // namespace
}  // namespace zebrageo
