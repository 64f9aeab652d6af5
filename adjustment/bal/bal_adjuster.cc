#include "adjustment/bal/bal_adjuster.h"

#include <ceres/problem.h>
#include <ceres/solver.h>
#include <glog/logging.h>

#include <cmath>
#include <sstream>

#include "adjustment/bal/snavely_reprojection_error.h"

namespace zebrageo {

std::string BalAdjusterOptions::Check() const { return solver.Check(); }

std::string BalAdjusterSummary::BriefReport() const {
  std::ostringstream out;
  out << (usable ? "usable" : "NOT usable") << ": cost " << initial_cost
      << " -> " << final_cost << " in " << iterations << " iterations, "
      << solve_time_in_seconds << " s (" << linear_solver << ")";
  if (!message.empty()) out << "; " << message;
  return out.str();
}

BalAdjusterSummary AdjustBalProblem(const BalAdjusterOptions& options,
                                    BalProblem* problem) {
  BalAdjusterSummary summary;
  const std::string error = options.Check();
  if (!error.empty()) {
    summary.message = "invalid BalAdjusterOptions: " + error;
    return summary;
  }
  if (problem->observations.empty()) {
    summary.message = "the problem has no observations";
    return summary;
  }
  BalProblem working = *problem;
  ceres::Problem::Options problem_options;
  problem_options.enable_fast_removal = false;
  ceres::Problem ceres_problem(problem_options);
  for (const BalObservation& o : working.observations) {
    ceres::CostFunction* cost =
        options.analytic_derivatives
            ? SnavelyReprojectionCost::Create(o.xy.x(), o.xy.y())
            : SnavelyReprojectionError::Create(o.xy.x(), o.xy.y());
    ceres_problem.AddResidualBlock(cost, nullptr,
                                   working.cameras[o.camera].data(),
                                   working.points[o.point].data());
  }
  ceres::Solver::Options ceres_options =
      ToCeresOptions(options.solver, working.num_cameras());
  // Eliminate points first: the reduced camera system.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (Eigen::Vector3d& point : working.points) {
    ordering->AddElementToGroup(point.data(), 0);
  }
  for (auto& camera : working.cameras) {
    ordering->AddElementToGroup(camera.data(), 1);
  }
  ceres_options.linear_solver_ordering = ordering;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(ceres_options, &ceres_problem, &ceres_summary);

  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  summary.num_residuals = ceres_summary.num_residuals;
  summary.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary.solve_time_in_seconds = ceres_summary.total_time_in_seconds;
  summary.linear_solver =
      ceres::LinearSolverTypeToString(ceres_summary.linear_solver_type_used);
  summary.message = ceres_summary.message;
  summary.usable = ceres_summary.IsSolutionUsable() &&
                   std::isfinite(ceres_summary.final_cost);
  if (summary.usable) *problem = std::move(working);
  VLOG(1) << ceres_summary.FullReport();
  return summary;
}

}  // namespace zebrageo
