#include "simulator/renderer.h"

#include <glog/logging.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "simulator/image_scene.h"
#include "simulator/noise.h"
#include "survey/threads.h"

namespace zebrageo::sim {
namespace {

using render_internal::GroundHint;
using render_internal::ImageScene;
using render_internal::Sample;

// Separable Gaussian blur with clamped borders.
void GaussianBlur(double sigma, int width, int height,
                  std::vector<float>* image) {
  if (sigma <= 0.0) return;
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<float> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    kernel[k + radius] =
        static_cast<float>(std::exp(-0.5 * k * k / (sigma * sigma)));
    sum += kernel[k + radius];
  }
  for (float& k : kernel) k = static_cast<float>(k / sum);
  std::vector<float> tmp(image->size());
  const std::vector<float>& in = *image;
  for (int y = 0; y < height; ++y) {
    const float* row = &in[static_cast<size_t>(y) * width];
    float* out = &tmp[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      float acc = 0.0f;
      for (int k = -radius; k <= radius; ++k) {
        acc += kernel[k + radius] * row[std::clamp(x + k, 0, width - 1)];
      }
      out[x] = acc;
    }
  }
  for (int y = 0; y < height; ++y) {
    float* out = &(*image)[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      float acc = 0.0f;
      for (int k = -radius; k <= radius; ++k) {
        acc +=
            kernel[k + radius] *
            tmp[static_cast<size_t>(std::clamp(y + k, 0, height - 1)) * width +
                x];
      }
      out[x] = acc;
    }
  }
}

}  // namespace

RayTable::RayTable(const Camera& camera)
    : width_(camera.width()), height_(camera.height()) {
  corners_.resize(2 * static_cast<size_t>(width_ + 1) * (height_ + 1));
  Eigen::Vector2d xy;
  for (int j = 0; j <= height_; ++j) {
    for (int i = 0; i <= width_; ++i) {
      CHECK(
          camera.UnprojectToNormalized(Eigen::Vector2d(i - 0.5, j - 0.5), &xy))
          << "camera " << camera.name() << ": distortion not invertible at ("
          << i - 0.5 << ", " << j - 0.5 << ")";
      float* c = &corners_[2 * (static_cast<size_t>(j) * (width_ + 1) + i)];
      c[0] = static_cast<float>(xy.x());
      c[1] = static_cast<float>(xy.y());
    }
  }
}

RenderSettings RenderSettings::FromOptions(const SimulationOptions& options) {
  RenderSettings s;
  s.supersampling = options.supersampling;
  s.blur_sigma_px = options.blur_sigma_px;
  s.vignetting = options.vignetting;
  s.gain_variation = options.gain_variation;
  s.noise_sigma = options.noise_sigma;
  s.shot_noise = options.shot_noise;
  s.pixel_depth = options.pixel_depth;
  return s;
}

Renderer::Renderer(const World& world, const RenderSettings& settings)
    : world_(world), settings_(settings) {
  first_band_of_crossing_.assign(world.crossings.size(), -1);
  for (int i = static_cast<int>(world.bands.size()) - 1; i >= 0; --i) {
    first_band_of_crossing_[world.bands[i].crossing] = i;
  }
}

