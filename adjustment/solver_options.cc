#include "adjustment/solver_options.h"

#include <cmath>
#include <sstream>

#include "survey/option_check.h"

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
  OptionCheck check;
  OPTION_GE(check, max_dense_pose_blocks, 0);
  OPTION_GE(check, max_sparse_pose_blocks, max_dense_pose_blocks);
  OPTION_GE(check, num_threads, 1);
  OPTION_GE(check, max_num_iterations, 0);
  OPTION_GE(check, function_tolerance, 0.0);
  OPTION_GE(check, gradient_tolerance, 0.0);
  OPTION_GE(check, parameter_tolerance, 0.0);
  OPTION_GT(check, max_solver_time_in_seconds, 0.0);
  return check.problem();
}

const char* LinearSolverName(LinearSolver solver) {
  for (const auto& [value, name] : kLinearSolverNames) {
    if (value == solver) return name;
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
