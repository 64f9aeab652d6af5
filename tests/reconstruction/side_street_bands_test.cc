// Issue 51: bands of crossings across a side street (their long sides
// along the epipolar lines, so monoplotted onto the local road surface)
// reconstructed from rendered images and scored against the truth, in the
// body frame with the true trajectory, as ../shared/tools/score_results.py
// and bench/rendered_sweep.py count them: a band is in view in an exposure
// when its four corners lie 5 px inside both images of the stereo pair and
// its centre within 15 m of the left camera; found when a band of that
// exposure has its centre within 0.3 m of it.
#include <glog/logging.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "reconstruction/reconstruction.h"
#include "simulator/simulated_survey.h"
#include "simulator/simulator.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"

namespace zebrageo {
namespace {

// The junctions preset (a wide-angle rig), a short street with one
// junction. Seed chosen for a side-street crossing on the right, set back
// little enough to be in full view within 15 m (most are not:
// docs/results.md, issue 51).
constexpr uint64_t kSeed = 30;

SimulationOptions SurveyOptions() {
  SimulationOptions options;
  CHECK_EQ(ApplyPreset("junctions", &options), "");
  options.seed = kSeed;
  options.road_length_m = 70.0;
  options.num_crossings = 1;
  options.num_junctions = 1;
  options.four_way_probability = 1.0;
  options.side_crossing_vehicle_probability = 0.0;
  options.exposure_spacing_m = 2.0;
  return options;
}

struct SideScore {
  int in_view_twice = 0;  // side-street bands in view in >= 2 exposures
  int found = 0;          // ... of them found in at least one
  int false_bands = 0;    // reported bands within 0.3 m of no truth band
  int side_vertices = 0;  // vertices of found side-street bands
  double side_sum_squares = 0.0;
  double side_worst_m = 0.0;
  // Vertex errors over their stated standard deviation along the error.
  double side_worst_normalised = 0.0;
  double Rmse() const {
    return std::sqrt(side_sum_squares / std::max(1, side_vertices));
  }
};

class SideStreetBands : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    folder_ = new std::string(
        (std::filesystem::temp_directory_path() /
         ("zebrageo-side-street-test-" + std::to_string(::getpid())))
            .string());
    const SimulationOptions options = SurveyOptions();
    ASSERT_EQ(options.Check(), "");
    SimulateSurvey(options, *folder_, nullptr);
  }
  static void TearDownTestSuite() {
    std::error_code ignored;
    std::filesystem::remove_all(*folder_, ignored);
    delete folder_;
  }
  static std::string* folder_;
};

std::string* SideStreetBands::folder_ = nullptr;

// The truth bands' corners in ENU, and whether each spans a side street.
struct TruthBands {
  std::vector<std::array<Eigen::Vector3d, 4>> corners_enu;
  std::vector<bool> side;
};

TruthBands ReadTruthBands(const Survey& survey) {
  SimulationOptions options = SurveyOptions();
  options.render_images = false;
  const sim::SimulatedSurvey simulated = sim::MakeSimulatedSurvey(options);
  std::set<std::string> side_ids;
  for (const sim::Crossing& c : simulated.world.crossings) {
    if (c.side_street >= 0) side_ids.insert(c.id);
  }
  const RoadmarkDatabase bands =
      ReadRoadmarks(survey.PathOf("truth/roadmarks.geojson"), "truth");
  TruthBands truth;
  for (const RoadmarkBand& band : bands.bands) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k) {
      c[k] = survey.frame.EnuFromGeodetic(band.corners[k]);
    }
    truth.corners_enu.push_back(c);
    truth.side.push_back(side_ids.count(band.crossing_id) > 0);
  }
  return truth;
}

Eigen::Isometry3d BodyFromEnuAt(const Trajectory& truth, double time) {
  Pose pose;
  CHECK(truth.InterpolatePose(time, &pose));
  return pose.T_enu_body().inverse();
}

