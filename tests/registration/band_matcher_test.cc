#include "registration/band_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <tuple>

#include "tests/registration/synthetic_scene.h"

namespace zebrageo {
namespace {

// Runs the matcher on a scene and scores it against the scene's truth.
struct SceneRun {
  SyntheticScene scene;
  RoadmarkIndex index;
  MatchResult result;
  MatchScore score;
};

SceneRun MatchScene(const SyntheticSceneOptions& scene_options,
                    const MatchOptions& options = MatchOptions()) {
  SceneRun run;
  run.scene = MakeSyntheticScene(scene_options);
  run.index = RoadmarkIndex(run.scene.database, run.scene.frame);
  run.result = MatchBands(run.scene.Input(run.index), options);
  run.score = ScoreMatches(run.scene, run.result.matches);
  return run;
}

bool Contains(const std::vector<std::string>& list, const std::string& x) {
  return std::find(list.begin(), list.end(), x) != list.end();
}

int CountDecisions(const MatchResult& result, Decision decision,
                   const std::string& reason_part = "") {
  int n = 0;
  for (const CrossingDecision& d : result.decisions) {
    if (d.decision == decision &&
        d.reason.find(reason_part) != std::string::npos) {
      ++n;
    }
  }
  return n;
}

double MatchedShare(const MatchScore& score) {
  return score.crossings_eligible.empty()
             ? 1.0
             : static_cast<double>(score.crossings_matched.size()) /
                   score.crossings_eligible.size();
}

TEST(MatchOptions, CheckNamesTheFieldItsValueAndTheConstraint) {
  EXPECT_EQ(MatchOptions().Check(), "");
  MatchOptions options;
  options.max_drift_m = -1.0;
  EXPECT_EQ(options.Check(), "max_drift_m = -1: must be > 0");
  options = MatchOptions();
  options.hit_tolerance_m = 0.6;
  EXPECT_NE(options.Check().find("hit_tolerance_m = 0.6: must be < 0.5"),
            std::string::npos);
  options = MatchOptions();
  options.min_hit_bands = 0;
  EXPECT_EQ(options.Check(), "min_hit_bands = 0: must be >= 1");
}

TEST(BandMatcher, ReportsInvalidOptionsInsteadOfRunning) {
  MatchOptions options;
  options.window_s = -2.0;
  const RoadmarkIndex index;
  MatchInput input;
  input.index = &index;
  const MatchResult result = MatchBands(input, options);
  EXPECT_FALSE(result.summary.IsUsable());
  EXPECT_EQ(result.summary.message,
            "MatchOptions: window_s = -2: must be >= 0");
  EXPECT_TRUE(result.matches.empty());
}

TEST(BandMatcher, MatchesAStreetWithTwoMetresOfDriftWithoutAWrongVertex) {
  for (int seed = 1; seed <= 3; ++seed) {
    const SceneRun run = MatchScene(RandomStreetScene(seed));
    SCOPED_TRACE("seed " + std::to_string(seed) + ": " +
                 run.result.summary.BriefReport());
    EXPECT_EQ(run.score.wrong, 0);
    EXPECT_GT(run.score.right, 100);
    EXPECT_GE(MatchedShare(run.score), 0.95);
    EXPECT_EQ(run.result.decisions.size(), run.scene.observations.size());
  }
}

TEST(BandMatcher, RecoversTwoMetreDriftDespiteOneMetrePeriod) {
  // The drift is two band periods straight across the crossings: a nearest-
  // band match would be off by two bands everywhere.
  SyntheticSceneOptions options = RandomStreetScene(4);
  options.drift_m = 0.0;
  options.constant_shift_m = Eigen::Vector2d(0.03, 2.0);
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_GE(MatchedShare(run.score), 0.95);
  for (const ObservationEvidence& e : run.result.evidence) {
    if (e.decision != Decision::kMatched) continue;
    EXPECT_NEAR(e.correction.shift_enu_m.y(), -2.0, 0.15);
  }
}

TEST(BandMatcher, RecoversThreeMetreDriftOfAnOutage) {
  SyntheticSceneOptions options = RandomStreetScene(5);
  options.drift_m = 3.0;
  options.heading_drift_rad = 0.01;
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_GE(MatchedShare(run.score), 0.95);
}

TEST(BandMatcher, NeverGuessesWhenTheDriftOutrunsContinuity) {
  // 3 m of drift turning at 0.09 m/s: too fast to carry a correction from
  // one crossing to the next 5 s later. Crossings seen end to end still
  // match; the others are refused, none is guessed.
  for (int seed = 5; seed <= 7; ++seed) {
    SyntheticSceneOptions options = RandomStreetScene(seed);
    options.drift_m = 3.0;
    options.drift_turn_rate_rad_per_s = 0.03;
    options.heading_drift_rad = 0.01;
    const SceneRun run = MatchScene(options);
    SCOPED_TRACE(run.result.summary.BriefReport());
    EXPECT_EQ(run.score.wrong, 0);
    EXPECT_GE(MatchedShare(run.score), 0.5);
  }
}

TEST(BandMatcher, RefusesWhenOnlyInteriorBandsAreSeen) {
  // One wide crossing, a narrow field of view: the ends are never in view,
  // so the band offset cannot be told.
  SyntheticSceneOptions options;
  options.seed = 6;
  SyntheticCrossingSpec wide;
  wide.x_m = 0.0;
  wide.bands = 12;
  wide.band_length_m = 3.0;
  options.crossings = {wide};
  options.road_y0_m = -8.0;
  options.lane_y_m = -2.0;
  options.horizontal_fov_deg = 35.0;
  options.max_range_m = 9.0;
  options.false_band_probability = 0.0;
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_TRUE(run.result.matches.empty());
  EXPECT_GT(CountDecisions(run.result, Decision::kRefused, "ambiguous"), 0);
  EXPECT_GT(CountDecisions(run.result, Decision::kRefused,
                           "only interior bands seen"),
            0);
  EXPECT_GT(run.result.summary.ambiguous, 0);
}

TEST(BandMatcher, ResolvesInteriorViewsFromAMatchedNeighbourCrossing) {
  // A narrow crossing seen whole, then 34 m on (beyond the +-3 s window) a
  // wide one seen only inside:
  // the correction carried over from the first singles out the offset.
  SyntheticSceneOptions options;
  options.seed = 7;
  SyntheticCrossingSpec narrow;
  narrow.x_m = 0.0;
  narrow.bands = 4;
  narrow.y0_m = -4.0;
  SyntheticCrossingSpec wide;
  wide.x_m = 34.0;
  wide.bands = 12;
  wide.y0_m = -8.0;
  options.crossings = {narrow, wide};
  options.lane_y_m = -2.0;
  options.horizontal_fov_deg = 60.0;
  options.max_range_m = 12.0;
  options.false_band_probability = 0.0;
  options.drift_turn_rate_rad_per_s = 0.0;
  // A GNSS/INS whose error is known to drift smoothly (no multipath
  // switch, which by default may move it by a metre over these 34 m).
  MatchOptions smooth;
  smooth.max_drift_per_metre = 0.005;
  const SceneRun run = MatchScene(options, smooth);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_TRUE(Contains(run.score.crossings_matched, "C01"));
  EXPECT_TRUE(Contains(run.score.crossings_matched, "C02"));
  EXPECT_GT(run.result.summary.resolved_by_neighbours, 0);
  EXPECT_GT(CountDecisions(run.result, Decision::kMatched,
                           "resolved by trajectory continuity"),
            0);
  // By default the 34 m to the matched crossing allow a multipath switch
  // of a band period: the interior views are refused, never guessed.
  const SceneRun cautious = MatchScene(options);
  SCOPED_TRACE(cautious.result.summary.BriefReport());
  EXPECT_EQ(cautious.score.wrong, 0);
  EXPECT_EQ(CountDecisions(cautious.result, Decision::kMatched,
                           "resolved by trajectory continuity"),
            0);
}

TEST(BandMatcher, IgnoresAnEndBandHiddenFromSomeViewsByAParkedVehicle) {
  // Band 1 of every crossing is hidden until the vehicle is within 9 m:
  // the far views must not count its absence against the right offset.
  for (int seed = 1; seed <= 3; ++seed) {
    SyntheticSceneOptions options = RandomStreetScene(seed);
    for (SyntheticCrossingSpec& c : options.crossings) {
      c.occluded_bands = 1;
      c.occluded_beyond_m = 9.0;
    }
    const SceneRun run = MatchScene(options);
    SCOPED_TRACE(run.result.summary.BriefReport());
    EXPECT_EQ(run.score.wrong, 0);
    EXPECT_GE(MatchedShare(run.score), 0.95);
  }
}

TEST(BandMatcher, WithBothEndsRequiredNeverGuessesAnEndBandHiddenFromAllViews) {
  // Bands 1 and 2 are never seen: from the bands alone this is a crossing
  // two bands narrower. Requiring both ends to agree refuses it.
  SyntheticSceneOptions options = RandomStreetScene(5);
  for (SyntheticCrossingSpec& c : options.crossings) {
    c.occluded_bands = 2;
    c.occluded_beyond_m = 6.0;
  }
  MatchOptions match;
  match.require_both_ends = true;
  const SceneRun run = MatchScene(options, match);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
}

TEST(BandMatcher,
     ImageEvidenceKeepsAnEndBandHiddenFromAllViewsFromPassingForAShift) {
  // A vehicle at the kerb hides band 1 of every crossing from every view:
  // from the bands alone this is the crossing shifted by one band, whose
  // extra band falls out of view. Counting every predicted band in view as
  // missing picks the shift; image evidence (here a perfect probe: paint
  // where the street has a band, the vehicle where it hides band 1, bare
  // road elsewhere) must not.
  for (int seed = 1; seed <= 3; ++seed) {
    SyntheticSceneOptions options = RandomStreetScene(seed);
    for (SyntheticCrossingSpec& c : options.crossings) {
      c.occluded_bands = 1;
      c.occluded_beyond_m = 1e-3;
    }
    const SyntheticScene scene = MakeSyntheticScene(options);
    const RoadmarkIndex index(scene.database, scene.frame);
    MatchInput input = scene.Input(index);
    input.paint_probe = [&scene](int64_t, const Pose&,
                                 const BandCornersEnu& band,
                                 const std::vector<BandCornersEnu>&) {
      const Eigen::Vector3d centre =
          0.25 * (band[0] + band[1] + band[2] + band[3]);
      for (const auto& [key, corners] : scene.truth) {
        const Eigen::Vector3d c =
            0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
        if ((c - centre).head<2>().norm() > 0.3) continue;
        return key.second == 1 ? PaintEvidence::kUnknown
                               : PaintEvidence::kPaint;
      }
      return PaintEvidence::kBareRoad;
    };
    const MatchResult with_probe = MatchBands(input, MatchOptions());
    const MatchScore score = ScoreMatches(scene, with_probe.matches);
    SCOPED_TRACE(with_probe.summary.BriefReport());
    EXPECT_EQ(score.wrong, 0);
  }
}

// A perfect image probe: paint where the street has a band (unknown where
// the scene's occluder hides one of its first `hidden` bands), bare road
// elsewhere.
MatchInput WithPerfectProbe(const SyntheticScene& scene,
                            const RoadmarkIndex& index, int hidden) {
  MatchInput input = scene.Input(index);
  input.paint_probe = [&scene, hidden](int64_t, const Pose&,
                                       const BandCornersEnu& band,
                                       const std::vector<BandCornersEnu>&) {
    const Eigen::Vector3d centre =
        0.25 * (band[0] + band[1] + band[2] + band[3]);
    for (const auto& [key, corners] : scene.truth) {
      const Eigen::Vector3d c =
          0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
      if ((c - centre).head<2>().norm() > 0.3) continue;
      return key.second <= hidden ? PaintEvidence::kUnknown
                                  : PaintEvidence::kPaint;
    }
    return PaintEvidence::kBareRoad;
  };
  return input;
}

TEST(BandMatcher, ADatabaseLackingItsLastBandWithBandOneHiddenIsRefused) {
  // The double fault no evidence separates from a one-band shift: the
  // database lost the last band (its numbering cannot tell) and a parked
  // vehicle hides band 1 from every view. The bands fit 2..n as well as
  // 1..n-1; the decision would rest on band counts at one end: refused,
  // never guessed.
  for (int seed = 1; seed <= 3; ++seed) {
    SyntheticSceneOptions options = RandomStreetScene(40 + seed, 5);
    for (SyntheticCrossingSpec& c : options.crossings) {
      c.database_lacks = {c.bands};
      c.occluded_bands = 1;
      c.occluded_beyond_m = 1e-3;
    }
    const SyntheticScene scene = MakeSyntheticScene(options);
    const RoadmarkIndex index(scene.database, scene.frame);
    const MatchResult result =
        MatchBands(WithPerfectProbe(scene, index, 1), MatchOptions());
    const MatchScore score = ScoreMatches(scene, result.matches);
    SCOPED_TRACE(result.summary.BriefReport());
    EXPECT_EQ(score.wrong, 0);
  }
}

TEST(BandMatcher, RejectsMatchInconsistentWithNeighbours) {
  // The database has crossing C03 one band period off (a wrong survey): it
  // still fits perfectly alone, but implies a correction 1 m away from the
  // crossings before and after it.
  SyntheticSceneOptions options = RandomStreetScene(8, 5, 30.0);
  options.crossings[2].database_shift_m = Eigen::Vector2d(0.0, 1.0);
  options.drift_turn_rate_rad_per_s = 0.0;
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_FALSE(Contains(run.score.crossings_matched, "C03"));
  EXPECT_GT(CountDecisions(run.result, Decision::kRefused, "inconsistent"), 0);
  EXPECT_TRUE(Contains(run.score.crossings_matched, "C02"));
  EXPECT_TRUE(Contains(run.score.crossings_matched, "C04"));
}

TEST(BandMatcher, ReportsCrossingMissingFromTheDatabase) {
  SyntheticSceneOptions options = RandomStreetScene(10, 5);
  options.crossings[1].in_database = false;
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_GE(MatchedShare(run.score), 0.95);
  EXPECT_GT(CountDecisions(run.result, Decision::kNoCandidate,
                           "missing from the database"),
            0);
  int missing = 0;
  for (const DatabaseFault& fault : run.result.faults) {
    missing += fault.kind == FaultKind::kCrossingMissingFromDatabase;
  }
  EXPECT_EQ(missing, 1);
}

TEST(BandMatcher, ReportsBandsMissingOnEitherSideWithoutGuessing) {
  SyntheticSceneOptions options = RandomStreetScene(11, 6);
  for (SyntheticCrossingSpec& c : options.crossings) c.bands = 6;
  options.crossings[1].street_lacks = {options.crossings[1].bands};
  options.crossings[3].database_lacks = {1};
  // C02 is told apart from its neighbours 45 m away only with a GNSS/INS
  // known to drift smoothly (see ResolvesInteriorViews...).
  MatchOptions smooth;
  smooth.max_drift_per_metre = 0.005;
  const SceneRun run = MatchScene(options, smooth);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  // Without images: not recognised, not missing from the street.
  EXPECT_FALSE(
      HasFault(run.result, FaultKind::kBandMissingFromStreet, "C02", 6));
  ASSERT_NE(FindUnrecognised(run.result, "C02", 6), nullptr);
  EXPECT_EQ(FindUnrecognised(run.result, "C02", 6)->why, "no images");
}

TEST(BandMatcher, ReportsARepaintedCrossingShiftedByDecimetres) {
  SyntheticSceneOptions options = RandomStreetScene(12, 5);
  options.crossings[2].database_shift_m = Eigen::Vector2d(0.35, 0.0);
  options.drift_turn_rate_rad_per_s = 0.0;
  options.database_offset_m = 0.02;
  const SceneRun run = MatchScene(options);
  SCOPED_TRACE(run.result.summary.BriefReport());
  EXPECT_EQ(run.score.wrong, 0);
  EXPECT_TRUE(HasFault(run.result, FaultKind::kCrossingShifted, "C03"));
  EXPECT_FALSE(HasFault(run.result, FaultKind::kCrossingShifted, "C02"));
}

TEST(BandMatcher, MapsVerticesToDatabaseCornersWhateverTheRingOrder) {
  const SceneRun run = MatchScene(RandomStreetScene(13, 3));
  ASSERT_FALSE(run.result.matches.empty());
  std::set<int> db_vertices;
  std::set<int> vertices;
  for (const VertexMatch& m : run.result.matches) {
    db_vertices.insert(m.db_vertex);
    vertices.insert(m.vertex);
  }
  EXPECT_EQ(db_vertices.size(), 4u);
  EXPECT_EQ(vertices.size(), 4u);
  EXPECT_EQ(run.score.wrong, 0);
}

TEST(BandMatcher, AnEndSeenShortLosesItsTwoCornersNotTheBand) {
  // In every view one band is seen 0.3 m short at its far end (cut by the
  // image's edge, worn paint): those two corners are off their database
  // corners by more than a wrong match is (0.2 m), yet the band is still
  // the database's across its axis, and its near corners are control.
  SyntheticScene scene = MakeSyntheticScene(RandomStreetScene(15, 3));
  // (exposure, band, vertex) of the cut corners and of the others.
  std::set<std::tuple<int64_t, int64_t, int>> cut, kept;
  for (CrossingObservation& o : scene.observations) {
    if (o.bands.empty()) continue;
    ObservedBand& b = o.bands.front();
    std::array<int, 4> order = {0, 1, 2, 3};  // far end first
    std::sort(order.begin(), order.end(),
              [&](int p, int q) { return b.p_body[p].x() > b.p_body[q].x(); });
    const Eigen::Vector3d far_to_near =
        (b.p_body[order[2]] + b.p_body[order[3]] - b.p_body[order[0]] -
         b.p_body[order[1]])
            .normalized();
    for (int i = 0; i < 4; ++i) {
      const std::tuple<int64_t, int64_t, int> id{o.exposure_id, b.band_id,
                                                 b.vertex[order[i]]};
      if (i < 2) {
        b.p_body[order[i]] += 0.3 * far_to_near;
        cut.insert(id);
      } else {
        kept.insert(id);
      }
    }
  }
  const RoadmarkIndex index(scene.database, scene.frame);
  const MatchResult result = MatchBands(scene.Input(index), MatchOptions());
  const MatchScore score = ScoreMatches(scene, result.matches);
  SCOPED_TRACE(result.summary.BriefReport());
  EXPECT_EQ(score.wrong, 0);
  EXPECT_GT(score.right, 200);
  int cut_matched = 0;
  int near_matched = 0;
  for (const VertexMatch& m : result.matches) {
    cut_matched += cut.count({m.exposure_id, m.band_id, m.vertex});
    near_matched += kept.count({m.exposure_id, m.band_id, m.vertex});
  }
  EXPECT_EQ(cut_matched, 0);
  // The cut bands' near corners: two per matched view.
  EXPECT_GE(near_matched, 20);
}

TEST(BandMatcher, IsDeterministic) {
  const SceneRun a = MatchScene(RandomStreetScene(14, 3));
  const SceneRun b = MatchScene(RandomStreetScene(14, 3));
  ASSERT_EQ(a.result.matches.size(), b.result.matches.size());
  for (size_t i = 0; i < a.result.matches.size(); ++i) {
    EXPECT_EQ(a.result.matches[i].band_id, b.result.matches[i].band_id);
    EXPECT_EQ(a.result.matches[i].db_vertex, b.result.matches[i].db_vertex);
  }
}

}  // namespace
}  // namespace zebrageo
