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
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "reconstruction/reconstruction.h"
#include "simulator/simulated_survey.h"
#include "simulator/simulator.h"
#include "survey/option_json.h"
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

// One found side-street band vertex's error, split by what placed it: the
// error of the band plane's height (the vertex moved along its left ray
// off the true road) and the error in the image (the vertex's ray cut with
// the true road: along the long side, the band end's; across it, the long
// side's).
struct VertexError {
  int64_t exposure_id = 0;
  int64_t band_id = 0;
  int vertex = 0;
  double range_m = 0.0;   // from the left camera
  double error_m = 0.0;   // |reconstructed - truth|
  double height_m = 0.0;  // signed, along the true road's normal
  double ray_m = 0.0;     // the height error's shift along the ray
  double end_m = 0.0;     // image part along the long side
  double side_m = 0.0;    // image part across the long side
  double side_px = 0.0;   // left image error across the long side (px)
  double sd_m = 0.0;      // stated sd along the error
  double sd_end_m = 0.0;  // stated sd along / across the long side
  double sd_side_m = 0.0;
  double Normalised() const { return error_m / sd_m; }
};

struct SideScore {
  std::vector<VertexError> side_errors;
  std::vector<VertexError> road_errors;  // bands across the road driven
  // Truth band -> the exposures it is in view in (range, where, found).
  std::map<int, std::string> views_of;
  std::vector<int> missed;  // in view in >= 2 exposures, never found
  int in_view_twice = 0;    // side-street bands in view in >= 2 exposures
  int found = 0;            // ... of them found in at least one
  int false_bands = 0;      // reported bands within 0.3 m of no truth band
  int side_vertices = 0;    // vertices of found side-street bands
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
    // A survey simulated beforehand with the same options (zebrageo
    // simulate --preset junctions --seed 30 --set ...) spares the 50 s of
    // rendering when measuring.
    if (const char* given = std::getenv("ZEBRAGEO_SIDE_STREET_SURVEY")) {
      folder_ = new std::string(given);
      owned_ = false;
      return;
    }
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
    if (owned_) std::filesystem::remove_all(*folder_, ignored);
    delete folder_;
  }
  static std::string* folder_;
  static bool owned_;
};

std::string* SideStreetBands::folder_ = nullptr;
bool SideStreetBands::owned_ = true;

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

VertexError SplitVertexError(const Rig& rig,
                             const Eigen::Isometry3d& T_body_enu,
                             const std::array<Eigen::Vector3d, 4>& corners_enu,
                             const Eigen::Vector3d& truth_body,
                             const ReconstructedVertex& v) {
  std::array<Eigen::Vector3d, 4> c;
  for (int k = 0; k < 4; ++k) c[k] = T_body_enu * corners_enu[k];
  const Eigen::Vector3d normal = (c[2] - c[0]).cross(c[3] - c[1]).normalized();
  Eigen::Vector3d long_dir = c[1] - c[0];
  if ((c[2] - c[1]).norm() > long_dir.norm()) long_dir = c[2] - c[1];
  long_dir = (long_dir - long_dir.dot(normal) * normal).normalized();
  const Eigen::Vector3d across = normal.cross(long_dir);
  const Eigen::Vector3d centre =
      rig.cameras[rig.stereo_pairs[0][0]].T_body_cam.translation();
  const Eigen::Vector3d ray = (v.p_body - centre).normalized();
  // The vertex's ray cut with the true road.
  const Eigen::Vector3d on_road =
      centre + ray * (normal.dot(truth_body - centre) / normal.dot(ray));
  VertexError out;
  out.exposure_id = v.exposure_id;
  out.band_id = v.band_id;
  out.vertex = v.vertex;
  out.range_m = (truth_body - centre).norm();
  const Eigen::Vector3d error = v.p_body - truth_body;
  out.error_m = error.norm();
  out.height_m = normal.dot(error);
  out.ray_m = (v.p_body - on_road).norm();
  out.end_m = long_dir.dot(on_road - truth_body);
  const RigCamera& left = rig.cameras[rig.stereo_pairs[0][0]];
  Eigen::Vector2d t0, t1, uv;
  if (left.camera.Project(left.T_body_cam.inverse() * truth_body, &t0) &&
      left.camera.Project(
          left.T_body_cam.inverse() * (truth_body + 0.1 * long_dir), &t1) &&
      left.camera.Project(left.T_body_cam.inverse() * v.p_body, &uv)) {
    const Eigen::Vector2d d = (t1 - t0).normalized();
    out.side_px = Eigen::Vector2d(-d.y(), d.x()).dot(uv - t0);
  }
  out.side_m = across.dot(on_road - truth_body);
  const Eigen::Vector3d u =
      out.error_m > 1e-9 ? Eigen::Vector3d(error / out.error_m) : normal;
  out.sd_m = std::sqrt(u.dot(v.covariance_body * u));
  out.sd_end_m = std::sqrt(long_dir.dot(v.covariance_body * long_dir));
  out.sd_side_m = std::sqrt(across.dot(v.covariance_body * across));
  return out;
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
    for (const auto* v : band) {
      Eigen::Vector3d nearest = T_body_enu * truth.corners_enu[best][0];
      for (const Eigen::Vector3d& p : truth.corners_enu[best]) {
        if ((T_body_enu * p - v->p_body).norm() <
            (nearest - v->p_body).norm()) {
          nearest = T_body_enu * p;
        }
      }
      if (!truth.side[best]) {
        score.road_errors.push_back(SplitVertexError(
            survey.rig, T_body_enu, truth.corners_enu[best], nearest, *v));
        continue;
      }
      const Eigen::Vector3d error = v->p_body - nearest;
      score.side_errors.push_back(SplitVertexError(
          survey.rig, T_body_enu, truth.corners_enu[best], nearest, *v));
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
      std::ostringstream view;
      view << " " << e.exposure_id << " (" << (centre - left_centre).norm()
           << " m, " << centre.x() << " ahead, " << centre.y() << " aside"
           << (found[e.exposure_id].count(static_cast<int>(b)) ? ", found" : "")
           << ")";
      score.views_of[static_cast<int>(b)] += view.str();
      if (found[e.exposure_id].count(static_cast<int>(b))) {
        found_any.insert(static_cast<int>(b));
      }
    }
  }
  for (const auto& [b, n] : views) {
    if (n < 2) continue;
    ++score.in_view_twice;
    score.found += found_any.count(b);
    if (!found_any.count(b)) score.missed.push_back(b);
  }
  return score;
}

