// Avenues through the geometry sweep (issue 52): surveys whose crossings a
// refuge island splits, in both database forms (two crossing_ids with the
// far half staggered; one crossing whose band numbers skip the island's
// places), matched and adjusted in process. Across the island a band of
// one half never takes the other half's id (nor a one-band shift): no
// wrong vertex match, and every matched band's (crossing_id, band) is the
// truth band it was reconstructed from.
#include <glog/logging.h>
#include <gtest/gtest.h>

#include <string>

#include "tests/support/geometry_sweep.h"

namespace zebrageo::support {
namespace {

struct Tally {
  int surveys = 0, wrong = 0, wrong_ids = 0, ids_checked = 0;
  int halves_matched = 0, matched = 0, matchable = 0, worse = 0;
};

void RunSeeds(const GeometrySweepOptions& options, uint64_t first,
              uint64_t last, Tally* tally) {
  FLAGS_minloglevel = google::GLOG_ERROR;
  for (uint64_t seed = first; seed <= last; ++seed) {
    const GeometryRunResult r = RunGeometrySurvey(seed, options);
    ASSERT_EQ(r.error, "") << r.Line();
    ++tally->surveys;
    tally->wrong += r.wrong;
    tally->wrong_ids += r.wrong_ids;
    tally->ids_checked += r.ids_checked;
    tally->matched += r.crossings_matched;
    tally->matchable += r.crossings_matchable;
    tally->worse += r.worse_position;
    for (const std::string& id : r.matched_crossings) {
      const char last_char = id.empty() ? ' ' : id.back();
      tally->halves_matched += last_char == 'a' || last_char == 'b';
    }
    EXPECT_EQ(r.wrong, 0) << r.Line();
    EXPECT_EQ(r.wrong_ids, 0) << r.Line();
    EXPECT_FALSE(r.worse_position) << r.Line();
  }
}

// The avenue preset: 20 m kerb to kerb, a 2.5 m median, half the crossings
// two staggered halves, two lanes each way and two lane changes.
TEST(AvenueGeometry, IslandHalvesKeepTheirOwnIdsOnTheAvenuePreset) {
  GeometrySweepOptions options;
  options.preset = "avenue";
  Tally tally;
  RunSeeds(options, 1, 6, &tally);
  EXPECT_EQ(tally.wrong, 0);
  EXPECT_EQ(tally.wrong_ids, 0);
  EXPECT_GT(tally.ids_checked, 500);
  EXPECT_GT(tally.halves_matched, 6);
  EXPECT_GT(tally.matched, tally.matchable / 2);
}

// Avenues of the random preset: 14-24 m, every kind of trajectory error,
// database fault and lane plan it draws.
TEST(AvenueGeometry, RandomAvenuesHaveNoWrongMatch) {
  GeometrySweepOptions options;
  options.avenues = 1;
  options.max_road_length_m = 400.0;
  Tally tally;
  RunSeeds(options, 1, 10, &tally);
  EXPECT_EQ(tally.wrong, 0);
  EXPECT_EQ(tally.wrong_ids, 0);
  EXPECT_GT(tally.ids_checked, 300);
}

}  // namespace
}  // namespace zebrageo::support
