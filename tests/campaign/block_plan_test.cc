// The geometry of `zebrageo plan` and the merge's weights, on synthetic
// crossing layouts (no survey).
#include "campaign/block_plan.h"

#include <gtest/gtest.h>

#include <random>

#include "campaign/merge.h"

namespace zebrageo {
namespace {

std::vector<CrossingSpan> Crossings(const std::vector<double>& centres) {
  std::vector<CrossingSpan> spans;
  for (size_t i = 0; i < centres.size(); ++i) {
    spans.push_back(
        {"c" + std::to_string(i), centres[i] - 3.0, centres[i] + 3.0});
  }
  return spans;
}

// No block boundary where a crossing is partly seen.
void ExpectCutsOutsideCrossings(const std::vector<BlockRange>& blocks,
                                const std::vector<CrossingSpan>& spans,
                                const PlanOptions& o) {
  for (size_t k = 0; k < blocks.size(); ++k) {
    for (const CrossingSpan& s : spans) {
      const double lo = s.start_m - o.crossing_view_m - o.crossing_margin_m;
      const double hi = s.end_m + o.crossing_margin_m;
      if (k > 0) {
        EXPECT_FALSE(blocks[k].start_m > lo && blocks[k].start_m < hi)
            << "block " << k << " starts in crossing " << s.crossing_id;
      }
      if (k + 1 < blocks.size()) {
        EXPECT_FALSE(blocks[k].end_m > lo && blocks[k].end_m < hi)
            << "block " << k << " ends in crossing " << s.crossing_id;
      }
    }
  }
}

TEST(PlanBlockRanges, OverlapsHoldTwoCrossingsAndCutsAvoidThem) {
  std::mt19937 random(46);
  PlanOptions o;
  o.block_length_m = 500.0;
  o.overlap_m = 150.0;
  for (int trial = 0; trial < 50; ++trial) {
    // Crossings 40-200 m apart over 2 km.
    std::vector<double> centres;
    for (double s = 20.0 + std::uniform_real_distribution<>(0, 50)(random);
         s < 1990.0; s += std::uniform_real_distribution<>(40, 200)(random)) {
      centres.push_back(s);
    }
    const std::vector<CrossingSpan> spans = Crossings(centres);
    const std::vector<BlockRange> blocks = PlanBlockRanges(2000.0, spans, o);
    ASSERT_EQ(blocks.size(), 4u) << trial;
    EXPECT_EQ(blocks.front().start_m, 0.0);
    EXPECT_EQ(blocks.back().end_m, 2000.0);
    for (size_t k = 1; k < blocks.size(); ++k) {
      // Overlapping, and each block keeps a stretch of its own.
      EXPECT_LT(blocks[k].start_m, blocks[k - 1].end_m);
      EXPECT_GE(blocks[k - 1].end_m - blocks[k].start_m, o.overlap_m - 1e-9);
      EXPECT_LE(blocks[k - 1].end_m - blocks[k].start_m, o.max_overlap_m);
      if (k + 1 < blocks.size()) {
        EXPECT_GT(blocks[k + 1].start_m, blocks[k - 1].end_m);
      }
      EXPECT_GE(
          CrossingsInside(spans, blocks[k].start_m, blocks[k - 1].end_m, o)
              .size(),
          2u)
          << trial << " overlap " << k;
    }
    ExpectCutsOutsideCrossings(blocks, spans, o);
  }
}

TEST(PlanBlockRanges, ARoadWithoutCrossingsStillGetsItsBlocks) {
  PlanOptions o;
  const std::vector<BlockRange> blocks = PlanBlockRanges(2000.0, {}, o);
  ASSERT_EQ(blocks.size(), 4u);
  for (size_t k = 1; k < blocks.size(); ++k) {
    EXPECT_NEAR(blocks[k - 1].end_m - blocks[k].start_m, o.overlap_m, 1e-9);
  }
  // Shorter than a block and a half: one block.
  EXPECT_EQ(PlanBlockRanges(700.0, {}, o).size(), 1u);
}

TEST(BlockWeight, TheTwoBlocksOfAnOverlapSumToOneAndAreContinuous) {
  // Block a: [0, 60], block b: [40, 100]; the overlap is [40, 60].
  const double overlap_start = 40.0, overlap_end = 60.0;
  double previous = 1.0;
  for (double t = 0.0; t <= 100.0; t += 0.01) {
    const double a = BlockWeight(t, 0.0, 60.0, nullptr, &overlap_start);
    const double b = BlockWeight(t, 40.0, 100.0, &overlap_end, nullptr);
    EXPECT_NEAR(a + b, 1.0, 1e-12) << t;
    EXPECT_LE(std::abs(a - previous), 0.01 * 1.5 / 20.0 + 1e-12) << t;
    previous = a;
  }
  EXPECT_EQ(BlockWeight(61.0, 0.0, 60.0, nullptr, &overlap_start), 0.0);
  EXPECT_EQ(BlockWeight(50.0, 0.0, 60.0, nullptr, &overlap_start), 0.5);
}

}  // namespace
}  // namespace zebrageo
