// Internal to the trajectory adjustment: the solves. Each adjustment is
// solved twice, first by plain least squares (the drift makes every
// observation look like an outlier at the start), then with the robust
// losses; then control vertices and whole crossings whose normalised
// residual exceeds blunder_threshold are rejected and the adjustment
// repeated (the blunder loop). Around it, RunAdjustments holds the check
// crossings out of a first adjustment and repeats the adjustment while the
// variance components widen the soft constraints' sigmas.
#ifndef ZEBRAGEO_ADJUSTMENT_BLUNDER_LOOP_H_
#define ZEBRAGEO_ADJUSTMENT_BLUNDER_LOOP_H_

#include <functional>
#include <memory>
#include <string>

#include "adjustment/adjustment_context.h"
#include "adjustment/adjustment_problem.h"
#include "adjustment/adjustment_state.h"

namespace zebrageo {
namespace adjustment_internal {

// The solves: least squares, then robust, then the blunder loop.
class AdjustmentSolver {
 public:
  // `progress(done, total)` after each solve when set.
  AdjustmentSolver(const Context& context, State* state,
                   const std::function<void(int, int)>& progress)
      : context_(context), state_(state), progress_(progress) {}

  // The problem of the last solve (null before the first).
  AdjustmentProblem* problem() { return problem_.get(); }

  // False (summary.message set) when a solve fails. Sets summary.sigma0.
  bool Adjust();

  // Whether any point is still ControlStatus::kControl.
  bool HasControl() const;

 private:
  bool SolveTwice() { return Solve(false) && Solve(true); }
  bool Solve(bool robust);
  // Rejects the worst control vertices and crossings; false when none
  // exceeds the threshold.
  bool RejectBlunders();

  const Context& context_;
  State* state_;
  std::function<void(int, int)> progress_;
  std::unique_ptr<AdjustmentProblem> problem_;
};

// Check points: their residuals from the adjustment that did not see them
// (held_out_*), then control in the final adjustment.
void HoldOutCheckPoints(const Context& context, State* state);

// Every adjustment of the run: with the check crossings held out, again
// with them as control (check_points_in_final), and again while the
// variance components change. False when the trajectory is not corrected,
// with the reason in `why_not` (no control at all, a failed solve, every
// control point rejected).
bool RunAdjustments(const Context& context, State* state,
                    AdjustmentSolver* solver, std::string* why_not);

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_BLUNDER_LOOP_H_
