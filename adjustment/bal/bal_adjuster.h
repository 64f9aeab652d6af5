// Solves a BAL problem (bal_problem.h) with the project's solver core: the
// Snavely residual (analytic Jacobians by default), every camera and point
// free, cameras in the reduced camera system (points eliminated by Schur).
#ifndef ZEBRAGEO_ADJUSTMENT_BAL_BAL_ADJUSTER_H_
#define ZEBRAGEO_ADJUSTMENT_BAL_BAL_ADJUSTER_H_

#include <string>

#include "adjustment/bal/bal_problem.h"
#include "adjustment/solver_options.h"

namespace zebrageo {

struct BalAdjusterOptions {
  SolverOptions solver;
  // Analytic Jacobians (SnavelyReprojectionCost) or automatic
  // differentiation (SnavelyReprojectionError); same residuals.
  bool analytic_derivatives = true;

  std::string Check() const;
};

struct BalAdjusterSummary {
  bool usable = false;
  std::string message;  // why not usable, or Ceres' termination message
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int num_residuals = 0;
  int iterations = 0;
  double solve_time_in_seconds = 0.0;  // Ceres' total time
  std::string linear_solver;

  bool IsUsable() const { return usable; }
  std::string BriefReport() const;
};

// Adjusts `problem` in place. Returns a summary that is not usable (problem
// unchanged) when the options are invalid or the solve fails.
BalAdjusterSummary AdjustBalProblem(const BalAdjusterOptions& options,
                                    BalProblem* problem);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_BAL_BAL_ADJUSTER_H_
