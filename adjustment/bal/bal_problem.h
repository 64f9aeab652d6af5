// Bundle Adjustment in the Large (BAL) problems: reading, cost, the
// reduction COLMAP applies, and an exact conversion to a COLMAP text model.
//
// BAL format (Agarwal, Snavely, Seitz, Szeliski, "Bundle Adjustment in the
// Large", ECCV 2010): a header "num_cameras num_points num_observations",
// then one "camera point x y" line per observation (pixels, origin at the
// image centre, y up), then 9 numbers per camera and 3 per point, all
// whitespace separated (blank lines allowed, as in GTSAM's subsets).
//
// Camera model (Bundler): parameters [w(3), t(3), f, k1, k2] with w a
// Rodrigues (angle-axis) vector, radians.
//   P = R(w) X + t          X in the world frame, P in the camera frame
//   p = -P.xy / P.z         the camera looks down -z
//   pixel = f (1 + k1 |p|^2 + k2 |p|^4) p
// The cost of a problem is 1/2 sum |pixel - observed|^2, as Ceres reports it.
#ifndef ZEBRAGEO_ADJUSTMENT_BAL_BAL_PROBLEM_H_
#define ZEBRAGEO_ADJUSTMENT_BAL_BAL_PROBLEM_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "survey/colmap_model.h"

namespace zebrageo {

constexpr int kBalCameraSize = 9;

struct BalObservation {
  int camera = 0;
  int point = 0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // pixels, BAL convention
};

struct BalProblem {
  // [w(3), t(3), f, k1, k2] per camera.
  std::vector<std::array<double, kBalCameraSize>> cameras;
  std::vector<Eigen::Vector3d> points;
  std::vector<BalObservation> observations;

  int num_cameras() const { return static_cast<int>(cameras.size()); }
  int num_points() const { return static_cast<int>(points.size()); }
  int num_observations() const { return static_cast<int>(observations.size()); }
};

// Reads a BAL file, plain text or bzip2-compressed (decided by the content,
// not the name; read through libbz2). Throws InputError naming the file and
// the problem: unreadable, truncated, a non-number, indices out of range,
// non-finite values.
BalProblem ReadBalProblem(const std::string& path);
// Parses BAL text held in memory.
BalProblem ParseBalProblem(const std::string& text,
                           const std::string& display_name);

// Reprojection residual (predicted - observed, pixels) of one observation;
// false when the point is on the camera's principal plane (P.z == 0).
bool BalResidual(const BalProblem& problem, const BalObservation& observation,
                 Eigen::Vector2d* residual);
// 1/2 sum of squared residuals over all observations.
double BalCost(const BalProblem& problem);

// Point depth along the viewing direction of the camera (-P.z): positive in
// front of a BAL camera.
double BalDepth(const BalProblem& problem, const BalObservation& observation);

struct BalReduction {
  int dropped_behind = 0;       // observations with depth <= 0
  int dropped_short_track = 0;  // observations of points left with < 3
  int dropped_points = 0;
  int dropped_cameras = 0;  // cameras left without observations
};

// The reduced problem COLMAP's bundle adjustment effectively solves:
// observations of points behind their camera are removed first, then the
// points observed by fewer than `min_track_length` images (COLMAP keeps
// tracks of 3 images and more). Unobserved points and cameras are removed
// and the rest renumbered in their original order.
BalProblem ReduceLikeColmap(const BalProblem& problem, int min_track_length,
                            BalReduction* reduction);

// `problem` as a COLMAP text model (geodata/colmap_export.h writes it),
// converted exactly: one RADIAL camera (f, cx, cy, k1, k2) per BAL camera,
// rotation flipped to COLMAP's +z viewing direction (R_colmap =
// diag(1,-1,-1) R_bal), image coordinates shifted by (cx, cy) with y
// mirrored. Each residual, hence the cost, is the same as in BAL as long as
// the principal point is held fixed (COLMAP's default).
ColmapModel ColmapModelOf(const BalProblem& problem);
// A COLMAP model made by ColmapModelOf (or by COLMAP from it, e.g. after
// `colmap bundle_adjuster` and `colmap model_converter --output_type TXT`)
// back into a BAL problem, inverting the conversion. Throws InputError for
// a camera model other than RADIAL.
BalProblem BalProblemOf(const ColmapModel& model);

}  // namespace zebrageo

#endif  // ZEBRAGEO_ADJUSTMENT_BAL_BAL_PROBLEM_H_
