#include "tiepoints/mount_misalignment.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

Eigen::Matrix3d ExpRotation(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d LogRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Isometry3d Rotated(const Eigen::Isometry3d& T_body_cam,
                          const Eigen::Vector3d& w) {
  Eigen::Isometry3d E = Eigen::Isometry3d::Identity();
  E.linear() = ExpRotation(w);
  return E * T_body_cam;
}

// The road plane's unit normal (down, stated body frame) of one stereo
// pair's points, or false.
bool RoadNormal(const MountMisalignmentOptions& options,
                const Eigen::Isometry3d& T_body_cam, const StereoPoints& stereo,
                Eigen::Vector3d* normal) {
  const double camera_z = T_body_cam.translation().z();
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& p_cam : stereo.points_cam) {
    const Eigen::Vector3d p = T_body_cam * p_cam;
    if (p.x() >= options.min_road_ahead_m &&
        p.x() <= options.max_road_ahead_m &&
        std::abs(p.y()) <= options.max_road_lateral_m &&
        p.z() > camera_z + 0.5) {
      points.push_back(p);
    }
  }
  const int n = static_cast<int>(points.size());
  if (n < options.min_road_points) return false;
  std::mt19937 random(12345);
  std::uniform_int_distribution<int> pick(0, n - 1);
  const double min_cos = std::cos(options.max_road_tilt_rad);
  std::vector<char> best;
  int best_count = 0;
  for (int iteration = 0; iteration < 300; ++iteration) {
    const Eigen::Vector3d& a = points[pick(random)];
    const Eigen::Vector3d& b = points[pick(random)];
    const Eigen::Vector3d& c = points[pick(random)];
    Eigen::Vector3d m = (b - a).cross(c - a);
    if (m.norm() < 1e-6) continue;
    m.normalize();
    if (m.z() < 0.0) m = -m;
    if (m.z() < min_cos) continue;
    std::vector<char> inlier(n, 0);
    int count = 0;
    for (int i = 0; i < n; ++i) {
      inlier[i] = std::abs(m.dot(points[i] - a)) <= options.road_tolerance_m;
      count += inlier[i];
    }
    if (count > best_count) {
      best_count = count;
      best = std::move(inlier);
    }
  }
  if (best_count < options.min_road_points) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (best[i]) mean += points[i];
  }
  mean /= best_count;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (best[i]) scatter += (points[i] - mean) * (points[i] - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Eigen::Vector3d m = solver.eigenvectors().col(0);
  if (m.z() < 0.0) m = -m;
  if (!m.allFinite() || m.z() < min_cos) return false;
  *normal = m;
  return true;
}

// The body's motion T_bb_ba with its rotation from the trajectory and its
// translation along the body's forward axis, turned by half the rotation
// (the chord of an arc), of the trajectory's length. A vehicle travels
// along its axis: the field cases' true trajectories depart from it by
// 0.03-0.08 degrees (no side slip to speak of), while their GNSS/INS
// positions, differenced over 0.5 s, wander by 0.1-1.7 degrees (sd); the
// attitude is good to a few hundredths of a degree from sample to sample.
Eigen::Isometry3d AlongBodyAxis(const Eigen::Isometry3d& T_bb_ba) {
  const Eigen::Isometry3d T_ba_bb = T_bb_ba.inverse();
  const Eigen::Quaterniond half = Eigen::Quaterniond::Identity().slerp(
      0.5, Eigen::Quaterniond(T_ba_bb.linear()));
  Eigen::Isometry3d along = Eigen::Isometry3d::Identity();
  along.linear() = T_ba_bb.linear();
  along.translation() =
      T_ba_bb.translation().norm() * (half * Eigen::Vector3d::UnitX());
  return along.inverse();
}

// The evidence, each residual with its kind (0 direction, 1 turn,
// 2 plane), as a function of the mount's rotation.
struct Evidence {
  std::vector<const CameraStep*> steps;
  std::vector<Eigen::Isometry3d> body_steps;  // T_bb_ba, AlongBodyAxis
  std::vector<Eigen::Isometry3d> T_body_cam;  // of each step's camera
  std::vector<Eigen::Vector3d> normals;       // stated body frame

  int size() const {
    return static_cast<int>(6 * steps.size() + 2 * normals.size());
  }
  static int KindOf(int row, int num_steps) {
    if (row < 6 * num_steps) return row % 6 < 3 ? 0 : 1;
    return 2;
  }
  Eigen::VectorXd Residuals(const Eigen::Vector3d& w) const {
    Eigen::VectorXd r(size());
    for (size_t i = 0; i < steps.size(); ++i) {
      const Eigen::Isometry3d X = Rotated(T_body_cam[i], w);
      const Eigen::Isometry3d predicted = X.inverse() * body_steps[i] * X;
      // Where camera b is in camera a's frame: the direction of travel.
      const Eigen::Vector3d c_measured =
          steps[i]->T_cb_ca.inverse().translation().normalized();
      const Eigen::Vector3d c_predicted =
          predicted.inverse().translation().normalized();
      r.segment<3>(6 * i) = c_measured - c_predicted;
      r.segment<3>(6 * i + 3) = LogRotation(steps[i]->T_cb_ca.linear() *
                                            predicted.linear().transpose());
    }
    const Eigen::Vector3d down = ExpRotation(-w) * Eigen::Vector3d::UnitZ();
    for (size_t j = 0; j < normals.size(); ++j) {
      r.segment<2>(6 * steps.size() + 2 * j) = (normals[j] - down).head<2>();
    }
    return r;
  }
};

