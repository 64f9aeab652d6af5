#include "geodata/calibration_import.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "geodata/text_input.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"
#include "survey/yaml_document.h"

namespace zebrageo {
namespace {

// Same tolerance as rig.yaml's reader on T_body_cam.
constexpr double kOrthonormalTolerance = 1e-6;
// A baseline longer than this is almost surely in millimetres.
constexpr double kMaxPlausibleBaselineM = 10.0;

// The line of `node`, or 0 for a key that is absent (yaml-cpp throws when
// asked the position of a node that does not exist).
int LineOf(const YAML::Node& node) {
  return node.IsDefined() ? YamlLine(node) : 0;
}

// The file's text: never more than a calibration file can be (a device
// such as /dev/zero is refused, not read for ever), never binary data.
std::string ReadText(const std::string& path, const char* what) {
  return ReadTextInput(path, what, kMaxCalibrationFileBytes);
}

// A YAML document whose top level is a mapping, or "not a <what>".
YAML::Node ReadYamlMapping(const std::string& path, const char* what) {
  const YAML::Node root = ParseYamlDocument(ReadText(path, what), path);
  if (!root.IsMap()) {
    throw InputError(
        path, 1, std::string("not a ") + what + ": expected a YAML mapping");
  }
  return root;
}

// Numbers of a flat list, or of a list of lists (Kalibr writes 4x4 as
// rows): `depth` more levels of nesting are accepted.
std::vector<double> Numbers(const YAML::Node& node, const std::string& key,
                            const std::string& path, int depth = 1) {
  std::vector<double> values;
  if (!node || !node.IsSequence()) {
    throw InputError(path, LineOf(node),
                     "'" + key + "' must be a list of numbers");
  }
  for (const YAML::Node& item : node) {
    if (item.IsSequence() && depth > 0) {
      for (double v : Numbers(item, key, path, depth - 1)) values.push_back(v);
      continue;
    }
    double value = 0.0;
    if (!item.IsScalar() || !YAML::convert<double>::decode(item, value) ||
        !std::isfinite(value)) {
      throw InputError(path, LineOf(item),
                       "'" + key + "' holds something that is not a number");
    }
    values.push_back(value);
  }
  return values;
}

std::vector<double> Required(const YAML::Node& parent, const std::string& key,
                             size_t size, const std::string& path) {
  const YAML::Node node = parent[key];
  if (!node) {
    throw InputError(path, LineOf(parent), "missing key '" + key + "'");
  }
  const std::vector<double> values = Numbers(node, key, path);
  if (values.size() != size) {
    throw InputError(path, LineOf(node),
                     "'" + key + "' must have " + std::to_string(size) +
                         " numbers, not " + std::to_string(values.size()));
  }
  return values;
}

std::string RequiredString(const YAML::Node& parent, const std::string& key,
                           const std::string& path) {
  const YAML::Node node = parent[key];
  if (!node || !node.IsScalar()) {
    throw InputError(path, LineOf(parent), "missing text key '" + key + "'");
  }
  return node.Scalar();
}

int RequiredInt(const YAML::Node& parent, const std::string& key,
                const std::string& path) {
  const YAML::Node node = parent[key];
  int value = 0;
  if (!node || !node.IsScalar() || !YAML::convert<int>::decode(node, value) ||
      value <= 0) {
    throw InputError(path, node ? LineOf(node) : LineOf(parent),
                     "'" + key + "' must be a positive integer");
  }
  return value;
}

Eigen::Matrix3d RotationOf(const std::vector<double>& row_major, int stride,
                           const YAML::Node& node, const std::string& key,
                           const std::string& path) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = row_major[r * stride + c];
  }
  const double error =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > kOrthonormalTolerance || R.determinant() < 0.0) {
    throw InputError(path, LineOf(node),
                     "'" + key + "' rotation is not orthonormal");
  }
  return R;
}

void CheckBaseline(const Eigen::Vector3d& t, const YAML::Node& node,
                   const std::string& path) {
  if (t.norm() > kMaxPlausibleBaselineM) {
    std::ostringstream problem;
    problem << "baseline " << t.norm()
            << " is implausible in metres (millimetres?)";
    throw InputError(path, LineOf(node), problem.str());
  }
}

