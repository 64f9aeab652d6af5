#include "adjustment/solver_options.h"

#include <cmath>
#include <sstream>

namespace zebrageo {
namespace {

template <typename T>
std::string Violation(const char* field, T value, const char* constraint) {
  std::ostringstream message;
  message << field << " = " << value << ": " << constraint;
  return message.str();
}

}  // namespace

std::string SolverOptions::Check() const {
  if (max_dense_pose_blocks < 0) {
    return Violation("max_dense_pose_blocks", max_dense_pose_blocks,
                     "must be >= 0");
  }
  if (max_sparse_pose_blocks < max_dense_pose_blocks) {
    return Violation("max_sparse_pose_blocks", max_sparse_pose_blocks,
                     "must be >= max_dense_pose_blocks");
  }
  if (num_threads < 1) {
    return Violation("num_threads", num_threads, "must be >= 1");
  }
  if (max_num_iterations < 0) {
    return Violation("max_num_iterations", max_num_iterations, "must be >= 0");
  }
  if (!(function_tolerance >= 0.0)) {
    return Violation("function_tolerance", function_tolerance, "must be >= 0");
  }
  if (!(gradient_tolerance >= 0.0)) {
    return Violation("gradient_tolerance", gradient_tolerance, "must be >= 0");
  }
  if (!(parameter_tolerance >= 0.0)) {
    return Violation("parameter_tolerance", parameter_tolerance,
                     "must be >= 0");
  }
  if (!(max_solver_time_in_seconds > 0.0)) {
    return Violation("max_solver_time_in_seconds", max_solver_time_in_seconds,
                     "must be > 0");
  }
  return "";
}

const char* LinearSolverName(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::kAuto:
      return "auto";
    case LinearSolver::kDenseSchur:
      return "DENSE_SCHUR";
    case LinearSolver::kSparseSchur:
      return "SPARSE_SCHUR";
    case LinearSolver::kIterativeSchur:
      return "ITERATIVE_SCHUR";
  }
  return "?";
}

ceres::Solver::Options ToCeresOptions(const SolverOptions& options,
                                      int num_pose_blocks) {
  ceres::Solver::Options ceres_options;
  LinearSolver solver = options.linear_solver;
  if (solver == LinearSolver::kAuto) {
    if (num_pose_blocks <= options.max_dense_pose_blocks) {
      solver = LinearSolver::kDenseSchur;
    } else if (num_pose_blocks <= options.max_sparse_pose_blocks) {
      solver = LinearSolver::kSparseSchur;
    } else {
      solver = LinearSolver::kIterativeSchur;
    }
  }
  switch (solver) {
    case LinearSolver::kAuto:
    case LinearSolver::kDenseSchur:
      ceres_options.linear_solver_type = ceres::DENSE_SCHUR;
      break;
    case LinearSolver::kSparseSchur:
      ceres_options.linear_solver_type = ceres::SPARSE_SCHUR;
      ceres_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
      break;
    case LinearSolver::kIterativeSchur:
      ceres_options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      ceres_options.preconditioner_type = ceres::SCHUR_JACOBI;
      break;
  }
  ceres_options.num_threads = options.num_threads;
  ceres_options.max_num_iterations = options.max_num_iterations;
  ceres_options.function_tolerance = options.function_tolerance;
  ceres_options.gradient_tolerance = options.gradient_tolerance;
  ceres_options.parameter_tolerance = options.parameter_tolerance;
  ceres_options.max_solver_time_in_seconds = options.max_solver_time_in_seconds;
  ceres_options.minimizer_progress_to_stdout =
      options.minimizer_progress_to_stdout;
  ceres_options.logging_type = options.minimizer_progress_to_stdout
                                   ? ceres::PER_MINIMIZER_ITERATION
                                   : ceres::SILENT;
  return ceres_options;
}

}  // namespace zebrageo
