#include "pipeline/match_stage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "pipeline/rematch_stage.h"
#include "pipeline/stage_results.h"
#include "registration/observations.h"
#include "survey/input_error.h"
#include "survey/results_adjustment.h"
#include "survey/survey.h"
#include "tests/registration/synthetic_scene.h"

namespace zebrageo {
namespace {

// The match stage on a results folder (pipeline/match_stage.h), its matches
// and decisions as it left them.
MatchResult RunMatchStage(const Survey& survey, const std::string& folder,
                          const MatchOptions& options) {
  StageResults results(folder);
  RunOptions run;
  run.matching = options;
  MatchResult result;
  result.summary = zebrageo::RunMatchStage(survey, &results, run);
  result.matches = results.Matches();
  result.decisions = results.Decisions();
  return result;
}

// `zebrageo match --second-pass` on a results folder
// (pipeline/rematch_stage.h).
RematchSummary RematchWithAdjustedTrajectory(const Survey& survey,
                                             const std::string& folder,
                                             const MatchOptions& matching,
                                             const RematchOptions& rematch) {
  StageResults results(folder);
  RunOptions run;
  run.matching = matching;
  run.second_pass = rematch;
  return RunRematchStage(survey, &results, run);
}

namespace fs = std::filesystem;

class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::random_device device;
    path_ = fs::temp_directory_path() /
            ("zebrageo-match-" + std::to_string(device()));
    fs::create_directories(path_);
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string Path(const std::string& name) const {
    return (path_ / name).string();
  }

 private:
  fs::path path_;
};

// Writes `scene` as a survey folder (the measured trajectory, empty image
// files) and its observations as reconstructed_bands.csv in `results`.
void WriteSceneSurvey(const SyntheticScene& scene, const std::string& survey,
                      const std::string& results) {
  fs::create_directories(survey + "/images");
  fs::create_directories(results);
  WriteRig(scene.rig, survey + "/rig.yaml");
  std::vector<TrajectorySample> samples;
  ExposureTable table;
  for (const ExposurePose& e : scene.exposures) {
    samples.push_back(SampleFromPose(e.time_s, e.pose, scene.frame,
                                     Eigen::Vector3d::Constant(0.05),
                                     Eigen::Vector3d::Constant(0.001)));
    for (int camera = 0; camera < 2; ++camera) {
      ExposureImage image;
      image.exposure_id = e.exposure_id;
      image.time = e.time_s;
      image.camera = camera;
      image.image = "images/" + std::to_string(e.exposure_id) + "_" +
                    std::to_string(camera) + ".png";
      std::ofstream(survey + "/" + image.image) << "";
      table.images.push_back(image);
    }
  }
  WriteTrajectorySamples(samples, survey + "/trajectory.csv");
  WriteExposures(table, scene.rig, survey + "/exposures.csv");
  WriteRoadmarks(scene.database, survey + "/roadmarks.geojson");
  SurveyManifest manifest;
  manifest.name = "synthetic";
  manifest.origin = scene.frame.origin();
  WriteManifest(manifest, survey + "/survey.yaml");
  std::vector<ReconstructedVertex> vertices;
  for (const CrossingObservation& obs : scene.observations) {
    for (const ObservedBand& band : obs.bands) {
      for (int k = 0; k < 4; ++k) {
        ReconstructedVertex v;
        v.exposure_id = obs.exposure_id;
        v.pair = band.pair;
        v.band_id = band.band_id;
        v.group_id = obs.group_id;
        v.vertex = band.vertex[k];
        v.p_body = band.p_body[k];
        v.covariance_body = Eigen::Matrix3d::Identity() * 2e-4;
        v.score = 0.9;
        vertices.push_back(v);
      }
    }
  }
  WriteReconstructedBands(vertices, {"synthetic"},
                          results + "/" + kReconstructedBandsFile);
}

TEST(MatchStage, WritesMatchesDecisionsEvidenceAndGeoJsonThatReadBack) {
  SyntheticSceneOptions options;
  options.seed = 21;
  options.crossings = RandomCrossings(3, 45.0, 21);
  const SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  // The survey's images are empty files, so the images can tell no bare
  // road from paint: a one-end decision has no evidence a database fault
  // could not fake and is refused by default. This test is about the
  // files; it lets band counts decide.
  MatchOptions options_by_counts;
  options_by_counts.min_strong_margin = 0.0;
  const MatchResult result =
      RunMatchStage(survey, folder.Path("results"), options_by_counts);
  ASSERT_TRUE(result.summary.IsUsable());
  EXPECT_GT(result.summary.matched, 0);

  const std::vector<VertexMatch> matches =
      ReadMatches(folder.Path("results/matches.csv"), "matches.csv");
  EXPECT_EQ(matches.size(), result.matches.size());
  EXPECT_EQ(ScoreMatches(scene, matches).wrong, 0);
  const std::vector<CrossingDecision> decisions = ReadCrossingDecisions(
      folder.Path("results/crossing_decisions.csv"), "crossing_decisions.csv");
  EXPECT_EQ(decisions.size(), scene.observations.size());
  for (const CrossingDecision& d : decisions) {
    EXPECT_EQ(d.crossing_id.empty(), d.decision != Decision::kMatched);
    EXPECT_FALSE(d.reason.empty());
  }

  std::ifstream evidence_file(folder.Path("results/match_evidence.json"));
  const nlohmann::json evidence = nlohmann::json::parse(evidence_file);
  EXPECT_EQ(evidence["observations"].size(), scene.observations.size());
  EXPECT_EQ(evidence["summary"]["matched"].get<int>(), result.summary.matched);
  std::ifstream geojson_file(folder.Path("results/matches.geojson"));
  const nlohmann::json geojson = nlohmann::json::parse(geojson_file);
  EXPECT_EQ(geojson["type"], "FeatureCollection");
  EXPECT_GE(geojson["features"].size(), matches.size());
  // No temporary file is left behind.
  for (const auto& entry : fs::directory_iterator(folder.Path("results"))) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"),
              std::string::npos);
  }
}

