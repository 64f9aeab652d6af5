#include "registration/paint_probe.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>

#include "survey/image_io.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Median and interquartile range of `values` (reordered).
void Quartiles(std::vector<float>* values, double* median, double* iqr) {
  const size_t n = values->size();
  auto at = [&](double share) {
    auto it = values->begin() + static_cast<ptrdiff_t>(share * (n - 1));
    std::nth_element(values->begin(), it, values->end());
    return static_cast<double>(*it);
  };
  *median = at(0.5);
  *iqr = at(0.75) - at(0.25);
}

// The quad midway between two neighbouring bands: the asphalt gap.
BandCornersEnu Between(const BandCornersEnu& a, const BandCornersEnu& b) {
  BandCornersEnu gap;
  for (int k = 0; k < 4; ++k) gap[k] = 0.5 * (a[k] + b[k]);
  return gap;
}

// Horizontal unit vector across the band (along its shorter sides).
Eigen::Vector3d AcrossUnit(const BandCornersEnu& q) {
  Eigen::Vector3d a = q[1] - q[0];
  const Eigen::Vector3d b = q[2] - q[1];
  if (b.head<2>().norm() < a.head<2>().norm()) a = b;
  a.z() = 0.0;
  return a.norm() > 0.0 ? Eigen::Vector3d(a / a.norm()) : a;
}

Eigen::Vector3d Centre(const BandCornersEnu& q) {
  return 0.25 * (q[0] + q[1] + q[2] + q[3]);
}

}  // namespace

const char* PaintEvidenceName(PaintEvidence evidence) {
  switch (evidence) {
    case PaintEvidence::kPaint:
      return "paint";
    case PaintEvidence::kBareRoad:
      return "bare road";
    case PaintEvidence::kOccluded:
      return "occluded";
    case PaintEvidence::kUnknown:
      break;
  }
  return "unknown";
}

std::string PaintProbeOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, sample_share, "(", 0.0, 1.0, "]");
  OPTION_GT(check, min_contrast, 0.0);
  OPTION_GE(check, bare_level, 0.0);
  OPTION_GT(check, paint_level, bare_level);
  OPTION_LE(check, paint_level, 1.0);
  OPTION_GT(check, max_bare_spread, 0.0);
  OPTION_IN(check, min_inside_share, "(", 0.0, 1.0, "]");
  OPTION_GE(check, cached_images, 2);
  OPTION_GE(check, occlusion_window_px, 3);
  check.Require(occlusion_window_px % 2 == 1, "occlusion_window_px",
                occlusion_window_px, "must be odd");
  OPTION_GT(check, occlusion_min_height_m, 0.0);
  OPTION_GE(check, occlusion_min_texture, 0.0);
  OPTION_IN(check, occlusion_min_ncc, "(", 0.0, 1.0, "]");
  OPTION_GE(check, occlusion_ncc_margin, 0.0);
  OPTION_GE(check, occlusion_min_points, 1);
  OPTION_IN(check, occlusion_min_share, "(", 0.0, 1.0, "]");
  OPTION_GT(check, assumed_paint_contrast, 0.0);
  OPTION_GT(check, max_road_level_change, 0.0);
  return check.problem();
}

ImagePaintProbe::ImagePaintProbe(const Survey& survey,
                                 PaintProbeOptions options)
    : survey_(survey), options_(options) {
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    heights_known_ = heights_known_ && band.height_known;
  }
  if (survey.rig.stereo_pairs.empty()) return;
  camera_ = survey.rig.stereo_pairs.front()[0];
  right_camera_ = survey.rig.stereo_pairs.front()[1];
  for (const Exposure& e : survey.exposures.exposures) {
    for (int side = 0; side < 2; ++side) {
      const int camera = side == 0 ? camera_ : right_camera_;
      if (camera >= static_cast<int>(e.image_of_camera.size())) continue;
      const int image = e.image_of_camera[camera];
      if (image < 0) continue;
      (side == 0 ? image_of_exposure_
                 : right_image_of_exposure_)[e.exposure_id] =
          survey.exposures.images[image].image;
    }
  }
}

const cv::Mat* ImagePaintProbe::LeftImage(int64_t exposure_id) {
  return CameraImage(exposure_id, camera_);
}