SideScore ScoreSideBands(const Survey& survey,
                         const std::vector<ReconstructedVertex>& vertices) {
  const Trajectory trajectory(
      ReadTrajectorySamples(survey.PathOf("truth/trajectory.csv"), "truth"),
      survey.frame);
  const TruthBands truth = ReadTruthBands(survey);
  std::map<int64_t, double> time_of;
  for (const Exposure& e : survey.exposures.exposures) {
    time_of[e.exposure_id] = e.time;
  }
  std::map<int64_t, std::vector<const ReconstructedVertex*>> by_band;
  for (const ReconstructedVertex& v : vertices)
    by_band[v.band_id].push_back(&v);
  SideScore score;
  std::map<int64_t, std::set<int>> found;  // exposure -> truth bands
  for (const auto& [id, band] : by_band) {
    const Eigen::Isometry3d T_body_enu =
        BodyFromEnuAt(trajectory, time_of.at(band[0]->exposure_id));
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto* v : band) centre += v->p_body / band.size();
    int best = -1;
    double best_distance = 1e9;
    for (size_t b = 0; b < truth.corners_enu.size(); ++b) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : truth.corners_enu[b])
        c += T_body_enu * p / 4.0;
      if ((c - centre).norm() < best_distance) {
        best_distance = (c - centre).norm();
        best = static_cast<int>(b);
      }
    }
    if (best_distance > 0.3) {
      ++score.false_bands;
      continue;
    }
    found[band[0]->exposure_id].insert(best);
    if (!truth.side[best]) continue;
    for (const auto* v : band) {
      Eigen::Vector3d nearest = T_body_enu * truth.corners_enu[best][0];
      for (const Eigen::Vector3d& p : truth.corners_enu[best]) {
        if ((T_body_enu * p - v->p_body).norm() <
            (nearest - v->p_body).norm()) {
          nearest = T_body_enu * p;
        }
      }
      const Eigen::Vector3d error = v->p_body - nearest;
      score.side_sum_squares += error.squaredNorm();
      ++score.side_vertices;
      score.side_worst_m = std::max(score.side_worst_m, error.norm());
      if (error.norm() > 1e-9) {
        const Eigen::Vector3d u = error.normalized();
        const double sd = std::sqrt(u.dot(v->covariance_body * u));
        score.side_worst_normalised =
            std::max(score.side_worst_normalised, error.norm() / sd);
      }
    }
  }
  // In view in exposure e: whole in both images of pair 0, centre within
  // 15 m of the left camera.
  const Rig& rig = survey.rig;
  std::map<int, int> views;
  std::set<int> found_any;
  for (const Exposure& e : survey.exposures.exposures) {
    const Eigen::Isometry3d T_body_enu = BodyFromEnuAt(trajectory, e.time);
    for (size_t b = 0; b < truth.corners_enu.size(); ++b) {
      if (!truth.side[b]) continue;
      bool visible = true;
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : truth.corners_enu[b]) {
        centre += T_body_enu * p / 4.0;
      }
      for (int c : rig.stereo_pairs[0]) {
        const RigCamera& camera = rig.cameras[c];
        for (const Eigen::Vector3d& p : truth.corners_enu[b]) {
          const Eigen::Vector3d p_cam =
              camera.T_body_cam.inverse() * (T_body_enu * p);
          Eigen::Vector2d uv;
          visible = visible && p_cam.z() > 0.5 &&
                    camera.camera.Project(p_cam, &uv) && uv.x() >= 5 &&
                    uv.y() >= 5 && uv.x() <= camera.camera.width() - 5 &&
                    uv.y() <= camera.camera.height() - 5;
        }
      }
      const Eigen::Vector3d left_centre =
          rig.cameras[rig.stereo_pairs[0][0]].T_body_cam.translation();
      if (!visible || (centre - left_centre).norm() > 15.0) continue;
      ++views[static_cast<int>(b)];
      if (found[e.exposure_id].count(static_cast<int>(b))) {
        found_any.insert(static_cast<int>(b));
      }
    }
  }
  for (const auto& [b, n] : views) {
    if (n < 2) continue;
    ++score.in_view_twice;
    score.found += found_any.count(b);
  }
  return score;
}

// What the stage does today (seed 30: 4 of the 9 side-street bands in view
// in >= 2 exposures, vertex RMSE 9.5 cm, worst 23.7 cm, 12 stated sd; no
// false band), held so that it cannot get worse: at least 40 % of them
// reconstructed, vertices within 12 cm RMS (30 cm worst) of the truth, no
// false band. Issue 51 asks 90 % and 3 cm (within 10 m): not met yet.
TEST_F(SideStreetBands, InViewAreReconstructedWithoutAFalseBand) {
  SurveyLoadOptions load;
  load.load_roadmarks = false;
  const Survey survey = LoadSurvey(*folder_, load);
  ReconstructionOptions options;
  options.threads = 2;
  std::vector<ReconstructedVertex> vertices;
  const ReconstructionSummary summary =
      ReconstructSurvey(survey, options, &vertices);
  ASSERT_TRUE(summary.IsUsable()) << summary.message;
  const SideScore score = ScoreSideBands(survey, vertices);
  LOG(INFO) << "side-street bands in view >= 2 exposures: " << score.found
            << " of " << score.in_view_twice << " found, vertex RMSE "
            << score.Rmse() << " m (worst " << score.side_worst_m
            << " m, worst / sd " << score.side_worst_normalised
            << "), false bands " << score.false_bands;
  ASSERT_GE(score.in_view_twice, 3);
  EXPECT_GE(score.found, 0.4 * score.in_view_twice);
  EXPECT_EQ(score.false_bands, 0);
  EXPECT_GT(score.side_vertices, 0);
  EXPECT_LT(score.Rmse(), 0.12);
  EXPECT_LT(score.side_worst_m, 0.30);
}

}  // namespace
}  // namespace zebrageo