// The vertex errors' RMSE over those within [low, high) metres of the left
// camera, and their count.
double RangeRmse(const std::vector<VertexError>& errors, double low,
                 double high, int* count) {
  double sum = 0.0;
  *count = 0;
  for (const VertexError& e : errors) {
    if (e.range_m < low || e.range_m >= high) continue;
    sum += e.error_m * e.error_m;
    ++*count;
  }
  return std::sqrt(sum / std::max(1, *count));
}

// The median of the errors over their stated sd along them (0.67 for an
// honest Gaussian covariance, 3-dimensional errors: 1.54; the monoplotted
// vertices' errors lie mostly along one direction, across the long side).
double MedianNormalised(const std::vector<VertexError>& errors) {
  std::vector<double> n;
  for (const VertexError& e : errors) n.push_back(e.Normalised());
  if (n.empty()) return 0.0;
  std::nth_element(n.begin(), n.begin() + n.size() / 2, n.end());
  return n[n.size() / 2];
}

// Seed 30, before issue 51's fourth part (the local height from the band's
// own ends, 0.3 m around; the covariance the height sd along the ray):
// 4 of the 9 side-street bands in view in >= 2 exposures, vertex RMSE
// 9.5 cm, worst 23.7 cm at 12.2 stated sd. With the height from the
// neighbouring bands' ends (3 m around) and the edge's localisation in the
// covariance: 6 of 9, RMSE 4.2 cm, worst 10.2 cm at 2.4 sd, median 0.68 sd
// (docs/results.md). Held with some margin; issue 51 asks 90 % and 3 cm
// within 10 m (only the nearest vertices of these bands are within 10 m).
TEST_F(SideStreetBands, InViewAreReconstructedWithoutAFalseBand) {
  SurveyLoadOptions load;
  load.load_roadmarks = false;
  const Survey survey = LoadSurvey(*folder_, load);
  ReconstructionOptions options;
  options.threads = 2;
  if (const char* json = std::getenv("ZEBRAGEO_SIDE_STREET_OPTIONS")) {
    options = OptionsFromJson(nlohmann::json::parse(json), options);
  }
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
  for (const VertexError& e : score.side_errors) {
    LOG(INFO) << "exposure " << e.exposure_id << " band " << e.band_id
              << " vertex " << e.vertex << " range " << e.range_m << " error "
              << e.error_m << " (height " << e.height_m << " -> along ray "
              << e.ray_m << ", end " << e.end_m << ", side " << e.side_m << ", "
              << e.side_px << " px) stated sd " << e.sd_m << " (end "
              << e.sd_end_m << ", side " << e.sd_side_m << ") normalised "
              << e.Normalised();
  }
  for (const auto& [b, views] : score.views_of) {
    LOG(INFO) << "side-street band " << b
              << (std::count(score.missed.begin(), score.missed.end(), b)
                      ? " never found"
                      : "")
              << ", in view in" << views;
  }
  for (const auto& [low, high] : {std::pair<double, double>{0.0, 10.0},
                                  {10.0, 12.0},
                                  {12.0, 15.0},
                                  {15.0, 100.0}}) {
    int count = 0;
    const double rmse = RangeRmse(score.side_errors, low, high, &count);
    LOG(INFO) << "vertices at " << low << "-" << high << " m: " << count
              << ", RMSE " << rmse << " m";
  }
  const double median_normalised = MedianNormalised(score.side_errors);
  LOG(INFO) << "median error / stated sd " << median_normalised;
  // The control: bands across the road driven (triangulated long sides).
  double road_worst = 0.0;
  for (const VertexError& e : score.road_errors) {
    road_worst = std::max(road_worst, e.Normalised());
  }
  int road_count = 0;
  const double road_rmse =
      RangeRmse(score.road_errors, 0.0, 100.0, &road_count);
  int road_near = 0;
  const double road_near_rmse =
      RangeRmse(score.road_errors, 0.0, 10.0, &road_near);
  LOG(INFO) << "road-driven band vertices: " << road_count << ", RMSE "
            << road_rmse << " m (" << road_near
            << " within 10 m: " << road_near_rmse << " m), median error / sd "
            << MedianNormalised(score.road_errors) << ", worst " << road_worst;
  ASSERT_GE(score.in_view_twice, 3);
  EXPECT_GE(score.found, 0.6 * score.in_view_twice);
  EXPECT_EQ(score.false_bands, 0);
  EXPECT_GE(score.side_vertices, 20);
  EXPECT_LT(score.Rmse(), 0.05);
  EXPECT_LT(score.side_worst_m, 0.12);
  // An honest covariance: the worst vertex within 3.5 stated sd, the median
  // near a Gaussian's 0.67 (neither much too optimistic nor too careful).
  EXPECT_LT(score.side_worst_normalised, 3.5);
  EXPECT_GT(median_normalised, 0.45);
  EXPECT_LT(median_normalised, 1.0);
}

}  // namespace
}  // namespace zebrageo