TEST(MatchStage, FailsClearlyWithoutReconstructedBands) {
  SyntheticSceneOptions options;
  options.crossings = RandomCrossings(1, 45.0, 1);
  const SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  fs::remove(folder.Path("results/reconstructed_bands.csv"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  try {
    RunMatchStage(survey, folder.Path("results"), MatchOptions());
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("reconstructed_bands.csv"),
              std::string::npos);
  }
  EXPECT_FALSE(fs::exists(folder.Path("results/matches.csv")));
}

TEST(MatchStage, RejectsBandsOfAnExposureTheSurveyDoesNotHave) {
  SyntheticSceneOptions options;
  options.crossings = RandomCrossings(1, 45.0, 2);
  SyntheticScene scene = MakeSyntheticScene(options);
  TemporaryFolder folder;
  WriteSceneSurvey(scene, folder.Path("survey"), folder.Path("results"));
  const Survey survey = LoadSurvey(folder.Path("survey"));
  ReconstructedVertex stray;
  stray.exposure_id = 999999;
  stray.band_id = 1;
  try {
    BuildObservations(survey, {stray}, "reconstructed_bands.csv", nullptr);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("exposure_id 999999"),
              std::string::npos);
  }
}

// A line_matches.csv row: a lane line seen from exposure `e` holding the
// position across the track (north).
LineMatch LaneLineAt(const ExposurePose& e) {
  LineMatch row;
  row.exposure_id = e.exposure_id;
  row.line_id = e.exposure_id;
  row.db_line = "lane";
  row.across_enu = Eigen::Vector2d(0.0, 1.0);
  return row;
}