// OpenCV distortion of a camera in `model` with `coefficients`.
std::array<double, 5> OpenCvDistortion(const std::string& model,
                                       const std::vector<double>& coefficients,
                                       double fx, double fy, double cx,
                                       double cy, int width, int height,
                                       const CalibrationImportOptions& options,
                                       const YAML::Node& node,
                                       const std::string& path) {
  auto need = [&](size_t n) {
    if (coefficients.size() != n) {
      throw InputError(path, LineOf(node),
                       "distortion model '" + model + "' needs " +
                           std::to_string(n) + " coefficients, not " +
                           std::to_string(coefficients.size()));
    }
  };
  if (model == "radtan") {
    need(4);
    return {coefficients[0], coefficients[1], coefficients[2], coefficients[3],
            0.0};
  }
  if (model == "plumb_bob" || model == "rational_polynomial") {
    if (coefficients.size() < 4 || coefficients.size() > 8) need(5);
    for (size_t i = 5; i < coefficients.size(); ++i) {
      if (coefficients[i] != 0.0) {
        throw InputError(path, LineOf(node),
                         "rational distortion terms k4..k6 are not zero; "
                         "rig.yaml holds only [k1, k2, p1, p2, k3]");
      }
    }
    return {coefficients[0], coefficients[1], coefficients[2], coefficients[3],
            coefficients.size() > 4 ? coefficients[4] : 0.0};
  }
  if (model == "equidistant") {
    need(4);
    const EquidistantFit fit = FitRadtanToEquidistant(
        fx, fy, cx, cy, width, height,
        {coefficients[0], coefficients[1], coefficients[2], coefficients[3]});
    if (!(fit.max_error_px <= options.max_fit_error_px)) {
      std::ostringstream problem;
      problem << "the equidistant (fisheye) distortion cannot be written as "
                 "rig.yaml's OpenCV [k1, k2, p1, p2, k3]: the best fit "
                 "departs by "
              << fit.max_error_px << " px in the image (limit "
              << options.max_fit_error_px << " px)";
      throw InputError(path, LineOf(node), problem.str());
    }
    return fit.distortion;
  }
  throw InputError(path, LineOf(node),
                   "unsupported distortion model '" + model +
                       "' (radtan, plumb_bob, equidistant)");
}

Eigen::Isometry3d IsometryOf(const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

// One camera of a ROS camera_info file, and its rectification and
// projection.
struct RosCamera {
  Camera camera;
  Eigen::Matrix3d R_rect_cam;
  Eigen::Matrix<double, 3, 4> P;
  YAML::Node projection_node;
  int size_line = 0;  // of image_width
};

RosCamera ReadRosCamera(const std::string& path, const std::string& name,
                        const CalibrationImportOptions& options) {
  const YAML::Node root = ReadYamlMapping(path, "ROS camera_info file");
  if (!root["image_width"] && !root["camera_matrix"]) {
    throw InputError(path, 1,
                     "not a ROS camera_info file: no image_width or "
                     "camera_matrix");
  }
  const int width = RequiredInt(root, "image_width", path);
  const int height = RequiredInt(root, "image_height", path);
  auto data = [&](const std::string& key, size_t size) {
    const YAML::Node node = root[key];
    if (!node || !node.IsMap()) {
      throw InputError(path, LineOf(root),
                       "missing '" + key + "' with rows, cols and data");
    }
    return size == 0 ? Numbers(node["data"], key + ".data", path)
                     : Required(node, "data", size, path);
  };
  const std::vector<double> k = data("camera_matrix", 9);
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0 ||
      !(k[0] > 0.0) || !(k[4] > 0.0)) {
    throw InputError(path, LineOf(root["camera_matrix"]),
                     "camera_matrix must be [fx 0 cx; 0 fy cy; 0 0 1] with "
                     "fx, fy > 0");
  }
  const std::string model = RequiredString(root, "distortion_model", path);
  const std::array<double, 5> distortion = OpenCvDistortion(
      model, data("distortion_coefficients", 0), k[0], k[4], k[2], k[5], width,
      height, options, root["distortion_coefficients"], path);
  RosCamera ros;
  ros.camera = Camera(name, width, height, k[0], k[4], k[2], k[5], distortion);
  ros.R_rect_cam =
      RotationOf(data("rectification_matrix", 9), 3,
                 root["rectification_matrix"], "rectification_matrix", path);
  const std::vector<double> p = data("projection_matrix", 12);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) ros.P(r, c) = p[r * 4 + c];
  }
  if (!(ros.P(0, 0) > 0.0) || !(ros.P(1, 1) > 0.0)) {
    throw InputError(path, LineOf(root["projection_matrix"]),
                     "projection_matrix must have fx', fy' > 0");
  }
  ros.projection_node = root["projection_matrix"];
  ros.size_line = LineOf(root["image_width"]);
  return ros;
}

}  // namespace

std::string CalibrationImportOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_fit_error_px, 0.0);
  return check.problem();
}

