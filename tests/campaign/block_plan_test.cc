// The geometry of `zebrageo plan` and the merge's weights, on synthetic
// crossing layouts (no survey).
#include "campaign/block_plan.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
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

// Three blocks over samples 0..100 (1 s apart), each a constant offset of
// the truth: outside the overlaps a sample is its block's, inside it lies
// between the two blocks' (lerp and slerp with BlockWeight), and the blend
// steps by no more than the weight's slope allows.
TEST(BlendBlockPoses, EachBlockWholeOutsideOverlapsAndContinuousAcross) {
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(i);
  std::vector<CampaignBlock> blocks(3);
  const int ranges[3][2] = {{0, 40}, {30, 70}, {60, 100}};
  for (int k = 0; k < 3; ++k) {
    blocks[k].index = k;
    blocks[k].first_sample = ranges[k][0];
    blocks[k].last_sample = ranges[k][1];
    blocks[k].start_time = times[ranges[k][0]];
    blocks[k].end_time = times[ranges[k][1]];
  }
  // Overlaps [30, 40] and [60, 70].
  const double start01 = 30.0, end01 = 40.0, start12 = 60.0, end12 = 70.0;
  const Eigen::Vector3d offset[3] = {Eigen::Vector3d(0.0, 0.0, 0.0),
                                     Eigen::Vector3d(0.04, 0.0, 0.01),
                                     Eigen::Vector3d(0.0, -0.03, 0.0)};
  const double yaw[3] = {0.0, 0.002, -0.001};
  std::vector<std::vector<Pose>> poses(3);
  for (int k = 0; k < 3; ++k) {
    for (int i = ranges[k][0]; i <= ranges[k][1]; ++i) {
      Pose p;
      p.p_enu = Eigen::Vector3d(10.0 * i, 0.0, 0.0) + offset[k];
      p.q_enu_body = Eigen::Quaterniond(
          Eigen::AngleAxisd(yaw[k], Eigen::Vector3d::UnitZ()));
      poses[k].push_back(p);
    }
  }
  std::vector<BlockPoses> views = {{&blocks[0], nullptr, &start01, &poses[0]},
                                   {&blocks[1], &end01, &start12, &poses[1]},
                                   {&blocks[2], &end12, nullptr, &poses[2]}};
  std::vector<int> dominant;
  const std::vector<Pose> merged = BlendBlockPoses(times, views, &dominant);
  ASSERT_EQ(merged.size(), times.size());
  for (int i = 0; i <= 100; ++i) {
    const Eigen::Vector3d shift =
        merged[i].p_enu - Eigen::Vector3d(10.0 * i, 0.0, 0.0);
    const int own = i < 30 ? 0 : (i > 40 && i < 60) ? 1 : i > 70 ? 2 : -1;
    if (own >= 0) {
      EXPECT_LT((shift - offset[own]).norm(), 1e-9) << i;
      EXPECT_EQ(dominant[i], own) << i;
      continue;
    }
    // Inside an overlap: on the segment between the two blocks' offsets.
    const int a = i <= 40 ? 0 : 1;
    const Eigen::Vector3d d = offset[a + 1] - offset[a];
    const double u = (shift - offset[a]).dot(d) / d.squaredNorm();
    EXPECT_GE(u, -1e-9) << i;
    EXPECT_LE(u, 1.0 + 1e-9) << i;
    EXPECT_LT((shift - offset[a] - u * d).norm(), 1e-9) << i;
    const double angle =
        Eigen::AngleAxisd(merged[i].q_enu_body).angle() *
        (Eigen::AngleAxisd(merged[i].q_enu_body).axis().z() < 0 ? -1 : 1);
    EXPECT_NEAR(angle, yaw[a] + u * (yaw[a + 1] - yaw[a]), 1e-9) << i;
    // Smoothstep over 10 s: at most 1.5/10 of the difference per second.
    const Eigen::Vector3d before =
        merged[i - 1].p_enu - Eigen::Vector3d(10.0 * (i - 1), 0.0, 0.0);
    EXPECT_LE((shift - before).norm(), 0.15 * d.norm() + 1e-9) << i;
  }
  // A sample no block holds.
  blocks[1].first_sample = 45;
  blocks[1].start_time = 45.0;
  poses[1].erase(poses[1].begin(), poses[1].begin() + 15);
  EXPECT_THROW(BlendBlockPoses(times, views, &dominant), std::exception);
}

}  // namespace
}  // namespace zebrageo