// The "adjusted" trajectory of the second pass: the true poses shifted by
// `shift_enu_m`, with a posterior sd of 3 cm, and an adjustment.json that
// says the sd is posterior (`posterior` false: it is not) and how many
// crossings controlled it (none with `road_lines_only`: then
// line_matches.csv has a line point holding the cross-track position at
// every exposure, unless `lines_everywhere` is false: none).
void WriteAdjustedTrajectory(const SyntheticScene& scene,
                             const Eigen::Vector2d& shift_enu_m, bool posterior,
                             const std::string& results,
                             int control_crossings = 3,
                             bool road_lines_only = false,
                             bool lines_everywhere = true) {
  if (road_lines_only) {
    std::vector<LineMatch> rows;
    for (const ExposurePose& e : scene.exposures) {
      if (!lines_everywhere) break;
      rows.push_back(LaneLineAt(e));
    }
    WriteLineMatches(rows, results + "/" + kLineMatchesFile);
  }
  std::vector<TrajectorySample> samples;
  for (const ExposurePose& e : scene.exposures) {
    Pose pose = scene.true_pose.at(e.exposure_id);
    pose.p_enu.head<2>() += shift_enu_m;
    samples.push_back(SampleFromPose(e.time_s, pose, scene.frame,
                                     Eigen::Vector3d::Constant(0.03),
                                     Eigen::Vector3d::Constant(1e-4)));
  }
  WriteTrajectorySamples(samples, results + "/" + kTrajectoryCorrectedFile);
  AdjustmentRecord adjustment;
  adjustment.usable = true;
  adjustment.posterior_sd_computed = posterior;
  adjustment.counts.control_crossings = control_crossings;
  adjustment.road_lines_only = road_lines_only;
  WriteAdjustmentRecord(adjustment, results + "/" + kAdjustmentJsonFile);
}

// Three crossings whose first two bands a parked vehicle hides from every
// viewpoint, seen from a trajectory 2 m off: an observation of interior
// bands alone cannot tell which bands they are, so the first pass refuses
// them; with a trajectory adjusted to centimetres they are unambiguous.
class SecondPassTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticSceneOptions options;
    options.seed = 8;
    options.crossings = RandomCrossings(3, 45.0, 8);
    for (SyntheticCrossingSpec& c : options.crossings) {
      c.occluded_bands = 2;
      c.occluded_beyond_m = 0.0;
    }
    options.miss_probability = 0.0;
    options.false_band_probability = 0.0;
    scene_ = MakeSyntheticScene(options);
    WriteSceneSurvey(scene_, folder_.Path("survey"), folder_.Path("results"));
    survey_ = LoadSurvey(folder_.Path("survey"));
    first_ = RunMatchStage(survey_, folder_.Path("results"), MatchOptions());
    ASSERT_TRUE(first_.summary.IsUsable());
  }
  std::vector<VertexMatch> Matches() const {
    return ReadMatches(folder_.Path("results/matches.csv"), "matches.csv");
  }
  int Undecided() const {
    int n = 0;
    for (const CrossingDecision& d : ReadCrossingDecisions(
             folder_.Path("results/crossing_decisions.csv"), "decisions")) {
      n += d.decision != Decision::kMatched;
    }
    return n;
  }
  TemporaryFolder folder_;
  SyntheticScene scene_;
  Survey survey_;
  MatchResult first_;
};

TEST_F(SecondPassTest, MatchesWhatTheFirstPassRefusedAndNothingWrong) {
  const int undecided = Undecided();
  ASSERT_GT(undecided, 0) << "the scene no longer makes the first pass refuse";
  const size_t first_matches = Matches().size();
  EXPECT_EQ(ScoreMatches(scene_, Matches()).wrong, 0);
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(0.03, -0.02), true,
                          folder_.Path("results"));
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_EQ(summary.observations, undecided);
  EXPECT_GT(summary.added, 0) << summary.message;
  EXPECT_EQ(summary.disagreements, 0);
  EXPECT_EQ(Undecided(), undecided - summary.added);
  const std::vector<VertexMatch> after = Matches();
  EXPECT_GT(after.size(), first_matches);
  EXPECT_EQ(ScoreMatches(scene_, after).wrong, 0);
  for (const CrossingDecision& d : ReadCrossingDecisions(
           folder_.Path("results/crossing_decisions.csv"), "decisions")) {
    if (d.reason.find("second pass") != std::string::npos) {
      EXPECT_EQ(d.decision, Decision::kMatched);
    }
  }
}