EquidistantFit FitRadtanToEquidistant(double fx, double fy, double cx,
                                      double cy, int width, int height,
                                      const std::array<double, 4>& k) {
  auto theta_d = [&k](double theta) {
    const double t2 = theta * theta;
    return theta * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
  };
  // The widest distorted radius in the image: at a corner (pixel edges).
  double r_max = 0.0;
  for (double u : {-0.5, width - 0.5}) {
    for (double v : {-0.5, height - 0.5}) {
      r_max = std::max(r_max, std::hypot((u - cx) / fx, (v - cy) / fy));
    }
  }
  EquidistantFit fit;
  fit.max_error_px = std::numeric_limits<double>::infinity();
  // theta at r_max, by bisection (theta_d must increase up to there).
  double lo = 0.0, hi = DegToRad(89.0);
  if (!(theta_d(hi) > r_max)) return fit;  // wider than a hemisphere
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (theta_d(mid) < r_max ? lo : hi) = mid;
  }
  const double theta_max = hi;
  constexpr int kSamples = 400;
  Eigen::MatrixXd A(kSamples, 3);
  Eigen::VectorXd b(kSamples);
  std::vector<double> thetas;
  for (int i = 0; i < kSamples; ++i) {
    const double theta = theta_max * (i + 1) / kSamples;
    if (i > 0 && !(theta_d(theta) > theta_d(thetas.back()))) return fit;
    thetas.push_back(theta);
    const double t = std::tan(theta);
    A.row(i) << std::pow(t, 3), std::pow(t, 5), std::pow(t, 7);
    b(i) = theta_d(theta) - t;
  }
  const Eigen::Vector3d radial = A.colPivHouseholderQr().solve(b);
  const double residual = (A * radial - b).cwiseAbs().maxCoeff();
  fit.distortion = {radial(0), radial(1), 0.0, 0.0, radial(2)};
  fit.max_error_px = std::max(fx, fy) * residual;
  return fit;
}

Rig ImportKalibrCamchain(const std::string& path,
                         const Eigen::Isometry3d& T_body_cam0,
                         const CalibrationImportOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(error);
  const YAML::Node root = ReadYamlMapping(path, "Kalibr camchain file");
  if (!root["cam0"]) {
    throw InputError(path, 1,
                     "not a Kalibr camchain file: no 'cam0' (a camchain "
                     "names its cameras cam0, cam1, ...)");
  }
  int count = 0;
  while (root["cam" + std::to_string(count)]) ++count;
  Rig rig;
  Eigen::Isometry3d T_body_previous = T_body_cam0;
  for (int n = 0; n < count; ++n) {
    const std::string key = "cam" + std::to_string(n);
    const YAML::Node cam = root[key];
    if (!cam.IsMap()) throw InputError(path, LineOf(cam), key + ": not a map");
    const std::string model = RequiredString(cam, "camera_model", path);
    if (model != "pinhole") {
      throw InputError(path, LineOf(cam["camera_model"]),
                       key + ": camera_model '" + model +
                           "' is not supported (pinhole only)");
    }
    const std::vector<double> intrinsics = Required(cam, "intrinsics", 4, path);
    const std::vector<double> resolution = Required(cam, "resolution", 2, path);
    // Whole pixels, and few enough that the int they become cannot overflow.
    constexpr double kMaxImageSidePx = 100000.0;
    for (double side : resolution) {
      if (!(side >= 1.0 && side <= kMaxImageSidePx) ||
          side != std::floor(side)) {
        throw InputError(path, LineOf(cam["resolution"]),
                         key +
                             ": resolution must be two whole numbers of "
                             "pixels in [1, 100000]");
      }
    }
    if (!(intrinsics[0] > 0.0) || !(intrinsics[1] > 0.0)) {
      throw InputError(path, LineOf(cam["intrinsics"]),
                       key + ": focal lengths must be > 0");
    }
    const int width = static_cast<int>(resolution[0]);
    const int height = static_cast<int>(resolution[1]);
    const std::array<double, 5> distortion = OpenCvDistortion(
        RequiredString(cam, "distortion_model", path),
        Numbers(cam["distortion_coeffs"], "distortion_coeffs", path),
        intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3], width,
        height, options, cam["distortion_coeffs"], path);
    const std::string name = count == 2 ? (n == 0 ? "left" : "right") : key;
    Eigen::Isometry3d T_body_cam = T_body_cam0;
    if (n > 0) {
      const std::vector<double> t = Required(cam, "T_cn_cnm1", 16, path);
      const Eigen::Matrix3d R =
          RotationOf(t, 4, cam["T_cn_cnm1"], key + " T_cn_cnm1", path);
      const Eigen::Vector3d translation(t[3], t[7], t[11]);
      CheckBaseline(translation, cam["T_cn_cnm1"], path);
      if (t[12] != 0.0 || t[13] != 0.0 || t[14] != 0.0 || t[15] != 1.0) {
        throw InputError(path, LineOf(cam["T_cn_cnm1"]),
                         key + ": T_cn_cnm1's last row must be 0 0 0 1");
      }
      T_body_cam = T_body_previous * IsometryOf(R, translation).inverse();
    }
    T_body_previous = T_body_cam;
    if (n % 2 == 1 && (width != rig.cameras.back().camera.width() ||
                       height != rig.cameras.back().camera.height())) {
      throw InputError(
          path, LineOf(cam["resolution"]),
          key + ": resolution " + std::to_string(width) + "x" +
              std::to_string(height) + " differs from cam" +
              std::to_string(n - 1) + "'s " +
              std::to_string(rig.cameras.back().camera.width()) + "x" +
              std::to_string(rig.cameras.back().camera.height()) +
              ": the two cameras of a stereo pair must have the same "
              "image size");
    }
    rig.cameras.push_back(
        {Camera(name, width, height, intrinsics[0], intrinsics[1],
                intrinsics[2], intrinsics[3], distortion),
         T_body_cam});
  }
  // After the cameras, so that an error in cam0 is named first.
  if (count < 2) {
    throw InputError(path, LineOf(root["cam0"]),
                     "the camchain has cam0 only: a stereo rig needs 'cam1' "
                     "too (calibrate both cameras together with "
                     "kalibr_calibrate_cameras)");
  }
  for (int n = 0; n + 1 < count; n += 2) rig.stereo_pairs.push_back({n, n + 1});
  return rig;
}

