#include "tiepoints/mount_observations.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/features2d.hpp>
#include <stdexcept>

#include "survey/image_io.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

struct Features {
  bool valid = false;
  cv::Mat descriptors;
  std::vector<Eigen::Vector2d> normalized;
  std::vector<char> has_normalized;
  std::vector<Eigen::Vector3d> point_cam;  // stereo points (left images)
  std::vector<char> has_point;
};

Features ReadFeatures(const std::string& folder, const ExposureImage& image,
                      const Camera& camera, cv::ORB& orb, int* images_read) {
  Features f;
  cv::Mat grey;
  try {
    const cv::Mat f32 = ReadGrayImage(
        (std::filesystem::path(folder) / image.image).string(), image.image);
    f32.convertTo(grey, CV_8U);
  } catch (const std::exception&) {
    return f;
  }
  ++*images_read;
  std::vector<cv::KeyPoint> keypoints;
  orb.detectAndCompute(grey, cv::noArray(), keypoints, f.descriptors);
  f.normalized.resize(keypoints.size());
  f.has_normalized.assign(keypoints.size(), 0);
  for (size_t k = 0; k < keypoints.size(); ++k) {
    // The pixel offset of a coarse pyramid level (tie_points.cc) is below
    // what the mount check resolves; the keypoints are taken as found.
    const Eigen::Vector2d uv(keypoints[k].pt.x, keypoints[k].pt.y);
    f.has_normalized[k] = camera.UnprojectToNormalized(uv, &f.normalized[k]);
  }
  f.point_cam.resize(keypoints.size());
  f.has_point.assign(keypoints.size(), 0);
  f.valid = !keypoints.empty();
  return f;
}

std::vector<std::pair<int, int>> Putative(const Features& a, const Features& b,
                                          double ratio) {
  std::vector<std::pair<int, int>> pairs;
  if (!a.valid || !b.valid) return pairs;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(a.descriptors, b.descriptors, knn, 2);
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance > ratio * m[1].distance) continue;
    const int ka = m[0].queryIdx, kb = m[0].trainIdx;
    if (a.has_normalized[ka] && b.has_normalized[kb])
      pairs.emplace_back(ka, kb);
  }
  return pairs;
}

// Triangulates the left image's stereo matches (camera frame of the left).
void TriangulateStereo(const MountObservationOptions& options,
                       const Eigen::Isometry3d& T_cr_cl, double focal_px,
                       const Features& right, Features* left) {
  const Eigen::Vector3d t = T_cr_cl.translation();
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d essential = tx * T_cr_cl.linear();
  for (const auto& [kl, kr] :
       Putative(*left, right, options.max_descriptor_ratio)) {
    const Eigen::Vector3d line = essential * left->normalized[kl].homogeneous();
    const double norm = line.head<2>().norm();
    if (norm <= 0.0 || std::abs(line.dot(right.normalized[kr].homogeneous())) /
                               norm * focal_px >
                           options.max_epipolar_distance_px) {
      continue;
    }
    left->has_point[kl] = TriangulateStereoPoint(
        options.odometry, T_cr_cl, left->normalized[kl], right.normalized[kr],
        focal_px, &left->point_cam[kl]);
  }
}

}  // namespace

std::string MountObservationOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, max_features_per_image, 100);
  OPTION_IN(check, max_descriptor_ratio, "(", 0.0, 1.0, "]");
  OPTION_GT(check, max_epipolar_distance_px, 0.0);
  OPTION_GE(check, max_exposures, 0);
  OPTION_REQUIRE(check, max_exposures != 1, max_exposures,
                 "must be 0 (every exposure) or >= 2");
  OPTION_GE(check, run_length, 2);
  OPTION_NESTED(check, odometry);
  return check.problem();
}

std::vector<bool> SampledExposures(int num_exposures, int max_exposures,
                                   int run_length) {
  if (max_exposures == 0 || num_exposures <= max_exposures) {
    return std::vector<bool>(num_exposures, true);
  }
  std::vector<bool> sampled(num_exposures, false);
  const int length = std::min(run_length, max_exposures);
  const int runs = max_exposures / length;
  for (int r = 0; r < runs; ++r) {
    // Run starts spread from the first exposure to the last full run.
    const int first =
        static_cast<int>(runs == 1 ? 0
                                   : static_cast<long long>(r) *
                                         (num_exposures - length) / (runs - 1));
    for (int k = 0; k < length; ++k) sampled[first + k] = true;
  }
  return sampled;
}