cv::Mat Renderer::RenderRadiance(const Camera& camera, const RayTable& rays,
                                 const Eigen::Isometry3d& T_enu_cam,
                                 double s_hint, RenderStats* stats) const {
  const double start = ThreadCpuSeconds();
  const int width = camera.width(), height = camera.height();
  CHECK_EQ(rays.width(), width);
  CHECK_EQ(rays.height(), height);
  const ImageScene scene(world_, settings_, first_band_of_crossing_, T_enu_cam,
                         s_hint, camera.fx());
  cv::Mat radiance(height, width, CV_32FC1);
  std::vector<Sample> upper(width + 1), lower(width + 1);
  std::vector<GroundHint> hint_upper(width + 1), hint_lower(width + 1);
  int64_t ray_count = 0, supersampled = 0;
  auto trace_corner_row = [&](int j, std::vector<Sample>* row,
                              std::vector<GroundHint>* hints) {
    GroundHint hint = (*hints)[0];
    for (int i = 0; i <= width; ++i) {
      const float* xy = rays.Corner(i, j);
      if ((*hints)[i].valid) hint = (*hints)[i];
      (*row)[i] = scene.Trace(xy[0], xy[1], &hint);
      (*hints)[i] = hint;
    }
    ray_count += width + 1;
  };
  trace_corner_row(0, &upper, &hint_upper);
  const int n = std::max(1, settings_.supersampling);
  for (int j = 0; j < height; ++j) {
    hint_lower = hint_upper;
    trace_corner_row(j + 1, &lower, &hint_lower);
    float* out = radiance.ptr<float>(j);
    for (int i = 0; i < width; ++i) {
      const Sample& c00 = upper[i];
      const Sample& c10 = upper[i + 1];
      const Sample& c01 = lower[i];
      const Sample& c11 = lower[i + 1];
      if (c00.key == c10.key && c00.key == c01.key && c00.key == c11.key) {
        out[i] = 0.25f * (c00.value + c10.value + c01.value + c11.value);
        continue;
      }
      GroundHint hint = hint_upper[i].valid ? hint_upper[i] : hint_lower[i];
      // Supersample n x n, rays bilinear between the pixel's corners.
      ++supersampled;
      const float* a = rays.Corner(i, j);
      const float* b = rays.Corner(i + 1, j);
      const float* c = rays.Corner(i, j + 1);
      const float* d = rays.Corner(i + 1, j + 1);
      double sum = 0.0;
      GroundHint sub_hint = hint;
      for (int sy = 0; sy < n; ++sy) {
        const double v = (sy + 0.5) / n;
        for (int sx = 0; sx < n; ++sx) {
          const double u = (sx + 0.5) / n;
          const double x = (1 - v) * ((1 - u) * a[0] + u * b[0]) +
                           v * ((1 - u) * c[0] + u * d[0]);
          const double y = (1 - v) * ((1 - u) * a[1] + u * b[1]) +
                           v * ((1 - u) * c[1] + u * d[1]);
          sum += scene.Trace(x, y, &sub_hint).value;
        }
      }
      ray_count += n * n;
      out[i] = static_cast<float>(sum / (n * n));
    }
    std::swap(upper, lower);
    std::swap(hint_upper, hint_lower);
  }
  if (stats != nullptr) {
    stats->rays = ray_count;
    stats->supersampled_pixels = supersampled;
    stats->seconds = ThreadCpuSeconds() - start;
  }
  return radiance;
}

cv::Mat Renderer::Render(const Camera& camera, const RayTable& rays,
                         const Eigen::Isometry3d& T_enu_cam, double s_hint,
                         uint64_t image_seed, RenderStats* stats) const {
  const double start = ThreadCpuSeconds();
  cv::Mat radiance = RenderRadiance(camera, rays, T_enu_cam, s_hint, stats);
  const int width = camera.width(), height = camera.height();
  std::vector<float> pixels(radiance.begin<float>(), radiance.end<float>());
  GaussianBlur(settings_.blur_sigma_px, width, height, &pixels);
  const double gain =
      1.0 + settings_.gain_variation *
                (2.0 * HashToUnit(Mix64(image_seed + 0x6a09e667)) - 1.0);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const double corner2 = cx * cx + cy * cy;
  const bool deep = settings_.pixel_depth == PixelDepth::kUint16;
  cv::Mat image(height, width, deep ? CV_16UC1 : CV_8UC1);
  const double read2 = settings_.noise_sigma * settings_.noise_sigma;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t index = static_cast<size_t>(y) * width + x;
      const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / corner2;
      double value = pixels[index] * gain * (1.0 - settings_.vignetting * r2);
      const double sigma =
          std::sqrt(read2 + settings_.shot_noise * std::max(0.0, value));
      value += sigma * HashGaussian(
                           Mix64(image_seed ^ (index * 0x9e3779b97f4a7c15ULL)));
      if (deep) {
        image.at<uint16_t>(y, x) = static_cast<uint16_t>(
            std::clamp(std::lround(value * 257.0), 0L, 65535L));
      } else {
        image.at<uint8_t>(y, x) =
            static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
  if (stats != nullptr) stats->seconds = ThreadCpuSeconds() - start;
  return image;
}

}  // namespace zebrageo::sim
