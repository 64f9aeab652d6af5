#include "tiepoints/tie_points.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "survey/image_io.h"
#include "survey/math_util.h"
#include "tiepoints/stereo_odometry.h"

namespace zebrageo {
namespace {

constexpr float kOrbScaleFactor = 1.2f;

struct ImageFeatures {
  bool valid = false;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<Eigen::Vector2d> normalized;  // undistorted x/z, y/z
  std::vector<char> has_normalized;
  // The pose the geometric checks use: the trajectory's, with the camera's
  // motion between exposures measured from the images where they could
  // (stereo_odometry.h); it agrees with the trajectory's locally, not
  // globally.
  Eigen::Isometry3d T_enu_cam = Eigen::Isometry3d::Identity();
  // The trajectory's pose (tracks are expressed in its frame).
  Eigen::Isometry3d T_enu_cam_ins = Eigen::Isometry3d::Identity();
  // Keypoints triangulated by this image's stereo pair (camera frame).
  std::vector<Eigen::Vector3d> point_cam;
  std::vector<char> has_point;
};

// Union-find over (image, keypoint) nodes.
class DisjointSets {
 public:
  int Add() {
    parent_.push_back(static_cast<int>(parent_.size()));
    return parent_.back();
  }
  int Find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Union(int a, int b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<int> parent_;
};

// Epipolar distance (pixels in image b) of a correspondence between images
// a and b with known poses.
double EpipolarDistancePx(const ImageFeatures& a, const ImageFeatures& b,
                          const Eigen::Vector2d& xa, const Eigen::Vector2d& xb,
                          double focal_b) {
  const Eigen::Isometry3d T_b_a = b.T_enu_cam.inverse() * a.T_enu_cam;
  const Eigen::Vector3d t = T_b_a.translation();
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d E = tx * T_b_a.linear();
  const Eigen::Vector3d line = E * xa.homogeneous();
  const double norm = line.head<2>().norm();
  if (norm <= 0.0) return HUGE_VAL;
  return std::abs(line.dot(xb.homogeneous())) / norm * focal_b;
}

// A matched component that passed every test, and the exposures it ties.
struct Candidate {
  TieTrack track;
  std::vector<int> exposures;
};

// Why matched components did not become tracks (VLOG(1)): a diagnosis of
// a scene whose ties are few.
struct Rejections {
  int components = 0, short_track = 0, same_image = 0, narrow_angle = 0,
      reprojection = 0, one_exposure = 0, no_stereo = 0;
};

// The features of every image and the matches between them, as a
// union-find over (image, keypoint) nodes; its connected components are the
// candidate tracks.
class FeatureGraph {
 public:
  FeatureGraph(const TiePointOptions& options, const std::string& folder,
               const Rig& rig, const Trajectory& trajectory,
               const ExposureTable& exposures, TiePointSummary* summary)
      : options_(options),
        folder_(folder),
        rig_(rig),
        trajectory_(trajectory),
        exposures_(exposures),
        summary_(summary),
        features_(exposures.images.size()),
        node_offset_(exposures.images.size(), 0),
        orb_(cv::ORB::create(options.max_features_per_image, kOrbScaleFactor,
                             options.orb_levels)),
        matcher_(cv::NORM_HAMMING),
        T_enu_body_ins_(exposures.exposures.size()),
        T_enu_body_checked_(exposures.exposures.size()),
        has_checked_pose_(exposures.exposures.size(), 0) {
    for (int e = 0; e < static_cast<int>(exposures.exposures.size()); ++e) {
      exposure_index_[exposures.exposures[e].exposure_id] = e;
    }
  }

  // Each exposure's images matched within its stereo pairs and with the
  // same camera of the exposure_window exposures before it.
  void MatchExposures(const std::function<void(int, int)>& progress,
                      const CancellationToken& cancel);

  // The components that make a track, in the order of their roots.
  std::vector<Candidate> Candidates(Rejections* rejected);

