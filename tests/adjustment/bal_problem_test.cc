#include "adjustment/bal/bal_problem.h"

#include <ceres/numeric_diff_cost_function.h>
#include <ceres/rotation.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "adjustment/bal/bal_adjuster.h"
#include "adjustment/bal/snavely_reprojection_error.h"
#include "geodata/colmap_export.h"
#include "survey/input_error.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

std::string BalFile(const std::string& name) {
  const std::string folder = SharedDatasetsFolder();
  return folder.empty() ? "" : folder + "/bal/" + name;
}

#define SKIP_WITHOUT_DATASETS()                                             \
  if (SharedDatasetsFolder().empty()) {                                     \
    GTEST_SKIP() << "../shared/datasets is absent: BAL reference problems " \
                    "cannot be read";                                       \
  }

TEST(BalProblem, ReadsGtsamSubsetWithBlankLinesAndReproducesInitialCost) {
  SKIP_WITHOUT_DATASETS();
  const BalProblem problem =
      ReadBalProblem(BalFile("gtsam/dubrovnik-3-7-pre.txt"));
  EXPECT_EQ(problem.num_cameras(), 3);
  EXPECT_EQ(problem.num_points(), 7);
  EXPECT_EQ(problem.num_observations(), 19);
  // datasets/README.md: initial cost 2764.22.
  EXPECT_NEAR(BalCost(problem), 2764.22, 0.005);
  const BalProblem single =
      ReadBalProblem(BalFile("gtsam/dubrovnik-1-1-pre.txt"));
  EXPECT_NEAR(BalCost(single), 63.316, 0.0005);
  const BalProblem eighteen =
      ReadBalProblem(BalFile("gtsam/dubrovnik-3-7-18-pre.txt"));
  EXPECT_NEAR(BalCost(eighteen), 2753.17, 0.005);
}

TEST(BalProblem, ReadsBzip2ThroughLibbz2AndReproducesReferenceCosts) {
  SKIP_WITHOUT_DATASETS();
  struct Reference {
    const char* file;
    int cameras, points, observations;
    double initial_cost;
  };
  // Initial costs of datasets/README.md (7 significant digits there).
  const Reference references[] = {
      {"problem-16-22106-pre.txt.bz2", 16, 22106, 83718, 4.185660e+06},
      {"problem-21-11315-pre.txt.bz2", 21, 11315, 36455, 4.413239e+06},
      {"problem-49-7776-pre.txt.bz2", 49, 7776, 31843, 8.509125e+05},
  };
  for (const Reference& r : references) {
    const BalProblem problem = ReadBalProblem(BalFile(r.file));
    EXPECT_EQ(problem.num_cameras(), r.cameras) << r.file;
    EXPECT_EQ(problem.num_points(), r.points) << r.file;
    EXPECT_EQ(problem.num_observations(), r.observations) << r.file;
    const double cost = BalCost(problem);
    EXPECT_LT(std::abs(cost - r.initial_cost), 0.5e-6 * r.initial_cost)
        << r.file << ": " << cost;
  }
}

TEST(BalProblem, MalformedTextNamesTheLine) {
  try {
    ParseBalProblem("1 1 1\n0 0 1.0 2.0\n1 2 3 4 5 6 7 8 abc\n", "bad.txt");
    FAIL() << "expected an InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.line(), 3);
    EXPECT_NE(std::string(error.what()).find("abc"), std::string::npos);
  }
  EXPECT_THROW(ParseBalProblem("1 1 1\n0 5 1.0 2.0\n", "x"), InputError);
  EXPECT_THROW(ParseBalProblem("1 1 2\n0 0 1.0 2.0\n", "x"), InputError);
  EXPECT_THROW(ReadBalProblem("/nonexistent/file.bz2"), InputError);
}

