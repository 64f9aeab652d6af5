#include "reconstruction/road_rectification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Step of the grid of original pixels used to find the road footprint.
constexpr int kFootprintStepPx = 8;

struct Box {
  double x_min = std::numeric_limits<double>::infinity();
  double y_min = std::numeric_limits<double>::infinity();
  double x_max = -std::numeric_limits<double>::infinity();
  double y_max = -std::numeric_limits<double>::infinity();
  void Add(double x, double y) {
    x_min = std::min(x_min, x);
    y_min = std::min(y_min, y);
    x_max = std::max(x_max, x);
    y_max = std::max(y_max, y);
  }
  bool Empty() const { return !(x_max > x_min && y_max > y_min); }
};

// Largest |x| and |y| of the undistorted normalised coordinates of the
// image border: rays beyond them are outside the camera's field of view
// (with strong barrel distortion the polynomial folds such rays back into
// the image, so they must be rejected before projecting).
Eigen::Vector2d NormalizedFieldOfView(const Camera& camera) {
  Eigen::Vector2d limit(0.0, 0.0);
  const double w = camera.width() - 0.5;
  const double h = camera.height() - 0.5;
  for (int i = 0; i <= 32; ++i) {
    const double s = i / 32.0;
    const Eigen::Vector2d border[4] = {{-0.5 + s * (w + 0.5), -0.5},
                                       {-0.5 + s * (w + 0.5), h},
                                       {-0.5, -0.5 + s * (h + 0.5)},
                                       {w, -0.5 + s * (h + 0.5)}};
    for (const Eigen::Vector2d& uv : border) {
      Eigen::Vector2d xy;
      if (!camera.UnprojectToNormalized(uv, &xy)) continue;
      limit.x() = std::max(limit.x(), std::abs(xy.x()));
      limit.y() = std::max(limit.y(), std::abs(xy.y()));
    }
  }
  return limit * 1.02;
}

// Footprint of each camera on the road, in the left virtual camera's
// normalised coordinates, within max_range_m of the left camera (nadir
// `nadir_left`) and max_lateral_m across from `middle`; their common part
// in `box`. False when they have none.
bool CommonRoadFootprint(const RigCamera* const cameras[2],
                         const Eigen::Vector3d centre_body[2],
                         const Eigen::Matrix3d& R_body_virt,
                         const RoadPlane& plane,
                         const Eigen::Vector3d& nadir_left,
                         const Eigen::Vector3d& middle,
                         const RectificationOptions& options, Box* box_out) {
  const Eigen::Vector3d x_axis = R_body_virt.col(0);
  Box boxes[2];
  for (int side = 0; side < 2; ++side) {
    const Camera& camera = cameras[side]->camera;
    const Eigen::Matrix3d R_body_cam = cameras[side]->T_body_cam.linear();
    for (int v = 0; v < camera.height(); v += kFootprintStepPx) {
      for (int u = 0; u < camera.width(); u += kFootprintStepPx) {
        Eigen::Vector3d ray;
        if (!camera.UnprojectToRay(Eigen::Vector2d(u, v), &ray)) continue;
        Eigen::Vector3d p;
        if (!plane.IntersectRay(centre_body[side], R_body_cam * ray, &p)) {
          continue;
        }
        if ((p - nadir_left).norm() > options.max_range_m) continue;
        if (std::abs((p - middle).dot(x_axis)) > options.max_lateral_m) {
          continue;
        }
        const Eigen::Vector3d p_virt =
            R_body_virt.transpose() * (p - centre_body[0]);
        if (p_virt.z() <= 0.0) continue;
        boxes[side].Add(p_virt.x() / p_virt.z(), p_virt.y() / p_virt.z());
      }
    }
  }
  Box box;
  box.x_min = std::max(boxes[0].x_min, boxes[1].x_min);
  box.y_min = std::max(boxes[0].y_min, boxes[1].y_min);
  box.x_max = std::min(boxes[0].x_max, boxes[1].x_max);
  box.y_max = std::min(boxes[0].y_max, boxes[1].y_max);
  *box_out = box;
  return !(boxes[0].Empty() || boxes[1].Empty() || box.Empty());
}

}  // namespace

std::string RectificationOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, ground_pixel_m, "(", 0.0, 0.2, "]");
  OPTION_GT(check, max_range_m, 1.0);
  OPTION_GT(check, max_lateral_m, 0.5);
  OPTION_GE(check, max_image_side_px, 64);
  OPTION_GE(check, border_margin_px, 0);
  return check.problem();
}

