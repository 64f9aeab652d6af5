// Ray-casting renderer of the simulated street.
//
// Each pixel's ray comes from the exact inverse of the OpenCV distortion,
// precomputed once per camera (RayTable) at pixel corners; rays inside a
// pixel are bilinear between its corners (the inverse map is smooth: the
// interpolation error is ~1e-4 px). A ray is transformed to ENU with the
// camera pose and intersected with the road height field (safeguarded Newton
// on z = crown(s) + cross(l), (s, l) from a per-image lookup grid), the
// zebra bands (exact ray/plane intersection with each band's planar quad:
// paint lies on top of the surface), buildings and parked vehicles (boxes
// with vertical sides; the nearest hit wins), else the sky.
//
// Anti-aliasing, adaptive at edges: every pixel has its 4 corner rays
// (shared with its neighbours). A pixel whose corners hit the same material
// (same band, window, line, shadow state...) is their mean (textures are
// prefiltered by the footprint, so they do not alias); any other pixel
// contains an edge and is supersampled n x n (default 4 x 4), so edge
// positions are sub-pixel exact.
// Then Gaussian blur, vignetting, exposure gain, Gaussian + shot noise and
// quantisation. Pixel (0, 0) is the centre of the top-left pixel.
#ifndef ZEBRAGEO_SIMULATOR_RENDERER_H_
#define ZEBRAGEO_SIMULATOR_RENDERER_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/camera.h"

namespace zebrageo::sim {

// Normalised undistorted coordinates (X/Z, Y/Z) of the pixel corners of one
// camera (Camera::UnprojectToNormalized, once). Immutable after
// construction: shared by threads.
class RayTable {
 public:
  // CHECK-fails if the distortion cannot be inverted inside the image
  // (SimulationOptions::Check rejects such distortions first).
  explicit RayTable(const Camera& camera);

  int width() const { return width_; }
  int height() const { return height_; }
  // Corner (i, j), i in [0, width], j in [0, height], is at pixel
  // coordinates (i - 0.5, j - 0.5).
  const float* Corner(int i, int j) const {
    return &corners_[2 * (static_cast<size_t>(j) * (width_ + 1) + i)];
  }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<float> corners_;
};

struct RenderSettings {
  int supersampling = 4;
  double blur_sigma_px = 0.6;
  double vignetting = 0.25;
  double gain_variation = 0.08;
  double noise_sigma = 1.5;
  double shot_noise = 0.04;
  PixelDepth pixel_depth = PixelDepth::kUint8;
  // The ground is traced up to this distance along the road (then haze).
  double max_ground_range_m = 140.0;

  static RenderSettings FromOptions(const SimulationOptions& options);
};

// Timing and ray counts of one image.
struct RenderStats {
  int64_t rays = 0;
  int64_t supersampled_pixels = 0;
  double seconds = 0.0;  // thread CPU time
};

class Renderer {
 public:
  Renderer(const World& world, const RenderSettings& settings);

  // Renders one grey image (CV_8UC1 or CV_16UC1) of `camera` at pose
  // T_enu_cam (camera -> ENU). `s_hint` is the road s near the camera;
  // `image_seed` seeds this image's gain and noise.
  cv::Mat Render(const Camera& camera, const RayTable& rays,
                 const Eigen::Isometry3d& T_enu_cam, double s_hint,
                 uint64_t image_seed, RenderStats* stats = nullptr) const;
  // The scene radiance (CV_32FC1, grey levels 0..255) before blur, gain,
  // vignetting and noise.
  cv::Mat RenderRadiance(const Camera& camera, const RayTable& rays,
                         const Eigen::Isometry3d& T_enu_cam, double s_hint,
                         RenderStats* stats = nullptr) const;

 private:
  const World& world_;
  RenderSettings settings_;
  std::vector<int> first_band_of_crossing_;  // index into world.bands, or -1
};

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_RENDERER_H_