double RobustSigma(std::vector<double> values) {
  if (values.empty()) return 0.0;
  for (double& v : values) v = std::abs(v);
  return 1.4826 * Median(values);
}

}  // namespace

std::string MountMisalignmentOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, min_step_m, 0.0);
  OPTION_GE(check, min_road_ahead_m, 0.0);
  OPTION_GT(check, max_road_ahead_m, min_road_ahead_m);
  OPTION_GT(check, max_road_lateral_m, 0.0);
  OPTION_GT(check, road_tolerance_m, 0.0);
  OPTION_GE(check, min_road_points, 3);
  OPTION_IN(check, max_road_tilt_rad, "(", 0.0, 1.0, ")");
  OPTION_GE(check, road_bias_sd_rad, 0.0);
  OPTION_GE(check, direction_bias_sd_rad, 0.0);
  OPTION_GT(check, prior_sd_rad, 0.0);
  OPTION_GE(check, min_steps, 1);
  OPTION_GE(check, min_planes, 1);
  return check.problem();
}

MountMisalignment EstimateMountMisalignment(
    const MountMisalignmentOptions& options, const Rig& rig,
    const MountObservations& observations) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("MountMisalignmentOptions: " + problem);
  }
  Evidence evidence;
  for (const CameraStep& step : observations.steps) {
    if (step.T_bb_ba.translation().norm() < options.min_step_m) continue;
    evidence.steps.push_back(&step);
    evidence.body_steps.push_back(AlongBodyAxis(step.T_bb_ba));
    evidence.T_body_cam.push_back(rig.cameras[step.camera].T_body_cam);
  }
  if (static_cast<int>(evidence.steps.size()) < options.min_steps) {
    evidence.steps.clear();
    evidence.T_body_cam.clear();
  }
  for (const StereoPoints& stereo : observations.stereo_points) {
    Eigen::Vector3d normal;
    if (RoadNormal(options, rig.cameras[stereo.camera].T_body_cam, stereo,
                   &normal)) {
      evidence.normals.push_back(normal);
    }
  }
  if (static_cast<int>(evidence.normals.size()) < options.min_planes) {
    evidence.normals.clear();
  }
  MountMisalignment result;
  result.steps_used = static_cast<int>(evidence.steps.size());
  result.planes_used = static_cast<int>(evidence.normals.size());
  if (evidence.size() == 0) return result;
  const int num_steps = result.steps_used;
  // Starting scatter of each kind (radians); then from the residuals.
  double sigma[3] = {0.005, 0.0005, 0.005};
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Identity();
  for (int round = 0; round < 3; ++round) {
    for (int iteration = 0; iteration < 8; ++iteration) {
      const Eigen::VectorXd r = evidence.Residuals(w);
      Eigen::MatrixXd J(r.size(), 3);
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dw = Eigen::Vector3d::Zero();
        dw[k] = 1e-6;
        J.col(k) = (evidence.Residuals(w + dw) - r) / 1e-6;
      }
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      for (int i = 0; i < r.size(); ++i) {
        const double s = sigma[Evidence::KindOf(i, num_steps)];
        // Huber's weight at 2.5 sigma: mismatched features and a road
        // plane on a car's bonnet count little.
        const double u = std::abs(r[i]) / s;
        const double weight = (u <= 2.5 ? 1.0 : 2.5 / u) / (s * s);
        A += weight * J.row(i).transpose() * J.row(i);
        b += weight * J.row(i).transpose() * r[i];
      }
      // A weak prior keeps an axis nothing observes near zero (without
      // it, roll from a few turns alone wandered to -58 degrees on a
      // simulated survey whose road gave no plane).
      A += Eigen::Matrix3d::Identity() /
           (options.prior_sd_rad * options.prior_sd_rad);
      const Eigen::Vector3d step = -A.ldlt().solve(b);
      w += step;
      normal_matrix = A;
      if (step.norm() < 1e-9) break;
    }
    const Eigen::VectorXd r = evidence.Residuals(w);
    std::vector<double> kinds[3];
    for (int i = 0; i < r.size(); ++i) {
      kinds[Evidence::KindOf(i, num_steps)].push_back(r[i]);
    }
    for (int k = 0; k < 3; ++k) {
      if (!kinds[k].empty()) sigma[k] = std::max(RobustSigma(kinds[k]), 1e-5);
    }
  }
  Eigen::Matrix3d covariance = normal_matrix.inverse();
  if (!evidence.normals.empty()) {
    // The road's systematic part on roll and pitch.
    covariance(0, 0) += options.road_bias_sd_rad * options.road_bias_sd_rad;
    covariance(1, 1) += options.road_bias_sd_rad * options.road_bias_sd_rad;
  }
  if (num_steps > 0) {
    covariance(2, 2) +=
        options.direction_bias_sd_rad * options.direction_bias_sd_rad;
  }
  result.estimated = w.allFinite() && covariance.allFinite();
  if (!result.estimated) return MountMisalignment();
  result.rotation_body_rad = w;
  result.sd_rad = covariance.diagonal().cwiseSqrt();
  result.direction_sigma_rad = num_steps > 0 ? sigma[0] : 0.0;
  result.turn_sigma_rad = num_steps > 0 ? sigma[1] : 0.0;
  result.plane_sigma_rad = result.planes_used > 0 ? sigma[2] : 0.0;
  return result;
}

Rig RotateRigMount(const Rig& rig, const Eigen::Vector3d& rotation_body_rad) {
  Rig rotated = rig;
  for (RigCamera& camera : rotated.cameras) {
    camera.T_body_cam = Rotated(camera.T_body_cam, rotation_body_rad);
  }
  return rotated;
}

}  // namespace zebrageo