// A random camera and point in front of it.
void RandomCameraAndPoint(std::mt19937* rng, double* camera, double* point) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 3; ++i) camera[i] = 0.3 * n(*rng);
  for (int i = 3; i < 6; ++i) camera[i] = 0.5 * n(*rng);
  camera[6] = 500.0 + 10.0 * n(*rng);
  camera[7] = 0.1 * n(*rng);
  camera[8] = 0.05 * n(*rng);
  // A point 4 to 12 m in front of the camera (BAL cameras look down -z).
  const double depth =
      4.0 + 8.0 * std::uniform_real_distribution<double>()(*rng);
  const Eigen::Vector3d in_camera(n(*rng), n(*rng), -depth);
  Eigen::Vector3d world;
  const double inverse[3] = {-camera[0], -camera[1], -camera[2]};
  const Eigen::Vector3d shifted =
      in_camera - Eigen::Vector3d(camera[3], camera[4], camera[5]);
  ceres::AngleAxisRotatePoint(inverse, shifted.data(), world.data());
  for (int i = 0; i < 3; ++i) point[i] = world[i];
}

TEST(SnavelyReprojectionCost, AnalyticAndAutodiffJacobiansMatchNumericDiff) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    double camera[9], point[3];
    RandomCameraAndPoint(&rng, camera, point);
    if (trial == 0) camera[0] = camera[1] = camera[2] = 0.0;  // theta = 0
    const double* parameters[2] = {camera, point};
    std::unique_ptr<ceres::CostFunction> analytic(
        SnavelyReprojectionCost::Create(12.0, -7.0));
    std::unique_ptr<ceres::CostFunction> autodiff(
        SnavelyReprojectionError::Create(12.0, -7.0));
    ceres::NumericDiffOptions numeric_options;
    std::unique_ptr<ceres::CostFunction> numeric(
        new ceres::NumericDiffCostFunction<SnavelyReprojectionError,
                                           ceres::RIDDERS, 2, 9, 3>(
            new SnavelyReprojectionError(12.0, -7.0), ceres::TAKE_OWNERSHIP, 2,
            numeric_options));
    double r[3][2];
    double j_camera[3][18], j_point[3][6];
    ceres::CostFunction* functions[3] = {analytic.get(), autodiff.get(),
                                         numeric.get()};
    for (int k = 0; k < 3; ++k) {
      double* jacobians[2] = {j_camera[k], j_point[k]};
      ASSERT_TRUE(functions[k]->Evaluate(parameters, r[k], jacobians));
    }
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(r[k][0], r[2][0], 1e-9);
      EXPECT_NEAR(r[k][1], r[2][1], 1e-9);
      for (int i = 0; i < 18; ++i) {
        EXPECT_NEAR(j_camera[k][i], j_camera[2][i],
                    1e-6 * (1.0 + std::abs(j_camera[2][i])))
            << "trial " << trial << " implementation " << k << " entry " << i;
      }
      for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(j_point[k][i], j_point[2][i],
                    1e-6 * (1.0 + std::abs(j_point[2][i])));
      }
    }
  }
}

TEST(BalProblem, ResidualOfSingleObservationEqualsHandComputation) {
  BalProblem problem;
  problem.cameras.push_back({0, 0, 0, 0.1, -0.2, 0.3, 500.0, 0.01, 0.001});
  problem.points.emplace_back(1.0, 2.0, -10.0);
  problem.observations.push_back({0, 0, Eigen::Vector2d(40.0, 80.0)});
  Eigen::Vector2d r;
  ASSERT_TRUE(BalResidual(problem, problem.observations[0], &r));
  const double z = -10.0 + 0.3;
  const double px = -(1.1) / z, py = -(1.8) / z;
  const double r2 = px * px + py * py;
  const double d = 1.0 + r2 * (0.01 + 0.001 * r2);
  EXPECT_NEAR(r.x(), 500.0 * d * px - 40.0, 1e-12);
  EXPECT_NEAR(r.y(), 500.0 * d * py - 80.0, 1e-12);
  EXPECT_NEAR(BalDepth(problem, problem.observations[0]), 9.7, 1e-12);
}