MountObservations ObserveMount(const MountObservationOptions& options,
                               const std::string& survey_folder, const Rig& rig,
                               const Trajectory& trajectory,
                               const ExposureTable& exposures,
                               const std::function<void(int, int)>& progress,
                               const CancellationToken& cancel) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("MountObservationOptions: " + problem);
  }
  MountObservations observations;
  cv::Ptr<cv::ORB> orb = cv::ORB::create(options.max_features_per_image);
  const int num_exposures = static_cast<int>(exposures.exposures.size());
  // Per stereo pair: the previous exposure's left features and body pose.
  std::vector<Features> previous(rig.stereo_pairs.size());
  std::vector<int> previous_exposure(rig.stereo_pairs.size(), -1);
  std::vector<Eigen::Isometry3d> previous_T_enu_body(rig.stereo_pairs.size());
  const std::vector<bool> sampled = SampledExposures(
      num_exposures, options.max_exposures, options.run_length);
  for (int e = 0; e < num_exposures; ++e) {
    cancel.ThrowIfCancelled();
    if (!sampled[e]) {
      // The next run's first exposure has no neighbour to measure from.
      std::fill(previous_exposure.begin(), previous_exposure.end(), -1);
      continue;
    }
    const Exposure& exposure = exposures.exposures[e];
    Pose pose;
    const bool has_pose = trajectory.InterpolatePose(exposure.time, &pose);
    for (size_t p = 0; p < rig.stereo_pairs.size(); ++p) {
      const int cl = rig.stereo_pairs[p][0], cr = rig.stereo_pairs[p][1];
      const int il = exposure.image_of_camera[cl];
      const int ir = exposure.image_of_camera[cr];
      Features left, right;
      if (has_pose && il >= 0 && ir >= 0) {
        left = ReadFeatures(survey_folder, exposures.images[il],
                            rig.cameras[cl].camera, *orb,
                            &observations.images_read);
        right = ReadFeatures(survey_folder, exposures.images[ir],
                             rig.cameras[cr].camera, *orb,
                             &observations.images_read);
      }
      if (!left.valid || !right.valid) {
        previous_exposure[p] = -1;
        continue;
      }
      const Eigen::Isometry3d& T_body_cl = rig.cameras[cl].T_body_cam;
      const double focal = rig.cameras[cl].camera.fx();
      TriangulateStereo(options,
                        rig.cameras[cr].T_body_cam.inverse() * T_body_cl,
                        rig.cameras[cr].camera.fx(), right, &left);
      StereoPoints points;
      points.camera = cl;
      points.exposure = e;
      for (size_t k = 0; k < left.point_cam.size(); ++k) {
        if (left.has_point[k]) points.points_cam.push_back(left.point_cam[k]);
      }
      observations.stereo_points.push_back(std::move(points));
      const Eigen::Isometry3d T_enu_body = pose.T_enu_body();
      if (previous_exposure[p] >= 0) {
        ++observations.motion_steps;
        CameraStep step;
        step.camera = cl;
        step.exposure_a = previous_exposure[p];
        step.exposure_b = e;
        step.T_bb_ba = T_enu_body.inverse() * previous_T_enu_body[p];
        std::vector<Eigen::Vector3d> points_ca;
        std::vector<Eigen::Vector2d> x_b;
        for (const auto& [ka, kb] : Putative(
                 previous[p], left, options.odometry.max_descriptor_ratio)) {
          if (!previous[p].has_point[ka]) continue;
          points_ca.push_back(previous[p].point_cam[ka]);
          x_b.push_back(left.normalized[kb]);
        }
        const CameraMotion motion = CameraMotionFromStereoPoints(
            options.odometry, points_ca, x_b,
            T_body_cl.inverse() * step.T_bb_ba * T_body_cl, focal);
        if (motion.valid) {
          step.T_cb_ca = motion.T_cb_ca;
          step.inliers = motion.inliers;
          observations.steps.push_back(step);
        }
      }
      previous[p] = std::move(left);
      previous_exposure[p] = e;
      previous_T_enu_body[p] = T_enu_body;
    }
    if (progress) progress(e + 1, num_exposures);
  }
  VLOG(1) << "mount: " << observations.steps.size() << " of "
          << observations.motion_steps << " camera motions measured, "
          << observations.stereo_points.size() << " stereo pairs, "
          << observations.images_read << " images";
  return observations;
}

}  // namespace zebrageo