const cv::Mat* ImagePaintProbe::CameraImage(int64_t exposure_id, int camera) {
  const int side = camera == camera_ ? 0 : 1;
  const int64_t key = exposure_id * 2 + side;
  for (auto it = cache_.begin(); it != cache_.end(); ++it) {
    if (it->first != key) continue;
    cache_.splice(cache_.begin(), cache_, it);
    return cache_.front().second.empty() ? nullptr : &cache_.front().second;
  }
  const auto& paths = side == 0 ? image_of_exposure_ : right_image_of_exposure_;
  const auto path = paths.find(exposure_id);
  if (path == paths.end()) return nullptr;
  cv::Mat image;
  try {
    const Camera& model = survey_.rig.cameras[camera].camera;
    image = ReadGrayImage(survey_.PathOf(path->second), path->second,
                          model.width(), model.height());
  } catch (const std::exception& error) {
    // The reconstruction already reported unreadable images; here the
    // evidence is simply unknown.
    VLOG(1) << "paint probe: " << error.what();
  }
  ++images_read_;
  cache_.emplace_front(key, image);
  if (static_cast<int>(cache_.size()) > options_.cached_images) {
    cache_.pop_back();
  }
  return cache_.front().second.empty() ? nullptr : &cache_.front().second;
}

bool ImagePaintProbe::Sample(const cv::Mat& image,
                             const Eigen::Isometry3d& T_cam_enu,
                             const BandCornersEnu& quad,
                             std::vector<float>* values) const {
  const Camera& camera = survey_.rig.cameras[camera_].camera;
  constexpr int kAlong = 15;
  constexpr int kAcross = 7;
  const double lo = 0.5 - 0.5 * options_.sample_share;
  values->clear();
  int total = 0;
  for (int i = 0; i < kAlong; ++i) {
    for (int j = 0; j < kAcross; ++j) {
      // Bilinear in the ring 0-1-2-3: 0-1 and 3-2 across, 0-3 along, or
      // the other way round; a symmetric grid does not care which.
      const double u = lo + options_.sample_share * i / (kAlong - 1);
      const double v = lo + options_.sample_share * j / (kAcross - 1);
      const Eigen::Vector3d p = (1 - u) * ((1 - v) * quad[0] + v * quad[1]) +
                                u * ((1 - v) * quad[3] + v * quad[2]);
      ++total;
      const Eigen::Vector3d p_cam = T_cam_enu * p;
      Eigen::Vector2d uv;
      if (p_cam.z() < 0.5 || !camera.Project(p_cam, &uv) ||
          !camera.IsInImage(uv, 2.0)) {
        continue;
      }
      const int x = static_cast<int>(std::lround(uv.x()));
      const int y = static_cast<int>(std::lround(uv.y()));
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      values->push_back(image.at<float>(y, x));
    }
  }
  return values->size() >= options_.min_inside_share * total;
}

PaintEvidence ImagePaintProbe::Classify(
    int64_t exposure_id, const Pose& pose, const BandCornersEnu& band,
    const std::vector<BandCornersEnu>& seen) {
  if (camera_ < 0) return PaintEvidence::kUnknown;
  const cv::Mat* image = LeftImage(exposure_id);
  if (image == nullptr) return PaintEvidence::kUnknown;
  const Eigen::Isometry3d T_cam_enu =
      (pose.T_enu_body() * survey_.rig.cameras[camera_].T_body_cam).inverse();
  // Every verdict is first checked for something standing over the place:
  // a dark, even vehicle side looks like bare road, a white one like paint
  // (measured: a truck over a band read as paint in 12 of 17 views).
  auto unless_occluded = [&](PaintEvidence evidence) {
    return StandsAboveRoad(exposure_id, pose, band) ? PaintEvidence::kOccluded
                                                    : evidence;
  };
  if (seen.empty()) {
    const double road = RoadAheadLevel(*image, T_cam_enu, band);
    if (!(road > 1.0)) return unless_occluded(PaintEvidence::kUnknown);
    return unless_occluded(Verdict(*image, T_cam_enu, band,
                                   options_.assumed_paint_contrast, road,
                                   exposure_id));
  }
  // Paint: the seen bands. Asphalt: the gaps between neighbouring ones.
  std::vector<float> paint, asphalt, values;
  for (size_t i = 0; i < seen.size(); ++i) {
    if (Sample(*image, T_cam_enu, seen[i], &values)) {
      paint.insert(paint.end(), values.begin(), values.end());
    }
    for (size_t j = i + 1; j < seen.size(); ++j) {
      const double apart = (Centre(seen[i]) - Centre(seen[j])).norm();
      if (apart < 0.7 || apart > 1.3) continue;  // not neighbours
      if (Sample(*image, T_cam_enu, Between(seen[i], seen[j]), &values)) {
        asphalt.insert(asphalt.end(), values.begin(), values.end());
      }
    }
  }
  if (paint.empty() || asphalt.empty()) {
    return unless_occluded(PaintEvidence::kUnknown);
  }
  double paint_level, paint_spread, road_level, road_spread;
  Quartiles(&paint, &paint_level, &paint_spread);
  Quartiles(&asphalt, &road_level, &road_spread);
  // Ratios, not differences: a cast shadow multiplies paint and asphalt
  // alike, so the band is compared with the surface right beside it.
  if (!(road_level > 1.0) || paint_level - road_level < options_.min_contrast) {
    return unless_occluded(PaintEvidence::kUnknown);
  }
  return unless_occluded(Verdict(*image, T_cam_enu, band,
                                 paint_level / road_level - 1.0, 0.0,
                                 exposure_id));
}