bool RoadRectification::Build(const RigCamera& left, const RigCamera& right,
                              const RoadPlane& plane,
                              const RectificationOptions& options,
                              std::string* error) {
  const RigCamera* cameras[2] = {&left, &right};
  centre_body_[0] = left.T_body_cam.translation();
  centre_body_[1] = right.T_body_cam.translation();
  const Eigen::Vector3d baseline = centre_body_[1] - centre_body_[0];
  baseline_m_ = baseline.norm();
  if (!(baseline_m_ > 1e-3)) {
    *error = "the stereo baseline is shorter than 1 mm";
    return false;
  }
  const Eigen::Vector3d x_axis = baseline / baseline_m_;
  Eigen::Vector3d z_axis =
      plane.normal_body - plane.normal_body.dot(x_axis) * x_axis;
  if (z_axis.norm() < 0.5) {
    *error = "the stereo baseline is within 30 degrees of the road normal";
    return false;
  }
  z_axis.normalize();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  R_body_virt_.col(0) = x_axis;
  R_body_virt_.col(1) = y_axis;
  R_body_virt_.col(2) = z_axis;

  const double height_left = -plane.SignedDistance(centre_body_[0]);
  if (!(height_left > 0.1)) {
    *error = "the left camera is not above the road plane";
    return false;
  }
  const Eigen::Vector3d nadir_left = plane.Project(centre_body_[0]);
  const Eigen::Vector3d middle = 0.5 * (centre_body_[0] + centre_body_[1]);

  // Footprint of each camera on the road, in the left virtual camera's
  // normalised coordinates, within max_range_m of the left camera.
  Box box;
  if (!CommonRoadFootprint(cameras, centre_body_, R_body_virt_, plane,
                           nadir_left, middle, options, &box)) {
    *error = "the two cameras see no common road area within max_range_m";
    return false;
  }

  // Depth of the road at the centre of the footprint sets the scale.
  const Eigen::Vector3d normal_virt =
      R_body_virt_.transpose() * plane.normal_body;
  const Eigen::Vector3d centre_ray(0.5 * (box.x_min + box.x_max),
                                   0.5 * (box.y_min + box.y_max), 1.0);
  const double depth_centre = height_left / normal_virt.dot(centre_ray);
  focal_px_ = depth_centre / options.ground_pixel_m;
  ground_pixel_m_ = options.ground_pixel_m;
  cx_ = -box.x_min * focal_px_;
  cy_ = -box.y_min * focal_px_;
  width_ = static_cast<int>(std::ceil((box.x_max - box.x_min) * focal_px_)) + 1;
  height_ =
      static_cast<int>(std::ceil((box.y_max - box.y_min) * focal_px_)) + 1;
  if (width_ > options.max_image_side_px ||
      height_ > options.max_image_side_px) {
    std::ostringstream message;
    message << "the rectified road image would be " << width_ << " x "
            << height_
            << " px (max_image_side_px = " << options.max_image_side_px
            << "): increase ground_pixel_m or decrease max_range_m";
    *error = message.str();
    return false;
  }
  disparity_offset_px_ = focal_px_ * baseline_m_ / depth_centre;

  cv::Mat valid(height_, width_, CV_8U, cv::Scalar(255));
  BuildRemapTables(cameras, options, &valid);
  ClearBeyondRange(plane, nadir_left, middle, options, &valid);
  valid_ = valid;
  return true;
}

void RoadRectification::BuildRemapTables(const RigCamera* const cameras[2],
                                         const RectificationOptions& options,
                                         cv::Mat* valid_out) {
  cv::Mat& valid = *valid_out;
  for (int side = 0; side < 2; ++side) {
    const Camera& camera = cameras[side]->camera;
    const Eigen::Matrix3d R_cam_virt =
        cameras[side]->T_body_cam.linear().transpose() * R_body_virt_;
    const Eigen::Vector2d fov = NormalizedFieldOfView(camera);
    const double offset = side == 0 ? 0.0 : disparity_offset_px_;
    const double margin = options.border_margin_px;
    cv::Mat map_x(height_, width_, CV_32F);
    cv::Mat map_y(height_, width_, CV_32F);
    for (int y = 0; y < height_; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      uint8_t* ok = valid.ptr<uint8_t>(y);
      for (int x = 0; x < width_; ++x) {
        const Eigen::Vector3d ray_virt((x - cx_ - offset) / focal_px_,
                                       (y - cy_) / focal_px_, 1.0);
        const Eigen::Vector3d ray_cam = R_cam_virt * ray_virt;
        mx[x] = -1.0f;
        my[x] = -1.0f;
        bool inside = false;
        if (ray_cam.z() > 1e-6 &&
            std::abs(ray_cam.x() / ray_cam.z()) <= fov.x() &&
            std::abs(ray_cam.y() / ray_cam.z()) <= fov.y()) {
          Eigen::Vector2d uv;
          if (camera.Project(ray_cam, &uv)) {
            mx[x] = static_cast<float>(uv.x());
            my[x] = static_cast<float>(uv.y());
            inside = uv.x() >= margin && uv.y() >= margin &&
                     uv.x() <= camera.width() - 1 - margin &&
                     uv.y() <= camera.height() - 1 - margin;
          }
        }
        if (!inside) ok[x] = 0;
      }
    }
    cv::convertMaps(map_x, map_y, map1_[side], map2_[side], CV_16SC2);
  }
}