  // Exposure steps whose motion the images measured, of all steps, and
  // how far the trajectory's motion departed from it (metres).
  int motions_measured() const { return motions_measured_; }
  int motion_steps() const { return motion_steps_; }
  const std::vector<double>& motion_departures_m() const {
    return motion_departures_m_;
  }

 private:
  void Load(int image_index);
  void RefineSubpixel(const cv::Mat& grey, ImageFeatures* f) const;
  // Keypoint pairs of images a and b that pass the descriptor ratio test.
  // (`ratio`: Lowe's ratio, the options' when negative).
  std::vector<std::pair<int, int>> Putative(int a, int b, double ratio = -1.0);
  // Joins the putative pairs that the epipolar geometry of the two images'
  // checked poses accepts; returns them.
  std::vector<std::pair<int, int>> Match(int a, int b);
  // Stereo points of image a from its matches with image b of the same
  // exposure (the rig's calibration, no trajectory).
  void TriangulateStereo(int a, int b,
                         const std::vector<std::pair<int, int>>& pairs);
  // Exposure e's checked poses: the previous exposure's, moved by the
  // camera's motion measured from the images, or the trajectory's motion
  // where they could not measure it.
  void SetCheckedPoses(int e);
  // Midpoint triangulation of the nodes' rays; false when not finite.
  bool Triangulate(const std::vector<int>& nodes, Eigen::Vector3d* X,
                   double* max_angle) const;
  // False (the reason counted in `rejected`) when the component is no
  // track.
  bool MakeCandidate(const std::vector<int>& nodes, Rejections* rejected,
                     Candidate* candidate);
  bool HasStereo(const TieTrack& track);

  const TiePointOptions& options_;
  const std::string& folder_;
  const Rig& rig_;
  const Trajectory& trajectory_;
  const ExposureTable& exposures_;
  TiePointSummary* summary_;
  std::vector<ImageFeatures> features_;
  std::vector<int> node_offset_;
  DisjointSets sets_;
  std::vector<std::pair<int, int>> node_key_;  // node -> (image, keypoint)
  std::map<int64_t, int> exposure_index_;
  cv::Ptr<cv::ORB> orb_;
  cv::BFMatcher matcher_;
  const StereoOdometryOptions odometry_;
  std::vector<Eigen::Isometry3d> T_enu_body_ins_;
  std::vector<Eigen::Isometry3d> T_enu_body_checked_;
  std::vector<char> has_checked_pose_;
  int motions_measured_ = 0;
  int motion_steps_ = 0;
  std::vector<double> motion_departures_m_;
};

void FeatureGraph::Load(int image_index) {
  ImageFeatures& f = features_[image_index];
  const ExposureImage& image = exposures_.images[image_index];
  const std::string path =
      (std::filesystem::path(folder_) / image.image).string();
  Pose pose;
  if (!trajectory_.InterpolatePose(image.time, &pose)) return;
  cv::Mat grey;
  try {
    const cv::Mat f32 = ReadGrayImage(path, image.image);
    f32.convertTo(grey, CV_8U);
  } catch (const std::exception&) {
    ++summary_->images_missing;
    return;
  }
  ++summary_->images_read;
  orb_->detectAndCompute(grey, cv::noArray(), f.keypoints, f.descriptors);
  // ORB reports a keypoint found on pyramid level l at x_l * s; with
  // pixel centres at integers (cv::resize) it is at (x_l + 0.5) s - 0.5.
  for (cv::KeyPoint& kp : f.keypoints) {
    const double scale = std::pow(kOrbScaleFactor, kp.octave);
    kp.pt.x += static_cast<float>(0.5 * (scale - 1.0));
    kp.pt.y += static_cast<float>(0.5 * (scale - 1.0));
  }
  if (options_.refine_subpixel) RefineSubpixel(grey, &f);
  const Camera& camera = rig_.cameras[image.camera].camera;
  f.normalized.resize(f.keypoints.size());
  f.has_normalized.assign(f.keypoints.size(), 0);
  for (size_t k = 0; k < f.keypoints.size(); ++k) {
    const Eigen::Vector2d uv(f.keypoints[k].pt.x, f.keypoints[k].pt.y);
    f.has_normalized[k] = camera.UnprojectToNormalized(uv, &f.normalized[k]);
  }
  f.T_enu_cam = pose.T_enu_body() * rig_.cameras[image.camera].T_body_cam;
  f.T_enu_cam_ins = f.T_enu_cam;
  f.point_cam.resize(f.keypoints.size());
  f.has_point.assign(f.keypoints.size(), 0);
  f.valid = !f.keypoints.empty();
  node_offset_[image_index] = static_cast<int>(node_key_.size());
  for (size_t k = 0; k < f.keypoints.size(); ++k) {
    sets_.Add();
    node_key_.emplace_back(image_index, static_cast<int>(k));
  }
}

void FeatureGraph::RefineSubpixel(const cv::Mat& grey, ImageFeatures* f) const {
  if (f->keypoints.empty()) return;
  std::vector<cv::Point2f> corners;
  for (const cv::KeyPoint& kp : f->keypoints) corners.push_back(kp.pt);
  cv::cornerSubPix(
      grey, corners, cv::Size(2, 2), cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 10,
                       0.01));
  for (size_t k = 0; k < corners.size(); ++k) {
    // Keep the detector's position when the refinement wanders off.
    const cv::Point2f d = corners[k] - f->keypoints[k].pt;
    if (d.dot(d) < 1.0) f->keypoints[k].pt = corners[k];
  }
}

std::vector<std::pair<int, int>> FeatureGraph::Putative(int a, int b,
                                                        double ratio) {
  if (ratio < 0.0) ratio = options_.max_descriptor_ratio;
  std::vector<std::pair<int, int>> pairs;
  const ImageFeatures& fa = features_[a];
  const ImageFeatures& fb = features_[b];
  if (!fa.valid || !fb.valid || fa.descriptors.empty() ||
      fb.descriptors.empty()) {
    return pairs;
  }
  std::vector<std::vector<cv::DMatch>> knn;
  matcher_.knnMatch(fa.descriptors, fb.descriptors, knn, 2);
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance > ratio * m[1].distance) {
      continue;
    }
    const int ka = m[0].queryIdx, kb = m[0].trainIdx;
    if (!fa.has_normalized[ka] || !fb.has_normalized[kb]) continue;
    pairs.emplace_back(ka, kb);
  }
  return pairs;
}

