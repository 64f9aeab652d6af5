// The solver core shared by the trajectory adjustment and the BAL solver:
// one options struct mapped onto ceres::Solver::Options, with the linear
// solver chosen from the problem's size the way COLMAP does (dense Schur for
// a few cameras, sparse Schur on SuiteSparse up to a few thousand, iterative
// Schur with a Schur-Jacobi preconditioner beyond).
#ifndef ZEBRAGEO_ADJUSTMENT_SOLVER_OPTIONS_H_
#define ZEBRAGEO_ADJUSTMENT_SOLVER_OPTIONS_H_

#include <ceres/solver.h>

#include <string>
#include <utility>
#include <vector>

namespace zebrageo {

enum class LinearSolver {
  kAuto,            // from the number of pose blocks, see ToCeresOptions
  kDenseSchur,      // best below ~50 pose blocks
  kSparseSchur,     // SuiteSparse Cholesky of the reduced camera system
  kIterativeSchur,  // conjugate gradients, Schur-Jacobi preconditioner
};

// LinearSolver's names (options files, adjustment.json).
inline const std::vector<std::pair<LinearSolver, const char*>>
    kLinearSolverNames = {{LinearSolver::kAuto, "auto"},
                          {LinearSolver::kDenseSchur, "DENSE_SCHUR"},
                          {LinearSolver::kSparseSchur, "SPARSE_SCHUR"},
                          {LinearSolver::kIterativeSchur, "ITERATIVE_SCHUR"}};

struct SolverOptions {
  LinearSolver linear_solver = LinearSolver::kAuto;
  // Pose blocks up to which kAuto uses DENSE_SCHUR, then SPARSE_SCHUR up to
  // max_sparse_pose_blocks, then ITERATIVE_SCHUR (very large surveys: the
  // sparse factorisation of a long banded system stays cheap, so the limit
  // is high).
  int max_dense_pose_blocks = 50;
  int max_sparse_pose_blocks = 200000;
  // Threads for Jacobian evaluation and the Schur complement. 2 matches the
  // project's machines; more only helps on bigger ones.
  int num_threads = 2;
  int max_num_iterations = 100;
  // Convergence: relative cost decrease, max-norm gradient, relative step.
  double function_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-10;
  double max_solver_time_in_seconds = 1800.0;
  // Print Ceres' per-iteration progress (debugging).
  bool minimizer_progress_to_stdout = false;

  // "" when valid, else "field = value: constraint".
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("linear_solver", linear_solver, kLinearSolverNames);
    v("max_dense_pose_blocks", max_dense_pose_blocks);
    v("max_sparse_pose_blocks", max_sparse_pose_blocks);
    v("num_threads", num_threads);
    v("max_num_iterations", max_num_iterations);
    v("function_tolerance", function_tolerance);
    v("gradient_tolerance", gradient_tolerance);
    v("parameter_tolerance", parameter_tolerance);
    v("max_solver_time_in_seconds", max_solver_time_in_seconds);
    v("minimizer_progress_to_stdout", minimizer_progress_to_stdout);
  }
};

// The Ceres options for a problem with `num_pose_blocks` camera/pose
// parameter blocks (the ones kept in the reduced camera system).
ceres::Solver::Options ToCeresOptions(const SolverOptions& options,
                                      int num_pose_blocks);

const char* LinearSolverName(LinearSolver solver);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_SOLVER_OPTIONS_H_