Rig ImportRosCameraInfoPair(const std::string& left_path,
                            const std::string& right_path,
                            const Eigen::Isometry3d& T_body_left,
                            const CalibrationImportOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(error);
  const RosCamera left = ReadRosCamera(left_path, "left", options);
  const RosCamera right = ReadRosCamera(right_path, "right", options);
  if (left.camera.width() != right.camera.width() ||
      left.camera.height() != right.camera.height()) {
    throw InputError(
        right_path, right.size_line,
        "image_width/image_height " + std::to_string(right.camera.width()) +
            "x" + std::to_string(right.camera.height()) + " differ from " +
            left_path + "'s " + std::to_string(left.camera.width()) + "x" +
            std::to_string(left.camera.height()) +
            ": the two cameras of a stereo pair must have the same image "
            "size");
  }
  // Offsets of the two rectified cameras, from P's fourth column.
  const Eigen::Vector3d b_rect(
      right.P(0, 3) / right.P(0, 0) - left.P(0, 3) / left.P(0, 0),
      right.P(1, 3) / right.P(1, 1) - left.P(1, 3) / left.P(1, 1), 0.0);
  CheckBaseline(b_rect, right.projection_node, right_path);
  if (b_rect.norm() == 0.0) {
    throw InputError(right_path, LineOf(right.projection_node),
                     "projection_matrix has no baseline (Tx = 0): is this "
                     "the right camera's file?");
  }
  const Eigen::Matrix3d R_right_left =
      right.R_rect_cam.transpose() * left.R_rect_cam;
  const Eigen::Vector3d t_right_left = right.R_rect_cam.transpose() * b_rect;
  Rig rig;
  rig.cameras.push_back({left.camera, T_body_left});
  rig.cameras.push_back(
      {right.camera,
       T_body_left * IsometryOf(R_right_left, t_right_left).inverse()});
  rig.stereo_pairs.push_back({0, 1});
  return rig;
}

CalibrationFormat DetectCalibrationFormat(const std::string& path) {
  const std::string text = ReadText(path, "calibration file");
  if (text.rfind("%YAML:1.0", 0) == 0 || text.rfind("%YAML 1.0", 0) == 0 ||
      text.find("<opencv_storage>") != std::string::npos) {
    return CalibrationFormat::kOpenCv;
  }
  YAML::Node root;
  try {
    root = ParseYamlDocument(text, path);
  } catch (const InputError&) {
    root = YAML::Node();
  }
  if (root.IsMap()) {
    if (root["cam0"]) return CalibrationFormat::kKalibr;
    if (root["image_width"] && root["camera_matrix"]) {
      return CalibrationFormat::kRos;
    }
    if (root["cameras"]) return CalibrationFormat::kRig;
  }
  throw InputError(path, 0,
                   "not a calibration file zebrageo reads: an OpenCV "
                   "stereoCalibrate file, a Kalibr camchain, ROS "
                   "camera_info files or a rig.yaml");
}

}  // namespace zebrageo