double ImagePaintProbe::RoadAheadLevel(const cv::Mat& image,
                                       const Eigen::Isometry3d& T_cam_enu,
                                       const BandCornersEnu& band) const {
  // Ahead: the camera's optical axis, level.
  const Eigen::Isometry3d T_enu_cam = T_cam_enu.inverse();
  Eigen::Vector3d ahead = T_enu_cam.linear().col(2);
  ahead.z() = 0.0;
  if (ahead.norm() < 1e-6) return 0.0;
  ahead.normalize();
  const Eigen::Vector3d left(-ahead.y(), ahead.x(), 0.0);
  Eigen::Vector3d base = T_enu_cam.translation();
  base.z() = Centre(band).z();
  // A quad 3 m long and 1 m wide in the vehicle's own lane, 5 to 8 m
  // ahead (sampled in its middle, sample_share).
  const BandCornersEnu patch = {
      base + 5.0 * ahead - 0.5 * left, base + 5.0 * ahead + 0.5 * left,
      base + 8.0 * ahead + 0.5 * left, base + 8.0 * ahead - 0.5 * left};
  std::vector<float> values;
  if (!Sample(image, T_cam_enu, patch, &values)) return 0.0;
  double level, spread;
  Quartiles(&values, &level, &spread);
  return level;
}

PaintEvidence ImagePaintProbe::Verdict(const cv::Mat& image,
                                       const Eigen::Isometry3d& T_cam_enu,
                                       const BandCornersEnu& band,
                                       double contrast, double road_ahead_level,
                                       int64_t exposure_id) const {
  std::vector<float> values;
  if (!Sample(image, T_cam_enu, band, &values)) {
    return PaintEvidence::kUnknown;
  }
  double level, spread;
  Quartiles(&values, &level, &spread);
  // Beside the band, half a band period either way: the gaps.
  const Eigen::Vector3d across = AcrossUnit(band);
  std::vector<float> beside;
  for (double sign : {-1.0, 1.0}) {
    BandCornersEnu side = band;
    for (Eigen::Vector3d& corner : side) corner += sign * 0.5 * across;
    if (Sample(image, T_cam_enu, side, &values)) {
      beside.insert(beside.end(), values.begin(), values.end());
    }
  }
  if (beside.empty()) return PaintEvidence::kUnknown;
  double local_level, local_spread;
  Quartiles(&beside, &local_level, &local_spread);
  if (!(local_level > 1.0)) return PaintEvidence::kUnknown;
  const double share = (level / local_level - 1.0) / contrast;
  VLOG(2) << "paint probe: exposure " << exposure_id << " contrast " << contrast
          << " band " << level << " (" << spread << ") beside " << local_level
          << " (" << local_spread << ") road ahead " << road_ahead_level
          << ": share " << share;
  if (share >= options_.paint_level) {
    // Without measured paint, bright is paint only where it is as even as
    // paint (not the kerb, a vehicle, a sunlit edge).
    const bool even =
        road_ahead_level <= 0.0 || spread <= options_.max_bare_spread * level;
    return even ? PaintEvidence::kPaint : PaintEvidence::kUnknown;
  }
  // Without measured paint: bare only where the surface is the road's.
  if (road_ahead_level > 0.0 && std::abs(local_level / road_ahead_level - 1.0) >
                                    options_.max_road_level_change) {
    return PaintEvidence::kUnknown;
  }
  if (std::abs(share) <= options_.bare_level &&
      spread <= local_spread + options_.max_bare_spread * contrast * level) {
    return PaintEvidence::kBareRoad;
  }
  return PaintEvidence::kUnknown;
}

}  // namespace zebrageo