std::vector<std::pair<int, int>> FeatureGraph::Match(int a, int b) {
  std::vector<std::pair<int, int>> kept;
  const ImageFeatures& fa = features_[a];
  const ImageFeatures& fb = features_[b];
  const double focal = rig_.cameras[exposures_.images[b].camera].camera.fx();
  for (const auto& [ka, kb] : Putative(a, b)) {
    if (EpipolarDistancePx(fa, fb, fa.normalized[ka], fb.normalized[kb],
                           focal) > options_.max_epipolar_distance_px) {
      continue;
    }
    sets_.Union(node_offset_[a] + ka, node_offset_[b] + kb);
    ++summary_->matches;
    kept.emplace_back(ka, kb);
  }
  return kept;
}

void FeatureGraph::TriangulateStereo(
    int a, int b, const std::vector<std::pair<int, int>>& pairs) {
  ImageFeatures& fa = features_[a];
  const ImageFeatures& fb = features_[b];
  const Eigen::Isometry3d T_cb_ca =
      rig_.cameras[exposures_.images[b].camera].T_body_cam.inverse() *
      rig_.cameras[exposures_.images[a].camera].T_body_cam;
  const double focal = rig_.cameras[exposures_.images[a].camera].camera.fx();
  for (const auto& [ka, kb] : pairs) {
    fa.has_point[ka] =
        TriangulateStereoPoint(odometry_, T_cb_ca, fa.normalized[ka],
                               fb.normalized[kb], focal, &fa.point_cam[ka]);
  }
}

