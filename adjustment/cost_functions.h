// Residuals of the trajectory adjustment, one header per family:
//   reprojection_costs.h    a point in a camera (reprojection) or in the
//                           body frame (a stereo-reconstructed vertex)
//                           through the corrected trajectory
//   prior_costs.h           database vertices, linear and Gauss-Markov
//                           priors on the knots and the exposures' offsets
//   exposure_offset_cost.h  an exposure's jitter offset added to a residual
//   vehicle_motion.h        the vehicle moves along its heading
//   line_costs.h            road-line points on database lines
// Frames: ENU (the survey's working frame), body (FRD), camera (OpenCV).
// Knot blocks are [dtheta (rad, ENU rotation vector), dp (m, ENU)] of
// trajectory_correction.h; rotation vectors are applied with
// ceres::AngleAxisRotatePoint (Hamilton, active). Every residual is
// whitened by its sqrt_information (r = S e), so a residual of 1 is one
// standard deviation.
#ifndef ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_
#define ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_

#include "adjustment/exposure_offset_cost.h"
#include "adjustment/prior_costs.h"
#include "adjustment/reprojection_costs.h"

#endif  // ZEBRAGEO_ADJUSTMENT_COST_FUNCTIONS_H_