// The second pass is only as good as the adjusted trajectory: one that
// contradicts the first pass's matches (here one band off) adds nothing,
// and the crossings it contradicts are refused (either may be wrong).
TEST_F(SecondPassTest, AnAdjustedTrajectoryOneBandOffIsNotTrusted) {
  // First-pass matches on the first two crossings (the right ones, from the
  // true trajectory), the third crossing left refused.
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d::Zero(), true,
                          folder_.Path("results"));
  RematchWithAdjustedTrajectory(survey_, folder_.Path("results"),
                                MatchOptions(), RematchOptions());
  const std::string decisions_path =
      folder_.Path("results/crossing_decisions.csv");
  std::vector<CrossingDecision> decisions =
      ReadCrossingDecisions(decisions_path, "decisions");
  std::vector<VertexMatch> matches = Matches();
  ASSERT_EQ(ScoreMatches(scene_, matches).wrong, 0);
  const int64_t last = decisions.back().exposure_id;
  std::set<int64_t> refused;
  for (CrossingDecision& d : decisions) {
    if (d.exposure_id + 30 < last) continue;  // the last crossing's views
    d.decision = Decision::kRefused;
    d.crossing_id.clear();
    refused.insert(d.exposure_id);
  }
  matches.erase(std::remove_if(matches.begin(), matches.end(),
                               [&](const VertexMatch& m) {
                                 return refused.count(m.exposure_id) > 0;
                               }),
                matches.end());
  ASSERT_FALSE(matches.empty());
  WriteCrossingDecisions(decisions, {}, decisions_path);
  WriteMatches(matches, {}, folder_.Path("results/matches.csv"));
  const std::vector<VertexMatch> before = Matches();
  // One band period across the road (the bands repeat along north here).
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(0.0, 1.0), true,
                          folder_.Path("results"));
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_GT(summary.disagreements, 0) << summary.message;
  EXPECT_EQ(summary.added, 0);
  const std::vector<VertexMatch> after = Matches();
  EXPECT_EQ(static_cast<int>(before.size() - after.size()), summary.dropped);
  EXPECT_GT(summary.dropped, 0);
  // Every observation of a contradicted crossing refused; what remains is
  // another crossing's, and right.
  const std::vector<CrossingDecision> now =
      ReadCrossingDecisions(decisions_path, "decisions");
  ASSERT_EQ(now.size(), decisions.size());
  std::set<std::string> contradicted;
  for (size_t k = 0; k < now.size(); ++k) {
    if (now[k].reason.find("comes out at another band") != std::string::npos) {
      EXPECT_EQ(now[k].decision, Decision::kRefused);
      contradicted.insert(decisions[k].crossing_id);
    }
  }
  EXPECT_FALSE(contradicted.empty());
  for (size_t k = 0; k < now.size(); ++k) {
    if (contradicted.count(decisions[k].crossing_id)) {
      EXPECT_NE(now[k].decision, Decision::kMatched);
    }
  }
  for (const VertexMatch& m : after) {
    EXPECT_EQ(contradicted.count(m.crossing_id), 0u) << m.crossing_id;
  }
  EXPECT_EQ(ScoreMatches(scene_, after).wrong, 0);
}