void FeatureGraph::SetCheckedPoses(int e) {
  const Exposure& exposure = exposures_.exposures[e];
  int first = -1;  // an image with a pose gives the trajectory's body pose
  for (int image : exposure.image_of_camera) {
    if (image >= 0 && features_[image].valid) {
      first = image;
      break;
    }
  }
  if (first < 0) return;
  T_enu_body_ins_[e] =
      features_[first].T_enu_cam_ins *
      rig_.cameras[exposures_.images[first].camera].T_body_cam.inverse();
  T_enu_body_checked_[e] = T_enu_body_ins_[e];
  has_checked_pose_[e] = 1;
  if (e > 0 && has_checked_pose_[e - 1]) {
    // The step from the previous exposure: the trajectory's, replaced by
    // the images' where a stereo pair measured it (the most inliers).
    const Exposure& previous = exposures_.exposures[e - 1];
    Eigen::Isometry3d T_prev_body =
        T_enu_body_ins_[e - 1].inverse() * T_enu_body_ins_[e];
    CameraMotion best;
    int best_camera = -1;
    for (const auto& pair : rig_.stereo_pairs) {
      const int a = previous.image_of_camera[pair[0]];
      const int b = exposure.image_of_camera[pair[0]];
      if (a < 0 || b < 0 || !features_[a].valid || !features_[b].valid) {
        continue;
      }
      std::vector<Eigen::Vector3d> points_ca;
      std::vector<Eigen::Vector2d> x_b;
      // A looser ratio test: PnP with RANSAC verifies these.
      for (const auto& [ka, kb] :
           Putative(a, b, odometry_.max_descriptor_ratio)) {
        if (!features_[a].has_point[ka]) continue;
        points_ca.push_back(features_[a].point_cam[ka]);
        x_b.push_back(features_[b].normalized[kb]);
      }
      const CameraMotion motion = CameraMotionFromStereoPoints(
          odometry_, points_ca, x_b,
          features_[b].T_enu_cam_ins.inverse() * features_[a].T_enu_cam_ins,
          rig_.cameras[pair[0]].camera.fx());
      VLOG(2) << "tie points: camera motion at exposure " << e << ": "
              << motion.correspondences << " stereo points seen again, "
              << motion.inliers << " inliers, accepted " << motion.valid;
      if (motion.valid && motion.inliers > best.inliers) {
        best = motion;
        best_camera = pair[0];
      }
    }
    ++motion_steps_;
    if (best_camera >= 0) {
      const Eigen::Isometry3d& T_body_cam =
          rig_.cameras[best_camera].T_body_cam;
      const Eigen::Isometry3d T_prev_body_images =
          T_body_cam * best.T_cb_ca.inverse() * T_body_cam.inverse();
      motion_departures_m_.push_back(
          (T_prev_body_images.translation() - T_prev_body.translation())
              .norm());
      T_prev_body = T_prev_body_images;
      ++motions_measured_;
    }
    T_enu_body_checked_[e] = T_enu_body_checked_[e - 1] * T_prev_body;
  }
  for (size_t c = 0; c < rig_.cameras.size(); ++c) {
    const int image = exposure.image_of_camera[c];
    if (image >= 0 && features_[image].valid) {
      features_[image].T_enu_cam =
          T_enu_body_checked_[e] * rig_.cameras[c].T_body_cam;
    }
  }
}

void FeatureGraph::MatchExposures(const std::function<void(int, int)>& progress,
                                  const CancellationToken& cancel) {
  const int num_exposures = static_cast<int>(exposures_.exposures.size());
  const int window = options_.exposure_window;
  for (int e = 0; e < num_exposures; ++e) {
    cancel.ThrowIfCancelled();  // between exposures
    const Exposure& exposure = exposures_.exposures[e];
    for (int image : exposure.image_of_camera) {
      if (image >= 0) Load(image);
    }
    for (const auto& pair : rig_.stereo_pairs) {
      const int a = exposure.image_of_camera[pair[0]];
      const int b = exposure.image_of_camera[pair[1]];
      if (a >= 0 && b >= 0) TriangulateStereo(a, b, Match(a, b));
    }
    SetCheckedPoses(e);
    for (int back = 1; back <= window && e - back >= 0; ++back) {
      const Exposure& previous = exposures_.exposures[e - back];
      for (size_t c = 0; c < rig_.cameras.size(); ++c) {
        const int a = previous.image_of_camera[c];
        const int b = exposure.image_of_camera[c];
        if (a >= 0 && b >= 0) Match(a, b);
      }
    }
    // Descriptors of exposures out of the window are no longer needed.
    if (e - window >= 0) {
      for (int image : exposures_.exposures[e - window].image_of_camera) {
        if (image >= 0) features_[image].descriptors.release();
      }
    }
    if (progress) progress(e + 1, num_exposures);
  }
}