TEST(BalProblem, ColmapReductionDropsPointsBehindAndShortTracks) {
  BalProblem problem;
  for (int c = 0; c < 3; ++c) {
    problem.cameras.push_back({0, 0, 0, 0.1 * c, 0, 0, 500, 0, 0});
  }
  problem.points = {Eigen::Vector3d(0, 0, -5), Eigen::Vector3d(0, 0, -6),
                    Eigen::Vector3d(0, 0, 5)};
  for (int c = 0; c < 3; ++c) problem.observations.push_back({c, 0, {0, 0}});
  for (int c = 0; c < 2; ++c) problem.observations.push_back({c, 1, {0, 0}});
  for (int c = 0; c < 3; ++c) problem.observations.push_back({c, 2, {0, 0}});
  BalReduction reduction;
  const BalProblem reduced = ReduceLikeColmap(problem, 3, &reduction);
  EXPECT_EQ(reduction.dropped_behind, 3);
  EXPECT_EQ(reduction.dropped_short_track, 2);
  EXPECT_EQ(reduction.dropped_points, 2);
  EXPECT_EQ(reduced.num_points(), 1);
  EXPECT_EQ(reduced.num_observations(), 3);
  EXPECT_EQ(reduced.num_cameras(), 3);
}

TEST(BalProblem, ColmapModelRoundTripKeepsEveryResidual) {
  SKIP_WITHOUT_DATASETS();
  const BalProblem problem =
      ReadBalProblem(BalFile("gtsam/dubrovnik-3-7-pre.txt"));
  TemporaryFolder folder;
  WriteColmapModel(ColmapModelOf(problem), folder.Path("model"));
  const BalProblem back = BalProblemOf(ReadColmapModel(folder.Path("model")));
  ASSERT_EQ(back.num_observations(), problem.num_observations());
  EXPECT_NEAR(BalCost(back), BalCost(problem), 1e-9 * BalCost(problem));
  // Residual by residual: the model lists observations image by image.
  std::vector<BalObservation> by_image = problem.observations;
  std::stable_sort(by_image.begin(), by_image.end(),
                   [](const BalObservation& a, const BalObservation& b) {
                     return a.camera < b.camera;
                   });
  for (int i = 0; i < problem.num_observations(); ++i) {
    Eigen::Vector2d a, b;
    ASSERT_TRUE(BalResidual(problem, by_image[i], &a));
    ASSERT_TRUE(BalResidual(back, back.observations[i], &b));
    EXPECT_NEAR((a - b).norm(), 0.0, 1e-8);
  }
}

TEST(BalAdjuster, SolvesDubrovnikSubsetToConvergence) {
  SKIP_WITHOUT_DATASETS();
  BalProblem problem = ReadBalProblem(BalFile("gtsam/dubrovnik-3-7-pre.txt"));
  BalAdjusterOptions options;
  options.solver.num_threads = 1;
  const BalAdjusterSummary summary = AdjustBalProblem(options, &problem);
  ASSERT_TRUE(summary.IsUsable()) << summary.message;
  EXPECT_NEAR(summary.initial_cost, 2764.22, 0.005);
  EXPECT_LT(summary.final_cost, 0.01 * summary.initial_cost);
  EXPECT_NEAR(BalCost(problem), summary.final_cost,
              1e-9 * summary.initial_cost);
}

TEST(BalAdjuster, InvalidOptionsGiveUnusableSummaryAndKeepProblem) {
  BalProblem problem;
  problem.cameras.push_back({0, 0, 0, 0, 0, 0, 500, 0, 0});
  problem.points.emplace_back(0, 0, -5);
  problem.observations.push_back({0, 0, {1, 1}});
  BalAdjusterOptions options;
  options.solver.num_threads = 0;
  const BalAdjusterSummary summary = AdjustBalProblem(options, &problem);
  EXPECT_FALSE(summary.IsUsable());
  EXPECT_NE(summary.message.find("num_threads = 0: must be >= 1"),
            std::string::npos);
  EXPECT_EQ(problem.points[0].z(), -5.0);
}

TEST(BalAdjuster, Problem16MatchesCeresDocumentedFinalCost) {
  SKIP_WITHOUT_DATASETS();
  BalProblem problem = ReadBalProblem(BalFile("problem-16-22106-pre.txt.bz2"));
  BalAdjusterOptions options;
  options.solver.function_tolerance = 1e-6;  // Ceres' default, as documented
  const BalAdjusterSummary summary = AdjustBalProblem(options, &problem);
  ASSERT_TRUE(summary.IsUsable()) << summary.message;
  EXPECT_NEAR(summary.initial_cost, 4.185660e+06, 5.0);
  // Ceres documentation: 1.80339e4 after its default trust-region run.
  EXPECT_NEAR(summary.final_cost, 1.80339e4, 0.01 * 1.80339e4);
}

}  // namespace
}  // namespace zebrageo
