#include "geodata/camera_mount.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <sstream>
#include <vector>

#include "geodata/text_input.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/yaml_document.h"

namespace zebrageo {
namespace {

// Same tolerance as rig.yaml's reader on T_body_cam.
constexpr double kOrthonormalTolerance = 1e-6;

class MountFileParser {
 public:
  explicit MountFileParser(std::string path) : path_(std::move(path)) {}

  CameraMount Parse() const {
    const YAML::Node root = ParseYamlDocument(
        ReadTextInput(path_, "camera mount file", kMaxCalibrationFileBytes),
        path_);
    if (!root.IsMap()) Fail(root, "expected a YAML mapping (lever_arm, ...)");
    static const std::set<std::string> kKeys = {
        "lever_arm",      "roll_deg",   "pitch_deg", "yaw_deg",
        "pitch_down_deg", "R_body_cam", "T_body_cam"};
    for (const auto& entry : root) {
      const std::string key = entry.first.Scalar();
      if (kKeys.count(key) == 0) {
        Fail(entry.first, "unknown key '" + key +
                              "' (lever_arm, roll_deg, pitch_deg, yaw_deg, "
                              "pitch_down_deg, R_body_cam, T_body_cam)");
      }
    }
    const bool angles = root["roll_deg"] || root["pitch_deg"] ||
                        root["yaw_deg"] || root["pitch_down_deg"];
    const int ways = (angles ? 1 : 0) + (root["R_body_cam"] ? 1 : 0) +
                     (root["T_body_cam"] ? 1 : 0);
    if (ways > 1) {
      Fail(root,
           "give the rotation one way: angles (roll_deg, pitch_deg, yaw_deg), "
           "R_body_cam or T_body_cam");
    }
    if (root["pitch_deg"] && root["pitch_down_deg"]) {
      Fail(root["pitch_down_deg"], "pitch_down_deg and pitch_deg both given");
    }
    CameraMount mount;
    mount.rotation_stated = ways == 1;
    if (root["T_body_cam"]) {
      if (root["lever_arm"]) {
        Fail(root["lever_arm"],
             "lever_arm and T_body_cam both given (T_body_cam holds it)");
      }
      const std::vector<double> t =
          Numbers(root["T_body_cam"], "T_body_cam", 16, kMaxLeverArmM);
      if (t[12] != 0.0 || t[13] != 0.0 || t[14] != 0.0 || t[15] != 1.0) {
        Fail(root["T_body_cam"], "T_body_cam: last row must be 0 0 0 1");
      }
      mount.R_body_cam = Rotation(root["T_body_cam"], "T_body_cam", t, 4);
      mount.lever_arm_m = Eigen::Vector3d(t[3], t[7], t[11]);
      return mount;
    }
    if (root["lever_arm"]) {
      const std::vector<double> arm =
          Numbers(root["lever_arm"], "lever_arm", 3, kMaxLeverArmM);
      mount.lever_arm_m = Eigen::Vector3d(arm[0], arm[1], arm[2]);
    }
    if (root["R_body_cam"]) {
      mount.R_body_cam =
          Rotation(root["R_body_cam"], "R_body_cam",
                   Numbers(root["R_body_cam"], "R_body_cam", 9, 1.0 + 1e-6), 3);
    } else if (angles) {
      const double pitch = root["pitch_down_deg"]
                               ? -Angle(root, "pitch_down_deg", 90.0)
                               : Angle(root, "pitch_deg", 90.0);
      mount.R_body_cam = MountRotation(DegToRad(Angle(root, "roll_deg", 180.0)),
                                       DegToRad(pitch),
                                       DegToRad(Angle(root, "yaw_deg", 180.0)));
    }
    return mount;
  }

 private:
  [[noreturn]] void Fail(const YAML::Node& node,
                         const std::string& problem) const {
    throw InputError(path_, YamlLine(node), problem);
  }

  double Number(const YAML::Node& node, const std::string& what,
                double limit) const {
    double value = 0.0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
      Fail(node, what + " is not a number");
    }
    if (!std::isfinite(value)) Fail(node, what + " is not finite");
    if (std::abs(value) > limit) {
      std::ostringstream problem;
      problem << what << " = " << value << " is outside [" << -limit << ", "
              << limit << "]";
      Fail(node, problem.str());
    }
    return value;
  }

  // An angle key (degrees), 0 when absent.
  double Angle(const YAML::Node& root, const std::string& key,
               double limit) const {
    return root[key] ? Number(root[key], key, limit) : 0.0;
  }

  std::vector<double> Numbers(const YAML::Node& node, const std::string& key,
                              size_t count, double limit) const {
    if (!node.IsSequence() || node.size() != count) {
      Fail(node,
           key + " must be a list of " + std::to_string(count) + " numbers");
    }
    std::vector<double> values;
    for (size_t i = 0; i < count; ++i) {
      values.push_back(
          Number(node[i], key + "[" + std::to_string(i) + "]", limit));
    }
    return values;
  }

  Eigen::Matrix3d Rotation(const YAML::Node& node, const std::string& key,
                           const std::vector<double>& values,
                           int stride) const {
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = values[r * stride + c];
    }
    const std::string problem = RotationProblem(R);
    if (!problem.empty()) Fail(node, key + ": " + problem);
    return R;
  }

  std::string path_;
};

}  // namespace

Eigen::Matrix3d LevelForwardCameraRotation() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  return R;
}

Eigen::Matrix3d MountRotation(double roll_rad, double pitch_rad,
                              double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
             .toRotationMatrix() *
         LevelForwardCameraRotation();
}

Eigen::Vector3d MountAngles(const Eigen::Matrix3d& R_body_cam) {
  // The camera's forward-right-down frame in the body frame.
  const Eigen::Matrix3d M =
      R_body_cam * LevelForwardCameraRotation().transpose();
  // atan2, not asin: accurate near +-90 degrees too.
  const double cos_pitch = std::hypot(M(0, 0), M(1, 0));
  const double pitch = std::atan2(-M(2, 0), cos_pitch);
  if (cos_pitch < 1e-12) {
    return Eigen::Vector3d(0.0, pitch, std::atan2(-M(0, 1), M(1, 1)));
  }
  return Eigen::Vector3d(std::atan2(M(2, 1), M(2, 2)), pitch,
                         std::atan2(M(1, 0), M(0, 0)));
}

std::string RotationProblem(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) return "the rotation has non-finite elements";
  const double error =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > kOrthonormalTolerance) {
    std::ostringstream problem;
    problem << "not a rotation: not orthonormal (|R^T R - I| = " << error
            << " > " << kOrthonormalTolerance
            << "; write its elements with 9 or more significant digits)";
    return problem.str();
  }
  if (R.determinant() < 0.0) {
    return "not a rotation: determinant -1 (a reflection: an axis is "
           "flipped)";
  }
  return "";
}

Eigen::Isometry3d CameraMount::T_body_cam() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_body_cam;
  T.translation() = lever_arm_m;
  return T;
}

CameraMount ReadCameraMountFile(const std::string& path) {
  return MountFileParser(path).Parse();
}

}  // namespace zebrageo