bool FeatureGraph::Triangulate(const std::vector<int>& nodes,
                               Eigen::Vector3d* X, double* max_angle) const {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> directions;
  for (int node : nodes) {
    const auto [image, k] = node_key_[node];
    const ImageFeatures& f = features_[image];
    const Eigen::Vector3d d =
        (f.T_enu_cam.linear() * f.normalized[k].homogeneous()).normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * f.T_enu_cam.translation();
    directions.push_back(d);
  }
  *X = A.ldlt().solve(b);
  if (!X->allFinite()) return false;
  *max_angle = 0.0;
  for (size_t i = 0; i < directions.size(); ++i) {
    for (size_t j = i + 1; j < directions.size(); ++j) {
      *max_angle = std::max(
          *max_angle,
          std::acos(std::clamp(directions[i].dot(directions[j]), -1.0, 1.0)));
    }
  }
  return true;
}

// A stereo observation fixes the depth: a temporal mismatch on a repeated
// pattern (windows, bands) that slides along the epipolar line cannot agree
// with it.
bool FeatureGraph::HasStereo(const TieTrack& track) {
  std::map<int, int> cameras_in_exposure;
  bool stereo = false;
  for (const TieObservation& o : track.observations) {
    const int e = exposure_index_[exposures_.images[o.image].exposure_id];
    stereo |= ++cameras_in_exposure[e] >= 2;
  }
  return stereo;
}

bool FeatureGraph::MakeCandidate(const std::vector<int>& nodes,
                                 Rejections* rejected, Candidate* candidate) {
  if (static_cast<int>(nodes.size()) < options_.min_track_length) {
    ++rejected->short_track;
    return false;
  }
  std::vector<int> images;
  for (int node : nodes) images.push_back(node_key_[node].first);
  std::sort(images.begin(), images.end());
  if (std::adjacent_find(images.begin(), images.end()) != images.end()) {
    ++rejected->same_image;
    return false;
  }
  Eigen::Vector3d X;
  double max_angle = 0.0;
  if (!Triangulate(nodes, &X, &max_angle)) return false;
  if (max_angle < options_.min_triangulation_angle_rad) {
    ++rejected->narrow_angle;
    return false;
  }
  for (int node : nodes) {
    const auto [image, k] = node_key_[node];
    const ImageFeatures& f = features_[image];
    const ExposureImage& info = exposures_.images[image];
    const Eigen::Vector3d p_cam = f.T_enu_cam.inverse() * X;
    Eigen::Vector2d uv;
    const Eigen::Vector2d observed(f.keypoints[k].pt.x, f.keypoints[k].pt.y);
    if (p_cam.z() < 2.0 || p_cam.norm() > options_.max_range_m ||
        !rig_.cameras[info.camera].camera.Project(p_cam, &uv) ||
        (uv - observed).norm() > options_.max_reprojection_error_px) {
      ++rejected->reprojection;
      return false;
    }
    candidate->track.observations.push_back(
        {image, info.time, info.camera, observed,
         std::pow(kOrbScaleFactor, f.keypoints[k].octave)});
    candidate->exposures.push_back(exposure_index_[info.exposure_id]);
  }
  // X is in the checked poses' frame, which agrees with the trajectory's
  // only locally: carried over through the track's first image.
  const ImageFeatures& first = features_[node_key_[nodes.front()].first];
  candidate->track.p_enu =
      first.T_enu_cam_ins * (first.T_enu_cam.inverse() * X);
  std::vector<int>& tied = candidate->exposures;
  std::sort(tied.begin(), tied.end());
  tied.erase(std::unique(tied.begin(), tied.end()), tied.end());
  if (tied.size() < 2) {  // ties exposures together
    ++rejected->one_exposure;
    return false;
  }
  if (options_.require_stereo && !HasStereo(candidate->track)) {
    ++rejected->no_stereo;
    return false;
  }
  return true;
}