// A crossing the adjustment rejected (gcp_residuals.csv) is not matched
// again: the next adjustment would face the same conflict and might reject
// the other side of it instead (geometry seed 969 flip-flopped so, H 26.5
// -> 120.8 cm). The pass still matches the other crossings.
TEST_F(SecondPassTest, NothingIsMatchedAgainToACrossingTheAdjustmentRejected) {
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(0.03, -0.02), true,
                          folder_.Path("results"));
  // What the pass adds when nothing is rejected, in a copy of the results.
  std::filesystem::copy(folder_.Path("results"), folder_.Path("unrejected"));
  RematchWithAdjustedTrajectory(survey_, folder_.Path("unrejected"),
                                MatchOptions(), RematchOptions());
  std::map<std::string, int> added;
  for (const CrossingDecision& d : ReadCrossingDecisions(
           folder_.Path("unrejected/crossing_decisions.csv"), "decisions")) {
    if (d.reason.find("second pass") != std::string::npos) {
      ++added[d.crossing_id];
    }
  }
  ASSERT_FALSE(added.empty()) << "the scene no longer needs a second pass";
  const std::string rejected = added.begin()->first;
  GcpResidual residual;
  residual.crossing_id = rejected;
  residual.band = 1;
  residual.status = GcpStatus::kRejected;
  WriteGcpResiduals({residual}, folder_.Path("results/gcp_residuals.csv"));
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  int total = 0;
  for (const auto& [crossing, n] : added) total += n;
  EXPECT_EQ(summary.added, total - added[rejected]) << summary.message;
  for (const VertexMatch& m : Matches()) EXPECT_NE(m.crossing_id, rejected);
  EXPECT_EQ(ScoreMatches(scene_, Matches()).wrong, 0);
}

TEST_F(SecondPassTest, WithoutAPosteriorSdNothingIsDone) {
  const int undecided = Undecided();
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d::Zero(), false,
                          folder_.Path("results"));
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_EQ(summary.added, 0);
  EXPECT_NE(summary.message.find("skipped"), std::string::npos);
  EXPECT_EQ(Undecided(), undecided);
}

// An adjustment with no crossing to estimate the drift from has a posterior
// sd that says nothing of its error (seen: 8 cm for a 1 m drift).
TEST_F(SecondPassTest, WithoutEnoughControlCrossingsNothingIsDone) {
  const int undecided = Undecided();
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d::Zero(), true,
                          folder_.Path("results"), 2);
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_EQ(summary.added, 0);
  EXPECT_NE(summary.message.find("2 control crossings"), std::string::npos)
      << summary.message;
  EXPECT_EQ(Undecided(), undecided);
}

// After an adjustment by road lines alone the cross-track position is
// known to centimetres and the along-track one not at all: the second pass
// searches along-track as the first did (here 1.5 m off, far beyond the
// usual 0.25 m gate) and across within cross_track_gate_m, which leaves
// the band offsets a metre away out.
TEST_F(SecondPassTest, AfterRoadLinesAloneSearchesAlongTrack) {
  const int undecided = Undecided();
  ASSERT_GT(undecided, 0);
  // The road runs east, the bands repeat along north (across it).
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(1.5, 0.04), true,
                          folder_.Path("results"), 0, true);
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_GT(summary.added, 0) << summary.message;
  EXPECT_EQ(ScoreMatches(scene_, Matches()).wrong, 0);
  bool said = false;
  for (const CrossingDecision& d : ReadCrossingDecisions(
           folder_.Path("results/crossing_decisions.csv"), "decisions")) {
    said = said || d.reason.find("after road lines alone") != std::string::npos;
  }
  EXPECT_TRUE(said);
}

// Lines that left the trajectory 0.6 m off across the track: the right
// band offset is outside the gate, and so is the wrong one (0.4 m): no
// match, and none wrong.
TEST_F(SecondPassTest, AfterRoadLinesAloneNothingOutsideTheCrossTrackGate) {
  const int undecided = Undecided();
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(0.0, 0.6), true,
                          folder_.Path("results"), 0, true);
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_EQ(summary.added, 0) << summary.message;
  EXPECT_EQ(Undecided(), undecided);
  EXPECT_EQ(ScoreMatches(scene_, Matches()).wrong, 0);
}

