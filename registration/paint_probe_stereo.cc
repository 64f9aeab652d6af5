// The paint probe's occlusion test (issue 52): does the stereo pair show
// something standing above the road at a band's place? A grid of points of
// the place is seen in the left image; the right image is searched for
// each point's window where the road surface puts it and along the left
// ray above the road. Road paint and asphalt match on the road; a truck's
// side, a car's door match in front of it. Untextured windows (paint, an
// even body panel) say nothing.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "registration/paint_probe.h"

namespace zebrageo {
namespace {

// The window of `half` pixels around (x, y) (rounded), or false when it
// leaves the image.
bool Window(const cv::Mat& image, const Eigen::Vector2d& uv, int half,
            std::vector<float>* values) {
  const int x = static_cast<int>(std::lround(uv.x()));
  const int y = static_cast<int>(std::lround(uv.y()));
  if (x - half < 0 || y - half < 0 || x + half >= image.cols ||
      y + half >= image.rows) {
    return false;
  }
  values->clear();
  for (int dy = -half; dy <= half; ++dy) {
    const float* row = image.ptr<float>(y + dy);
    for (int dx = -half; dx <= half; ++dx) values->push_back(row[x + dx]);
  }
  return true;
}

// Mean-removed copy and its norm.
double Centred(std::vector<float>* values) {
  double mean = 0.0;
  for (float v : *values) mean += v;
  mean /= std::max<size_t>(1, values->size());
  double norm = 0.0;
  for (float& v : *values) {
    v = static_cast<float>(v - mean);
    norm += static_cast<double>(v) * v;
  }
  return std::sqrt(norm);
}

// Normalised cross-correlation of a centred window (norm `norm_a`) with
// the window of `image` at uv; -1 outside or without texture.
double Ncc(const std::vector<float>& a, double norm_a, const cv::Mat& image,
           const Eigen::Vector2d& uv, int half, std::vector<float>* scratch) {
  if (!Window(image, uv, half, scratch)) return -1.0;
  const double norm_b = Centred(scratch);
  if (norm_b < 1e-6 || norm_a < 1e-6) return -1.0;
  double dot = 0.0;
  for (size_t i = 0; i < a.size(); ++i) dot += a[i] * (*scratch)[i];
  return dot / (norm_a * norm_b);
}

}  // namespace

bool ImagePaintProbe::StandsAboveRoad(int64_t exposure_id, const Pose& pose,
                                      const BandCornersEnu& band) {
  if (camera_ < 0 || right_camera_ < 0 || right_camera_ == camera_) {
    return false;
  }
  // What stands over a place does not depend on the hypothesis that put a
  // band there: one answer per exposure and quarter-metre cell (the
  // matcher asks for the same places under many corrections).
  const Eigen::Vector3d mid = 0.25 * (band[0] + band[1] + band[2] + band[3]);
  const uint64_t cell = (static_cast<uint64_t>(exposure_id) * 1000003ULL) ^
                        (static_cast<uint64_t>(std::llround(mid.x() * 4.0)) *
                         0x9e3779b97f4a7c15ULL) ^
                        (static_cast<uint64_t>(std::llround(mid.y() * 4.0)) *
                         0xc2b2ae3d27d4eb4fULL);
  const auto known = occlusion_cache_.find(cell);
  if (known != occlusion_cache_.end()) return known->second;
  const bool answer = MeasureStandsAboveRoad(exposure_id, pose, band);
  occlusion_cache_[cell] = answer;
  return answer;
}

bool ImagePaintProbe::MeasureStandsAboveRoad(int64_t exposure_id,
                                             const Pose& pose,
                                             const BandCornersEnu& band) {
  // The test compares the road at the band's height with a surface above
  // it. A 2D layer's heights are a guess (survey/roadmark_layer.h): the
  // real road then stands above the guessed one and would read as an
  // occluder, so without heights nothing is called occluded.
  if (!heights_known_) return false;
  const cv::Mat* left = CameraImage(exposure_id, camera_);
  if (left == nullptr) return false;
  const cv::Mat left_image = *left;  // shares the data; the cache may evict
  const cv::Mat* right = CameraImage(exposure_id, right_camera_);
  if (right == nullptr) return false;
  const cv::Mat right_image = *right;
  const Camera& cam_l = survey_.rig.cameras[camera_].camera;
  const Camera& cam_r = survey_.rig.cameras[right_camera_].camera;
  const Eigen::Isometry3d T_enu_l =
      pose.T_enu_body() * survey_.rig.cameras[camera_].T_body_cam;
  const Eigen::Isometry3d T_r_enu =
      (pose.T_enu_body() * survey_.rig.cameras[right_camera_].T_body_cam)
          .inverse();
  const Eigen::Isometry3d T_l_enu = T_enu_l.inverse();
  const Eigen::Vector3d centre = T_enu_l.translation();
  const double baseline = (T_r_enu.inverse().translation() - centre).norm();
  const int half = options_.occlusion_window_px / 2;
  // A grid of 8 x 5 points over the middle of the place, visited in a
  // scattered order, until kMaxTextured of them have voted (textured, and
  // matching clearly on the road or above it).
  constexpr int kAlong = 8;
  constexpr int kAcross = 5;
  constexpr int kMaxTextured = 16;
  const double lo = 0.5 - 0.5 * options_.sample_share;
  int textured = 0, above = 0;
  std::vector<float> a, scratch;
  for (int k = 0; k < kAlong * kAcross && textured < kMaxTextured; ++k) {
    const int index = (k * 17) % (kAlong * kAcross);
    const int i = index / kAcross;
    const int j = index % kAcross;
    const double u = lo + options_.sample_share * i / (kAlong - 1);
    const double v = lo + options_.sample_share * j / (kAcross - 1);
    const Eigen::Vector3d p = (1 - u) * ((1 - v) * band[0] + v * band[1]) +
                              u * ((1 - v) * band[3] + v * band[2]);
    const Eigen::Vector3d p_l = T_l_enu * p;
    Eigen::Vector2d uv_l;
    if (p_l.z() < 0.5 || !cam_l.Project(p_l, &uv_l) ||
        !Window(left_image, uv_l, half, &a)) {
      continue;
    }
    const double norm_a = Centred(&a);
    const double sd = norm_a / std::sqrt(static_cast<double>(a.size()));
    if (sd < options_.occlusion_min_texture) continue;
    Eigen::Vector2d uv_r;
    const Eigen::Vector3d p_r = T_r_enu * p;
    const double on_road =
        p_r.z() > 0.5 && cam_r.Project(p_r, &uv_r)
            ? Ncc(a, norm_a, right_image, uv_r, half, &scratch)
            : -1.0;
    // Along the left ray X(w) = centre + (p - centre) / w, w = 1 at the
    // road; a surface occlusion_min_height_m above it and at least 1 m
    // from the camera; two pixels of disparity a step in w (the windows
    // of blurred texture still correlate one pixel off).
    const double depth = (p - centre).norm();
    const double drop = centre.z() - p.z();
    if (!(drop > options_.occlusion_min_height_m + 0.1)) continue;
    const double w0 = drop / (drop - options_.occlusion_min_height_m);
    const double w1 = std::max(w0, depth / 1.0);
    const double focal = std::max(1.0, cam_l.fx());
    const double step = 2.0 * depth / (focal * std::max(0.05, baseline));
    double best = -1.0;
    for (double w = w0; w <= w1; w += step) {
      const Eigen::Vector3d x = centre + (p - centre) / w;
      const Eigen::Vector3d x_r = T_r_enu * x;
      if (x_r.z() < 0.3 || !cam_r.Project(x_r, &uv_r)) continue;
      best = std::max(best, Ncc(a, norm_a, right_image, uv_r, half, &scratch));
    }
    // A vote only where one surface matches clearly (image noise alone
    // matches neither).
    if (best >= options_.occlusion_min_ncc &&
        best >= on_road + options_.occlusion_ncc_margin) {
      ++above;
      ++textured;
    } else if (on_road >= options_.occlusion_min_ncc) {
      ++textured;
    }
  }
  VLOG(2) << "occlusion probe: exposure " << exposure_id << " textured "
          << textured << " above the road " << above;
  return above >= options_.occlusion_min_points &&
         above >= options_.occlusion_min_share * textured;
}

}  // namespace zebrageo