std::vector<Candidate> FeatureGraph::Candidates(Rejections* rejected) {
  // Tracks: connected components, at most one keypoint per image.
  std::map<int, std::vector<int>> components;
  for (int node = 0; node < static_cast<int>(node_key_.size()); ++node) {
    components[sets_.Find(node)].push_back(node);
  }
  std::vector<Candidate> candidates;
  for (const auto& [root, nodes] : components) {
    if (nodes.size() < 2) continue;
    ++rejected->components;
    Candidate candidate;
    if (MakeCandidate(nodes, rejected, &candidate)) {
      candidates.push_back(std::move(candidate));
    }
  }
  return candidates;
}

// The longest tracks first, until every exposure has enough.
std::vector<TieTrack> SelectTracks(const TiePointOptions& options,
                                   int num_exposures,
                                   std::vector<Candidate> candidates,
                                   TiePointSummary* summary) {
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) {
              return a.track.observations.size() > b.track.observations.size();
            });
  std::vector<int> kept_per_exposure(num_exposures, 0);
  std::vector<TieTrack> tracks;
  for (Candidate& c : candidates) {
    bool useful = false;
    for (int e : c.exposures) {
      useful |= kept_per_exposure[e] < options.max_tracks_per_exposure;
    }
    if (!useful) continue;
    for (int e : c.exposures) ++kept_per_exposure[e];
    summary->observations += static_cast<int>(c.track.observations.size());
    tracks.push_back(std::move(c.track));
  }
  summary->tracks = static_cast<int>(tracks.size());
  return tracks;
}

}  // namespace

std::vector<TieTrack> BuildTieTracks(
    const TiePointOptions& options, const std::string& survey_folder,
    const Rig& rig, const Trajectory& trajectory,
    const ExposureTable& exposures, TiePointSummary* summary,
    const std::function<void(int, int)>& progress,
    const CancellationToken& cancel) {
  const auto start = std::chrono::steady_clock::now();
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument("TiePointOptions: " + error);
  }
  TiePointSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  *summary = TiePointSummary();

  FeatureGraph graph(options, survey_folder, rig, trajectory, exposures,
                     summary);
  graph.MatchExposures(progress, cancel);
  Rejections rejected;
  std::vector<Candidate> candidates = graph.Candidates(&rejected);
  VLOG(1) << "tie points: " << rejected.components
          << " matched components; too short " << rejected.short_track
          << ", two keypoints in one image " << rejected.same_image
          << ", intersection angle " << rejected.narrow_angle
          << ", reprojection or range " << rejected.reprojection
          << ", one exposure " << rejected.one_exposure << ", no stereo "
          << rejected.no_stereo << "; " << candidates.size() << " candidates";
  std::vector<TieTrack> tracks =
      SelectTracks(options, static_cast<int>(exposures.exposures.size()),
                   std::move(candidates), summary);
  summary->time_in_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (!graph.motion_departures_m().empty()) {
    LOG(INFO) << "tie points: the camera's motion measured from the images "
              << "for " << graph.motions_measured() << " of "
              << graph.motion_steps()
              << " exposure steps; the trajectory's departs from it by "
              << Median(graph.motion_departures_m()) * 100.0 << " cm (median)";
  }
  LOG(INFO) << "tie points: " << summary->tracks << " tracks, "
            << summary->observations << " observations from "
            << summary->images_read << " images in " << summary->time_in_seconds
            << " s";
  return tracks;
}

}  // namespace zebrageo