void RoadRectification::ClearBeyondRange(const RoadPlane& plane,
                                         const Eigen::Vector3d& nadir_left,
                                         const Eigen::Vector3d& middle,
                                         const RectificationOptions& options,
                                         cv::Mat* valid_out) const {
  cv::Mat& valid = *valid_out;
  const Eigen::Vector3d x_axis = R_body_virt_.col(0);
  for (int y = 0; y < height_; ++y) {
    uint8_t* ok = valid.ptr<uint8_t>(y);
    for (int x = 0; x < width_; ++x) {
      if (!ok[x]) continue;
      Eigen::Vector3d p;
      if (!plane.IntersectRay(centre_body_[0],
                              RayBody(0, Eigen::Vector2d(x, y)), &p) ||
          (p - nadir_left).norm() > options.max_range_m ||
          std::abs((p - middle).dot(x_axis)) > options.max_lateral_m) {
        ok[x] = 0;
      }
    }
  }
}

void RoadRectification::Rectify(const cv::Mat& left_image,
                                const cv::Mat& right_image,
                                cv::Mat* left_rectified,
                                cv::Mat* right_rectified) const {
  cv::remap(left_image, *left_rectified, map1_[0], map2_[0], cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::remap(right_image, *right_rectified, map1_[1], map2_[1], cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(0));
}

bool RoadRectification::IsValid(double x, double y) const {
  const int xi = static_cast<int>(std::lround(x));
  const int yi = static_cast<int>(std::lround(y));
  if (xi < 0 || yi < 0 || xi >= width_ || yi >= height_) return false;
  return valid_.at<uint8_t>(yi, xi) != 0;
}

bool RoadRectification::Triangulate(double x_left, double x_right, double y,
                                    Eigen::Vector3d* p_body) const {
  const double disparity = x_left - x_right + disparity_offset_px_;
  if (!(disparity > 1e-6)) return false;
  const double z = focal_px_ * baseline_m_ / disparity;
  const Eigen::Vector3d p_virt((x_left - cx_) * z / focal_px_,
                               (y - cy_) * z / focal_px_, z);
  *p_body = centre_body_[0] + R_body_virt_ * p_virt;
  return true;
}

Eigen::Matrix3d RoadRectification::TriangulationJacobian(double x_left,
                                                         double x_right,
                                                         double y) const {
  const double disparity = x_left - x_right + disparity_offset_px_;
  const double fb = focal_px_ * baseline_m_;
  const double z = fb / disparity;
  const double dz = z * z / fb;  // dZ/dx_right = +dz, dZ/dx_left = -dz
  const double xn = (x_left - cx_) / focal_px_;
  const double yn = (y - cy_) / focal_px_;
  Eigen::Matrix3d J;  // rows X, Y, Z; columns x_left, x_right, y
  J << z / focal_px_ - xn * dz, xn * dz, 0.0,  //
      -yn * dz, yn * dz, z / focal_px_,        //
      -dz, dz, 0.0;
  return R_body_virt_ * J;
}

bool RoadRectification::ProjectToRectified(int side,
                                           const Eigen::Vector3d& p_body,
                                           Eigen::Vector2d* xy) const {
  const Eigen::Vector3d p_virt =
      R_body_virt_.transpose() * (p_body - centre_body_[side]);
  if (!(p_virt.z() > 1e-9)) return false;
  const double offset = side == 0 ? 0.0 : disparity_offset_px_;
  *xy = Eigen::Vector2d(focal_px_ * p_virt.x() / p_virt.z() + cx_ + offset,
                        focal_px_ * p_virt.y() / p_virt.z() + cy_);
  return true;
}

Eigen::Vector3d RoadRectification::RayBody(int side,
                                           const Eigen::Vector2d& xy) const {
  const double offset = side == 0 ? 0.0 : disparity_offset_px_;
  return R_body_virt_ * Eigen::Vector3d((xy.x() - cx_ - offset) / focal_px_,
                                        (xy.y() - cy_) / focal_px_, 1.0);
}

double RoadRectification::DisparityOf(const Eigen::Vector3d& p_body) const {
  Eigen::Vector2d left, right;
  if (!ProjectToRectified(0, p_body, &left) ||
      !ProjectToRectified(1, p_body, &right)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return left.x() - right.x();
}

}  // namespace zebrageo
