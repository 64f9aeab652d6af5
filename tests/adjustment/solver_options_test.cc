// SolverOptions (adjustment/solver_options.h): the linear solver kAuto picks
// for a problem's size, the fields copied into ceres::Solver::Options, and
// Check() naming the field, its value and the rule it breaks.
#include "adjustment/solver_options.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace zebrageo {
namespace {

TEST(SolverOptions, DefaultsAreValid) {
  EXPECT_EQ(SolverOptions().Check(), "");
}

// COLMAP's rule: dense Schur for a few pose blocks, sparse Schur on
// SuiteSparse up to the sparse limit, iterative Schur beyond; the limits are
// inclusive.
TEST(SolverOptions, AutoPicksTheSolverFromThePoseBlocks) {
  SolverOptions options;
  options.max_dense_pose_blocks = 50;
  options.max_sparse_pose_blocks = 1000;
  struct Case {
    int pose_blocks;
    ceres::LinearSolverType expected;
  };
  for (const Case& c :
       {Case{0, ceres::DENSE_SCHUR}, Case{1, ceres::DENSE_SCHUR},
        Case{50, ceres::DENSE_SCHUR}, Case{51, ceres::SPARSE_SCHUR},
        Case{1000, ceres::SPARSE_SCHUR}, Case{1001, ceres::ITERATIVE_SCHUR},
        Case{1000000, ceres::ITERATIVE_SCHUR}}) {
    SCOPED_TRACE(c.pose_blocks);
    const ceres::Solver::Options ceres_options =
        ToCeresOptions(options, c.pose_blocks);
    EXPECT_EQ(ceres_options.linear_solver_type, c.expected);
    std::string why;
    EXPECT_TRUE(ceres_options.IsValid(&why)) << why;
  }
}

TEST(SolverOptions, SparseSchurUsesSuiteSparseAndIterativeSchurJacobi) {
  SolverOptions options;
  options.linear_solver = LinearSolver::kSparseSchur;
  const ceres::Solver::Options sparse = ToCeresOptions(options, 3);
  EXPECT_EQ(sparse.linear_solver_type, ceres::SPARSE_SCHUR);
  EXPECT_EQ(sparse.sparse_linear_algebra_library_type, ceres::SUITE_SPARSE);

  options.linear_solver = LinearSolver::kIterativeSchur;
  const ceres::Solver::Options iterative = ToCeresOptions(options, 3);
  EXPECT_EQ(iterative.linear_solver_type, ceres::ITERATIVE_SCHUR);
  EXPECT_EQ(iterative.preconditioner_type, ceres::SCHUR_JACOBI);
}

// A solver chosen explicitly is kept whatever the problem's size.
TEST(SolverOptions, AnExplicitSolverIgnoresTheSize) {
  SolverOptions options;
  options.linear_solver = LinearSolver::kDenseSchur;
  EXPECT_EQ(ToCeresOptions(options, 500000).linear_solver_type,
            ceres::DENSE_SCHUR);
  options.linear_solver = LinearSolver::kIterativeSchur;
  EXPECT_EQ(ToCeresOptions(options, 2).linear_solver_type,
            ceres::ITERATIVE_SCHUR);
}

TEST(SolverOptions, ThreadsToleranceAndLimitsReachCeres) {
  SolverOptions options;
  options.num_threads = 7;
  options.max_num_iterations = 33;
  options.function_tolerance = 1e-7;
  options.gradient_tolerance = 1e-9;
  options.parameter_tolerance = 1e-6;
  options.max_solver_time_in_seconds = 12.5;
  const ceres::Solver::Options ceres_options = ToCeresOptions(options, 10);
  EXPECT_EQ(ceres_options.num_threads, 7);
  EXPECT_EQ(ceres_options.max_num_iterations, 33);
  EXPECT_EQ(ceres_options.function_tolerance, 1e-7);
  EXPECT_EQ(ceres_options.gradient_tolerance, 1e-9);
  EXPECT_EQ(ceres_options.parameter_tolerance, 1e-6);
  EXPECT_EQ(ceres_options.max_solver_time_in_seconds, 12.5);
}

// Quiet unless progress is asked for: the CLI draws its own bars.
TEST(SolverOptions, ProgressOnlyWhenAskedFor) {
  SolverOptions options;
  ceres::Solver::Options quiet = ToCeresOptions(options, 10);
  EXPECT_FALSE(quiet.minimizer_progress_to_stdout);
  EXPECT_EQ(quiet.logging_type, ceres::SILENT);
  options.minimizer_progress_to_stdout = true;
  ceres::Solver::Options loud = ToCeresOptions(options, 10);
  EXPECT_TRUE(loud.minimizer_progress_to_stdout);
  EXPECT_EQ(loud.logging_type, ceres::PER_MINIMIZER_ITERATION);
}

TEST(SolverOptions, CheckNamesTheFieldTheValueAndTheRule) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    void (*set)(SolverOptions*, double);
    double value;
    std::string expected;
  };
  const Case cases[] = {
      {[](SolverOptions* o, double v) {
         o->max_dense_pose_blocks = static_cast<int>(v);
       },
       -1, "max_dense_pose_blocks = -1: must be >= 0"},
      {[](SolverOptions* o, double v) {
         o->max_sparse_pose_blocks = static_cast<int>(v);
       },
       49,
       "max_sparse_pose_blocks = 49: must be >= max_dense_pose_blocks (50)"},
      {[](SolverOptions* o, double v) { o->num_threads = static_cast<int>(v); },
       0, "num_threads = 0: must be >= 1"},
      {[](SolverOptions* o, double v) {
         o->max_num_iterations = static_cast<int>(v);
       },
       -3, "max_num_iterations = -3: must be >= 0"},
      {[](SolverOptions* o, double v) { o->function_tolerance = v; }, -1e-6,
       "function_tolerance = -1e-06: must be >= 0"},
      {[](SolverOptions* o, double v) { o->gradient_tolerance = v; }, nan,
       "gradient_tolerance = nan: must be >= 0"},
      {[](SolverOptions* o, double v) { o->parameter_tolerance = v; }, -2,
       "parameter_tolerance = -2: must be >= 0"},
      {[](SolverOptions* o, double v) { o->max_solver_time_in_seconds = v; }, 0,
       "max_solver_time_in_seconds = 0: must be > 0"},
      {[](SolverOptions* o, double v) { o->max_solver_time_in_seconds = v; },
       nan, "max_solver_time_in_seconds = nan: must be > 0"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    SolverOptions options;
    c.set(&options, c.value);
    EXPECT_EQ(options.Check(), c.expected);
  }
}

// Equal limits leave no sparse range: every size above is iterative.
TEST(SolverOptions, EqualLimitsAreValidAndSkipTheSparseRange) {
  SolverOptions options;
  options.max_dense_pose_blocks = 10;
  options.max_sparse_pose_blocks = 10;
  EXPECT_EQ(options.Check(), "");
  EXPECT_EQ(ToCeresOptions(options, 10).linear_solver_type, ceres::DENSE_SCHUR);
  EXPECT_EQ(ToCeresOptions(options, 11).linear_solver_type,
            ceres::ITERATIVE_SCHUR);
}

TEST(SolverOptions, NamesTheLinearSolvers) {
  EXPECT_STREQ(LinearSolverName(LinearSolver::kAuto), "auto");
  EXPECT_STREQ(LinearSolverName(LinearSolver::kDenseSchur), "DENSE_SCHUR");
  EXPECT_STREQ(LinearSolverName(LinearSolver::kSparseSchur), "SPARSE_SCHUR");
  EXPECT_STREQ(LinearSolverName(LinearSolver::kIterativeSchur),
               "ITERATIVE_SCHUR");
}

}  // namespace
}  // namespace zebrageo