// Where no line held the cross-track position it is interpolated between
// stretches of line (a multipath switch there puts it a metre off): the
// pass searches nothing there, even with a trajectory that is right.
TEST_F(SecondPassTest, AfterRoadLinesAloneOnlyWhereTheLinesHeldIt) {
  const int undecided = Undecided();
  ASSERT_GT(undecided, 0);
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(1.5, 0.04), true,
                          folder_.Path("results"), 0, true, false);
  const RematchSummary summary = RematchWithAdjustedTrajectory(
      survey_, folder_.Path("results"), MatchOptions(), RematchOptions());
  EXPECT_EQ(summary.added, 0) << summary.message;
  EXPECT_EQ(Undecided(), undecided);
}

// Road lines every `period_s` seconds up to `until_s` (line_matches.csv),
// and the lines' fitted error model across the track in adjustment.json.
void WriteSparseLines(const SyntheticScene& scene, double period_s,
                      double until_s, double sigma_m,
                      const std::string& results) {
  std::vector<LineMatch> rows;
  for (const ExposurePose& e : scene.exposures) {
    const double phase = std::fmod(e.time_s + 1e-6, period_s);
    if (e.time_s > until_s || phase > 0.1) continue;
    rows.push_back(LaneLineAt(e));
  }
  WriteLineMatches(rows, results + "/" + kLineMatchesFile);
  const std::string path = results + "/" + kAdjustmentJsonFile;
  AdjustmentRecord record = ReadAdjustmentRecord(path, kAdjustmentJsonFile);
  record.model.position_model_estimated = true;
  record.model.position_sigma_m = Eigen::Vector3d(sigma_m, sigma_m, 0.03);
  record.model.position_tau_s = Eigen::Vector3d::Constant(30.0);
  WriteAdjustmentRecord(record, path);
}

// Lines every 5 s (40 m at 8 m/s): between two of them, farther than
// max_line_control_gap_m from both, an observation is searched when the
// lines' model says the cross-track error barely changes over the gap;
// not when it shows a metre-size process (a multipath switch), nor beyond
// the last line point.
TEST_F(SecondPassTest, AfterRoadLinesAloneBetweenLinesAsTheirModelAllows) {
  ASSERT_GT(Undecided(), 0);
  WriteAdjustedTrajectory(scene_, Eigen::Vector2d(1.5, 0.04), true,
                          folder_.Path("results"), 0, true, false);
  const auto added = [&](const std::string& name, double until_s,
                         double sigma_m) {
    const std::string results = folder_.Path(name);
    std::filesystem::copy(folder_.Path("results"), results);
    WriteSparseLines(scene_, 5.0, until_s, sigma_m, results);
    const RematchSummary summary = RematchWithAdjustedTrajectory(
        survey_, results, MatchOptions(), RematchOptions());
    EXPECT_EQ(ScoreMatches(scene_,
                           ReadMatches(results + "/matches.csv", "matches.csv"))
                  .wrong,
              0)
        << name;
    return summary.added;
  };
  const double end_s = scene_.exposures.back().time_s;
  const int steady = added("steady", end_s, 0.1);
  const int switching = added("switching", end_s, 2.3);
  const int beyond = added("beyond", 0.0, 0.1);
  EXPECT_GT(steady, switching) << steady << " against " << switching;
  EXPECT_EQ(beyond, 0);
}

TEST(RematchOptions, CrossTrackGateUnderHalfABand) {
  RematchOptions options;
  EXPECT_EQ(options.Check(), "");
  options.cross_track_gate_m = 0.5;
  EXPECT_NE(options.Check().find("cross_track_gate_m"), std::string::npos);
  options = RematchOptions();
  options.max_line_control_gap_m = -1.0;
  EXPECT_NE(options.Check().find("max_line_control_gap_m"), std::string::npos);
  options = RematchOptions();
  options.max_cross_track_control_gap_m = std::nan("");
  EXPECT_NE(options.Check().find("max_cross_track_control_gap_m"),
            std::string::npos);
  MatchOptions match;
  match.max_cross_track_m = -1.0;
  EXPECT_NE(match.Check().find("max_cross_track_m"), std::string::npos);
}

}  // namespace
}  // namespace zebrageo
