// StageResults: what a stage hands the next in memory is what a resumed run
// reads from the folder, bit for bit; what is absent says so.
#include "pipeline/stage_results.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

using ::testing::HasSubstr;

bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

// Vertices as the reconstruction makes them: full-precision doubles and
// covariances J C J^T that differ across the diagonal in their last bits.
std::vector<ReconstructedVertex> RandomVertices(int n) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::vector<ReconstructedVertex> vertices;
  for (int i = 0; i < n; ++i) {
    ReconstructedVertex v;
    v.exposure_id = 1000 + i / 8;
    v.band_id = i / 4;
    v.group_id = i / 16;
    v.vertex = i % 4;
    v.p_body = Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Matrix3d j = Eigen::Matrix3d::Random() * 0.01;
    v.covariance_body =
        j * Eigen::Vector3d(1e-4, 2e-4, 5e-4).asDiagonal() * j.transpose();
    v.covariance_body(1, 0) += 1e-22;  // the last bits of a product
    v.uv_left = Eigen::Vector2d(u(rng) + 500.0, u(rng) + 400.0);
    v.uv_right = v.uv_left - Eigen::Vector2d(30.0, 0.0);
    v.score = 0.5 + u(rng) / 50.0;
    vertices.push_back(v);
  }
  return vertices;
}

TEST(StageResults, HandedOverInMemoryIsWhatAResumedRunReads) {
  TemporaryFolder folder;
  std::vector<ReconstructedVertex> vertices = RandomVertices(64);
  const std::vector<SkippedExposure> skipped = {{1003, "unreadable image"}};
  // The reconstruct stage: writes its files, hands the data over.
  StageResults handed(folder.Path());
  WriteReconstructedBands(vertices, {"test"},
                          handed.PathOf(kReconstructedBandsFile));
  WriteSkippedExposures(skipped, handed.PathOf(kSkippedExposuresFile));
  handed.SetReconstruction(vertices, skipped);
  // A resumed run: the same folder, nothing in memory.
  StageResults resumed(folder.Path());

  const std::vector<ReconstructedVertex>& a = handed.Vertices();
  const std::vector<ReconstructedVertex>& b = resumed.Vertices();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].exposure_id, b[i].exposure_id);
    EXPECT_EQ(a[i].band_id, b[i].band_id);
    EXPECT_EQ(a[i].vertex, b[i].vertex);
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(SameBits(a[i].p_body[k], b[i].p_body[k]));
    }
    for (int k = 0; k < 9; ++k) {
      EXPECT_TRUE(SameBits(a[i].covariance_body.data()[k],
                           b[i].covariance_body.data()[k]))
          << "vertex " << i << " covariance element " << k;
    }
    EXPECT_TRUE(SameBits(a[i].score, b[i].score));
    EXPECT_TRUE(SameBits(a[i].uv_right.x(), b[i].uv_right.x()));
  }
  ASSERT_EQ(resumed.SkippedExposures().size(), 1u);
  EXPECT_EQ(resumed.SkippedExposures()[0].exposure_id, 1003);
  EXPECT_EQ(handed.SkippedExposures()[0].exposure_id, 1003);
}

TEST(StageResults, WhatAStageHandedOverIsNotReadBack) {
  TemporaryFolder folder;
  StageResults results(folder.Path());
  VertexMatch match;
  match.exposure_id = 1001;
  match.crossing_id = "C1";
  match.band = 2;
  results.SetMatches({match}, {});
  // Nothing on disk: the data in memory is used.
  ASSERT_EQ(results.Matches().size(), 1u);
  EXPECT_EQ(results.Matches()[0].crossing_id, "C1");
  EXPECT_TRUE(results.Decisions().empty());
}

TEST(StageResults, MissingStageFilesNameTheCommandToRun) {
  TemporaryFolder folder;
  StageResults results(folder.Path());
  try {
    results.Vertices();
    FAIL() << "no reconstructed_bands.csv, no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr(kReconstructedBandsFile));
    EXPECT_THAT(error.what(), HasSubstr("zebrageo reconstruct"));
  }
  try {
    results.Matches();
    FAIL() << "no matches.csv, no error";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr(kMatchesFile));
    EXPECT_THAT(error.what(), HasSubstr("zebrageo match"));
  }
  EXPECT_THROW(results.CorrectedTrajectory(), InputError);
  // Optional files: absent is no error.
  EXPECT_TRUE(results.SkippedExposures().empty());
  EXPECT_TRUE(results.Decisions().empty());
  EXPECT_EQ(results.LinePoints(), nullptr);
  EXPECT_EQ(results.Adjustment(), nullptr);
}

TEST(StageResults, AMalformedFileIsAnErrorNamingIt) {
  TemporaryFolder folder;
  folder.Write(kMatchesFile, "exposure_id,band_id\n1,2\n");
  StageResults results(folder.Path());
  try {
    results.Matches();
    FAIL() << "a matches.csv without its columns was accepted";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr(kMatchesFile));
  }
}

}  // namespace
}  // namespace zebrageo
