// "Vertical" epipolar rectification of a stereo pair over the road plane
// (road_plane.h; Soheilian et al., section 3.2).
//
// Frames: body = FRD (x forward, y right, z down), metres. A virtual camera
// ("virt") looks straight down at the road plane: its z axis is the road
// normal (pointing down, away from the cameras) made orthogonal to the
// baseline, its x axis is the baseline (left camera centre to right camera
// centre), y = z x x. Both virtual cameras share that rotation and the focal
// length; each sits at its original camera's centre, so a rectified image is
// a pure rotation (plus distortion removal) of the original one and epipolar
// lines are image rows.
//
// Seen from above, the rectified images are orthoimages of the road: a road
// mark keeps its shape and size in both images (the "road plane adaptive"
// geometry), and a road point has the same pixel in both images: the right
// virtual principal point is shifted by `disparity_offset_px` = f B / h0
// (h0: the road's depth below the cameras at the image centre). With
// d = x_left - x_right (the "residual" disparity, ~0 on the road),
// f B / Z = d + disparity_offset_px.
#ifndef ZEBRAGEO_RECONSTRUCTION_ROAD_RECTIFICATION_H_
#define ZEBRAGEO_RECONSTRUCTION_ROAD_RECTIFICATION_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "reconstruction/road_plane.h"
#include "survey/rig.h"

namespace zebrageo {

struct RectificationOptions {
  // Ground sample distance of the rectified images on the road plane,
  // metres per pixel. Smaller keeps more of the original resolution near the
  // vehicle but costs time (pixels grow as 1/gsd^2).
  double ground_pixel_m = 0.015;
  // The rectified images cover the road visible in both cameras up to this
  // horizontal distance from the left camera (bands are scored up to 15 m;
  // a 6 m band centred at 15 m reaches 18 m).
  double max_range_m = 20.0;
  // ... and within this distance across (along the baseline) from the
  // middle of the two cameras: a road with its sidewalks; farther is
  // facades and parked cars, and costs time.
  double max_lateral_m = 14.0;
  // Largest rectified image side, pixels: a guard against absurd rigs.
  int max_image_side_px = 4096;
  // Pixels closer than this to the border of either original image are
  // marked invalid (gradients there are artefacts of the border).
  int border_margin_px = 4;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("ground_pixel_m", ground_pixel_m);
    v("max_range_m", max_range_m);
    v("max_lateral_m", max_lateral_m);
    v("max_image_side_px", max_image_side_px);
    v("border_margin_px", border_margin_px);
  }
};

class RoadRectification {
 public:
  // Builds the virtual cameras and remap tables of the stereo pair
  // (left, right) for the road plane `plane`. Returns false with `error`
  // when the geometry is unusable (no common road footprint, baseline along
  // the road normal...).
  bool Build(const RigCamera& left, const RigCamera& right,
             const RoadPlane& plane, const RectificationOptions& options,
             std::string* error);

  // Resamples the original (distorted) CV_32F images into the rectified
  // geometry (bilinear). Pixels outside an original image are 0.
  void Rectify(const cv::Mat& left_image, const cv::Mat& right_image,
               cv::Mat* left_rectified, cv::Mat* right_rectified) const;

  int width() const { return width_; }
  int height() const { return height_; }
  double focal_px() const { return focal_px_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  double baseline_m() const { return baseline_m_; }
  double disparity_offset_px() const { return disparity_offset_px_; }
  double ground_pixel_m() const { return ground_pixel_m_; }
  const Eigen::Matrix3d& R_body_virt() const { return R_body_virt_; }
  const Eigen::Vector3d& left_centre_body() const { return centre_body_[0]; }
  const Eigen::Vector3d& right_centre_body() const { return centre_body_[1]; }
  // CV_8U, 255 where the pixel is seen by both original cameras (less the
  // border margin) and lies within max_range_m.
  const cv::Mat& valid_mask() const { return valid_; }
  bool IsValid(double x, double y) const;

  // Body point from a left pixel (x, y) and the right abscissa x_right on
  // the same row y. False when the depth is not positive.
  bool Triangulate(double x_left, double x_right, double y,
                   Eigen::Vector3d* p_body) const;
  // d p_body / d (x_left, x_right, y) at that point (3x3).
  Eigen::Matrix3d TriangulationJacobian(double x_left, double x_right,
                                        double y) const;
  // Rectified pixel of a body point in camera `side` (0 left, 1 right).
  // False when the point is behind the virtual camera.
  bool ProjectToRectified(int side, const Eigen::Vector3d& p_body,
                          Eigen::Vector2d* xy) const;
  // Body direction (not normalised) of the ray through rectified pixel xy.
  Eigen::Vector3d RayBody(int side, const Eigen::Vector2d& xy) const;
  // Residual disparity d = x_left - x_right of a body point (NaN behind).
  double DisparityOf(const Eigen::Vector3d& p_body) const;

 private:
  // Build, after the geometry: the remap tables of both images, and
  // `valid` (CV_8U, 255) cleared where a camera does not see (or sees
  // within border_margin_px of its border).
  void BuildRemapTables(const RigCamera* const cameras[2],
                        const RectificationOptions& options, cv::Mat* valid);
  // ... and cleared beyond max_range_m of the left camera's nadir or
  // max_lateral_m across from `middle`, on the road plane.
  void ClearBeyondRange(const RoadPlane& plane,
                        const Eigen::Vector3d& nadir_left,
                        const Eigen::Vector3d& middle,
                        const RectificationOptions& options,
                        cv::Mat* valid) const;

  int width_ = 0;
  int height_ = 0;
  double focal_px_ = 0.0;
  double cx_ = 0.0;
  double cy_ = 0.0;
  double baseline_m_ = 0.0;
  double disparity_offset_px_ = 0.0;
  double ground_pixel_m_ = 0.0;
  Eigen::Matrix3d R_body_virt_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre_body_[2];
  cv::Mat map1_[2];  // CV_16SC2 + CV_16UC1 fixed-point remap tables
  cv::Mat map2_[2];
  cv::Mat valid_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_ROAD_RECTIFICATION_H_
