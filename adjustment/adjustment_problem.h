// Internal to the trajectory adjustment: the Ceres problem of one solve,
// built from the State (adjustment_state.h), and the statistics of its
// residual groups for the variance components (variance_components.h).
#ifndef ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_PROBLEM_H_
#define ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_PROBLEM_H_

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <memory>
#include <vector>

#include "adjustment/adjustment_state.h"
#include "adjustment/trajectory_adjuster.h"
#include "survey/rig.h"

namespace zebrageo {
namespace adjustment_internal {

// Residual block ids of each observation type.
struct Blocks {
  std::vector<ceres::ResidualBlockId> control_images;
  std::vector<ceres::ResidualBlockId> tie_images;
  std::vector<ceres::ResidualBlockId> control_priors;
  // The knots' Gauss-Markov priors, per knot (first knot first).
  std::vector<ceres::ResidualBlockId> position_prior;
  std::vector<ceres::ResidualBlockId> attitude_prior;
  std::vector<ceres::ResidualBlockId> motion;
  std::vector<ceres::ResidualBlockId> lines;
};

class AdjustmentProblem {
 public:
  // `robust`: with the loss functions of the options (the first solve of
  // an adjustment is plain least squares, see trajectory_adjuster.cc).
  AdjustmentProblem(const AdjustmentOptions& options, const Rig& rig,
                    bool robust, State* state);

  ceres::Problem* problem() { return problem_.get(); }
  const Blocks& blocks() const { return blocks_; }

  // Stops between iterations once `cancel` is cancelled (the summary then
  // says so; the caller throws).
  ceres::Solver::Summary Solve(const CancellationToken& cancel = {});

  // sqrt(sum r^2 / (residuals - free parameters)), without loss functions.
  double Sigma0();

  // The whitened residuals of each block (no loss function), concatenated.
  std::vector<double> Residuals(const std::vector<ceres::ResidualBlockId>& ids);

 private:
  void AddImageResidual(const ImageObservation& o, double* point,
                        double sigma_px,
                        std::vector<ceres::ResidualBlockId>* ids);
  void AddKnotPriors();
  // The attitude axes of State::attitude_held, and the along-track
  // position with State::along_track_held, fixed on every knot.
  void HoldAxes();
  void AddRigPriors();
  void AddControl();
  void AddTiesAndLines();
  void AddVehicleMotion();
  void AddExposureOffsets();
  // `cost` with the exposure's offset block appended when the model has
  // jitter (cost_functions.h, WithExposureOffset).
  ceres::ResidualBlockId AddWithExposure(ceres::CostFunction* cost,
                                         ceres::LossFunction* loss,
                                         std::vector<double*> blocks,
                                         int exposure);

  const AdjustmentOptions& options_;
  const Rig& rig_;
  State* state_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::LossFunction> image_loss_;
  std::unique_ptr<ceres::LossFunction> control_loss_;
  std::unique_ptr<ceres::LossFunction> line_loss_;
  std::unique_ptr<ceres::LossFunction> motion_loss_;
  Blocks blocks_;
  int num_pose_blocks_ = 0;
};

}  // namespace adjustment_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_ADJUSTMENT_PROBLEM_H_
