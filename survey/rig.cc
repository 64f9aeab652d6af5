#include "survey/rig.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/distortion_check.h"
#include "survey/image_io.h"
#include "survey/input_error.h"
#include "survey/text_file.h"
#include "survey/yaml_document.h"

namespace zebrageo {
namespace {

// Tolerance on |R^T R - I| (largest element) for T_body_cam: a rotation
// written with 9+ significant digits passes, a hand-edited one does not.
constexpr double kOrthonormalTolerance = 1e-6;
// An OpenCV baseline longer than this is almost surely in millimetres (the
// unit of the calibration target), not the metres rig.yaml wants.
constexpr double kMaxPlausibleBaselineM = 10.0;

int LineOf(const YAML::Node& node) { return YamlLine(node); }

class RigParser {
 public:
  explicit RigParser(std::string display_name)
      : display_name_(std::move(display_name)) {}

  Rig Parse(const std::string& yaml_text) const {
    const YAML::Node root = ParseYamlDocument(yaml_text, display_name_);
    if (!root.IsMap()) {
      Fail(root, "expected a mapping with 'cameras' and 'stereo_pairs'");
    }
    const YAML::Node cameras = root["cameras"];
    if (!cameras) Fail(root, "missing key 'cameras'");
    if (!cameras.IsSequence() || cameras.size() == 0) {
      Fail(cameras, "'cameras' must be a non-empty list of cameras");
    }
    Rig rig;
    for (const YAML::Node& node : cameras) {
      RigCamera camera = ParseCamera(node);
      if (rig.FindCamera(camera.camera.name()) >= 0) {
        Fail(node["name"],
             "duplicate camera name '" + camera.camera.name() + "'");
      }
      rig.cameras.push_back(std::move(camera));
    }
    const YAML::Node pairs = root["stereo_pairs"];
    if (pairs && !pairs.IsNull()) {
      if (!pairs.IsSequence()) {
        Fail(pairs, "'stereo_pairs' must be a list of [left, right] names");
      }
      for (const YAML::Node& pair : pairs) {
        rig.stereo_pairs.push_back(ParseStereoPair(pair, rig));
      }
    }
    return rig;
  }

 private:
  [[noreturn]] void Fail(const YAML::Node& node,
                         const std::string& problem) const {
    throw InputError(display_name_, LineOf(node), problem);
  }

  // The child `key` of map `parent`, which must be present.
  YAML::Node Require(const YAML::Node& parent, const std::string& key,
                     const std::string& where) const {
    const YAML::Node child = parent[key];
    if (!child || child.IsNull()) {
      Fail(parent, where + ": missing key '" + key + "'");
    }
    return child;
  }

  double Number(const YAML::Node& node, const std::string& what) const {
    double value = 0.0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
      Fail(node, what + " is not a number");
    }
    if (!std::isfinite(value)) Fail(node, what + " is not finite");
    return value;
  }

  int PositiveInt(const YAML::Node& node, const std::string& what) const {
    long long value = 0;
    if (!node.IsScalar() || !YAML::convert<long long>::decode(node, value)) {
      Fail(node, what + " '" + (node.IsScalar() ? node.Scalar() : "") +
                     "' is not an integer");
    }
    if (value <= 0 || value > 1000000) {
      Fail(node, what + " = " + std::to_string(value) + ": must be > 0");
    }
    return static_cast<int>(value);
  }

  std::vector<double> Numbers(const YAML::Node& node, size_t count,
                              const std::string& what) const {
    if (!node.IsSequence() || node.size() != count) {
      // An OpenCV FileStorage matrix (!!opencv-matrix) is a mapping.
      const std::string hint =
          node.IsMap() ? " (an OpenCV matrix? convert the file with "
                         "`zebrageo import-opencv-stereo`)"
                       : "";
      Fail(node, what + " must be a list of exactly " + std::to_string(count) +
                     " numbers" +
                     (node.IsSequence()
                          ? " (it has " + std::to_string(node.size()) + ")"
                          : "") +
                     hint);
    }
    std::vector<double> values;
    for (size_t i = 0; i < count; ++i) {
      values.push_back(Number(node[i], what + "[" + std::to_string(i) + "]"));
    }
    return values;
  }

  RigCamera ParseCamera(const YAML::Node& node) const {
    if (!node.IsMap()) Fail(node, "a camera must be a mapping");
    const YAML::Node name_node = Require(node, "name", "camera");
    if (!name_node.IsScalar() || name_node.Scalar().empty()) {
      Fail(name_node, "camera name must be a non-empty string");
    }
    const std::string name = name_node.Scalar();
    // Names end up in CSV files (exposures.csv, poses.csv).
    if (name.find_first_of(",\"\n\r") != std::string::npos ||
        name.front() == ' ' || name.back() == ' ') {
      Fail(name_node, "camera name '" + name +
                          "' must not contain ',', '\"', line breaks or "
                          "leading/trailing spaces");
    }
    const std::string where = "camera '" + name + "'";
    const int width =
        PositiveInt(Require(node, "width", where), where + " width");
    const int height =
        PositiveInt(Require(node, "height", where), where + " height");
    if (static_cast<int64_t>(width) * height > kMaxImagePixels) {
      Fail(node["width"],
           where + " is " + std::to_string(width) + "x" +
               std::to_string(height) + " pixels, more than the limit of " +
               std::to_string(kMaxImagePixels / 1000000) + " megapixels");
    }

    const YAML::Node k_node = Require(node, "K", where);
    const std::vector<double> k = Numbers(k_node, 9, where + " K");
    // Zero skew and a plain last row: the camera model has no skew term, so
    // silently dropping one would move every pixel.
    if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 ||
        k[8] != 1.0) {
      Fail(k_node, where +
                       " K must be [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew, "
                       "last row 0 0 1)");
    }
    if (!(k[0] > 0.0) || !(k[4] > 0.0)) {
      Fail(k_node, where + " K: fx and fy must be > 0");
    }
    const YAML::Node d_node = Require(node, "D", where);
    const std::vector<double> d = Numbers(d_node, 5, where + " D");

    const YAML::Node t_node = Require(node, "T_body_cam", where);
    const std::vector<double> t = Numbers(t_node, 16, where + " T_body_cam");
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = t[4 * r + c];
    }
    if (m(3, 0) != 0.0 || m(3, 1) != 0.0 || m(3, 2) != 0.0 || m(3, 3) != 1.0) {
      Fail(t_node, where + " T_body_cam: last row must be 0 0 0 1");
    }
    const Eigen::Matrix3d rotation = m.topLeftCorner<3, 3>();
    const double error =
        (rotation.transpose() * rotation - Eigen::Matrix3d::Identity())
            .cwiseAbs()
            .maxCoeff();
    if (error > kOrthonormalTolerance) {
      std::ostringstream problem;
      problem << where
              << " T_body_cam: rotation is not orthonormal (|R^T R - I| = "
              << error << " > " << kOrthonormalTolerance << ")";
      Fail(t_node, problem.str());
    }
    if (rotation.determinant() < 0.0) {
      Fail(t_node, where +
                       " T_body_cam: rotation has determinant -1 (a "
                       "reflection, not a rotation)");
    }
    RigCamera camera;
    camera.camera = Camera(name, width, height, k[0], k[4], k[2], k[5],
                           {d[0], d[1], d[2], d[3], d[4]});
    const std::string distortion = RadialDistortionProblem(camera.camera);
    if (!distortion.empty()) Fail(d_node, where + " D: " + distortion);
    // Stored as written (not re-orthonormalised) so a write/read round trip
    // is exact.
    camera.T_body_cam.matrix() = m;
    return camera;
  }

  std::array<int, 2> ParseStereoPair(const YAML::Node& node,
                                     const Rig& rig) const {
    if (!node.IsSequence() || node.size() != 2) {
      Fail(node,
           "a stereo pair must be a list of two camera names [left, right]");
    }
    std::array<int, 2> pair{};
    for (int i = 0; i < 2; ++i) {
      const YAML::Node name = node[i];
      if (!name.IsScalar()) Fail(name, "stereo pair: expected a camera name");
      pair[i] = rig.FindCamera(name.Scalar());
      if (pair[i] < 0) {
        std::string known;
        for (const RigCamera& camera : rig.cameras) {
          known += (known.empty() ? "" : ", ") + camera.camera.name();
        }
        Fail(name, "stereo pair names unknown camera '" + name.Scalar() +
                       "' (cameras: " + known + ")");
      }
    }
    if (pair[0] == pair[1]) {
      Fail(node, "stereo pair uses camera '" + node[0].Scalar() +
                     "' twice: it needs two different cameras");
    }
    for (const std::array<int, 2>& other : rig.stereo_pairs) {
      if (other == pair) {
        Fail(node, "stereo pair [" + node[0].Scalar() + ", " +
                       node[1].Scalar() + "] is listed twice");
      }
    }
    return pair;
  }

  std::string display_name_;
};

// "[a, b, c]"; `group` > 0 puts two spaces between groups (matrix rows).
std::string NumberList(const double* values, int count, int group = 0) {
  std::string list = "[";
  for (int i = 0; i < count; ++i) {
    if (i > 0) list += (group > 0 && i % group == 0) ? ",  " : ", ";
    list += FormatDouble(values[i]);
  }
  return list + "]";
}

// cv::Mat (any numeric type) as doubles, or an error naming `key`.
std::vector<double> MatValues(const cv::FileStorage& storage,
                              const std::string& key,
                              const std::string& display_name) {
  const cv::FileNode node = storage[key];
  if (node.empty() || node.isNone()) {
    throw InputError(display_name, 0, "missing matrix '" + key + "'");
  }
  cv::Mat mat;
  try {
    node >> mat;
  } catch (const cv::Exception&) {
    throw InputError(display_name, 0, "'" + key + "' is not a matrix");
  }
  if (mat.empty() || mat.channels() != 1) {
    throw InputError(display_name, 0, "'" + key + "' is not a matrix");
  }
  cv::Mat as_double;
  mat.convertTo(as_double, CV_64F);
  std::vector<double> values(as_double.begin<double>(),
                             as_double.end<double>());
  for (double v : values) {
    if (!std::isfinite(v)) {
      throw InputError(display_name, 0, "'" + key + "' has non-finite values");
    }
  }
  return values;
}

int OptionalInt(const cv::FileStorage& storage, const char* key_a,
                const char* key_b) {
  for (const char* key : {key_a, key_b}) {
    const cv::FileNode node = storage[key];
    if (!node.empty() && node.isInt()) return static_cast<int>(node);
    if (!node.empty() && node.isReal()) {
      return static_cast<int>(static_cast<double>(node));
    }
  }
  return 0;
}

Camera CameraFromOpenCv(const std::string& name, int width, int height,
                        const std::vector<double>& k,
                        const std::vector<double>& d, const std::string& k_key,
                        const std::string& d_key,
                        const std::string& display_name) {
  if (k.size() != 9) {
    throw InputError(display_name, 0, "'" + k_key + "' must be 3x3");
  }
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0 ||
      !(k[0] > 0.0) || !(k[4] > 0.0)) {
    throw InputError(display_name, 0,
                     "'" + k_key +
                         "' must be [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0 "
                         "(no skew)");
  }
  // OpenCV writes 4, 5, 8, 12 or 14 coefficients; the extra ones (rational,
  // thin prism, tilt) are not in our model, so they must be zero.
  if (d.size() < 4) {
    throw InputError(display_name, 0,
                     "'" + d_key + "' has " + std::to_string(d.size()) +
                         " coefficients; expected [k1, k2, p1, p2, k3]");
  }
  for (size_t i = 5; i < d.size(); ++i) {
    if (d[i] != 0.0) {
      throw InputError(
          display_name, 0,
          "'" + d_key + "' has " + std::to_string(d.size()) +
              " coefficients with non-zero rational/prism/tilt terms; only "
              "[k1, k2, p1, p2, k3] is supported");
    }
  }
  const std::array<double, 5> distortion = {d[0], d[1], d[2], d[3],
                                            d.size() >= 5 ? d[4] : 0.0};
  Camera camera(name, width, height, k[0], k[4], k[2], k[5], distortion);
  const std::string problem = RadialDistortionProblem(camera);
  if (!problem.empty()) {
    throw InputError(display_name, 0, "'" + d_key + "': " + problem);
  }
  return camera;
}

}  // namespace

int Rig::FindCamera(const std::string& name) const {
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (cameras[i].camera.name() == name) return static_cast<int>(i);
  }
  return -1;
}

Rig ParseRig(const std::string& yaml_text, const std::string& display_name) {
  return RigParser(display_name).Parse(yaml_text);
}

Rig ReadRig(const std::string& path, const std::string& display_name) {
  return ParseRig(ReadTextFile(path, display_name), display_name);
}

void WriteRig(const Rig& rig, const std::string& path) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "# zebrageo rig: T_body_cam maps camera (x right, y down, z forward)\n"
         "# to body (x forward, y right, z down) coordinates, row-major.\n";
  out << "cameras:\n";
  for (const RigCamera& rig_camera : rig.cameras) {
    const Camera& camera = rig_camera.camera;
    const double k[9] = {camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(),
                         camera.cy(), 0.0, 0.0,         1.0};
    const std::array<double, 5> d = camera.distortion();
    double t[16];
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) t[4 * r + c] = rig_camera.T_body_cam(r, c);
    }
    out << "  - name: " << YamlScalar(camera.name()) << "\n"
        << "    width: " << camera.width() << "\n"
        << "    height: " << camera.height() << "\n"
        << "    K: " << NumberList(k, 9, 3) << "\n"
        << "    D: " << NumberList(d.data(), 5) << "\n"
        << "    T_body_cam: " << NumberList(t, 16, 4) << "\n";
  }
  out << "stereo_pairs:" << (rig.stereo_pairs.empty() ? " []" : "") << "\n";
  for (const std::array<int, 2>& pair : rig.stereo_pairs) {
    out << "  - [" << YamlScalar(rig.cameras.at(pair[0]).camera.name()) << ", "
        << YamlScalar(rig.cameras.at(pair[1]).camera.name()) << "]\n";
  }
  file.Commit();
}

namespace {

// A stereoCalibrate file is a few kilobytes; FileStorage reads all of it.
constexpr std::uintmax_t kMaxOpenCvCalibrationBytes = 1 << 20;
constexpr char kNotOpenCv[] =
    "not an OpenCV calibration file (a FileStorage YAML, XML or JSON with "
    "K1, D1, K2, D2, R, T)";

// Refuses what FileStorage should not be handed: a device, a folder, a
// huge file, binary data (a NUL byte in the first 64 KiB).
void CheckOpenCvCalibrationFile(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw InputError(path, 0,
                     "cannot open OpenCV calibration file: it does not exist");
  }
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(path, 0,
                     std::string(kNotOpenCv) +
                         ": a device, pipe or folder, not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > kMaxOpenCvCalibrationBytes) {
    throw InputError(path, 0,
                     std::string(kNotOpenCv) + ": " + std::to_string(size) +
                         " bytes, more than the " +
                         std::to_string(kMaxOpenCvCalibrationBytes) +
                         " of any calibration");
  }
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(&head[0], static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  const size_t nul = head.find('\0');
  if (nul != std::string::npos) {
    throw InputError(path, 0,
                     std::string(kNotOpenCv) +
                         ": binary data (a NUL byte at "
                         "byte " +
                         std::to_string(nul) + ")");
  }
}

// The first line of an OpenCV error ("... error: (-5:Bad argument) Input
// file is invalid in function 'open'"), without the source location.
std::string OpenCvReason(const cv::Exception& e) {
  std::string reason = e.err.empty() ? e.msg : e.err;
  const size_t end = reason.find('\n');
  if (end != std::string::npos) reason.resize(end);
  return reason;
}

}  // namespace

Rig ImportOpenCvStereo(const std::string& path, int width, int height,
                       const Eigen::Isometry3d& T_body_left) {
  CheckOpenCvCalibrationFile(path);
  cv::FileStorage storage;
  try {
    if (!storage.open(path, cv::FileStorage::READ)) {
      throw InputError(path, 0, "cannot open OpenCV calibration file");
    }
  } catch (const cv::Exception& e) {
    throw InputError(path, 0,
                     std::string(kNotOpenCv) + ": OpenCV cannot parse it (" +
                         OpenCvReason(e) + ")");
  }
  const int file_width = OptionalInt(storage, "image_width", "width");
  const int file_height = OptionalInt(storage, "image_height", "height");
  if (file_width > 0) width = file_width;
  if (file_height > 0) height = file_height;
  if (width <= 0 || height <= 0) {
    throw InputError(path, 0,
                     "image size unknown: the file has no image_width/"
                     "image_height (or width/height) and none was given");
  }
  // One matrix at a time, so a file missing several names the first.
  const std::vector<double> k1 = MatValues(storage, "K1", path);
  const std::vector<double> d1 = MatValues(storage, "D1", path);
  const std::vector<double> k2 = MatValues(storage, "K2", path);
  const std::vector<double> d2 = MatValues(storage, "D2", path);
  const Camera left =
      CameraFromOpenCv("left", width, height, k1, d1, "K1", "D1", path);
  const Camera right =
      CameraFromOpenCv("right", width, height, k2, d2, "K2", "D2", path);

  const std::vector<double> r = MatValues(storage, "R", path);
  const std::vector<double> t = MatValues(storage, "T", path);
  Eigen::Matrix3d R_right_left;
  if (r.size() == 9) {
    R_right_left =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
            r.data());
  } else if (r.size() == 3) {
    // A Rodrigues vector, as cv::stereoCalibrate's callers sometimes save.
    const Eigen::Vector3d rvec(r[0], r[1], r[2]);
    const double angle = rvec.norm();
    R_right_left =
        angle > 0.0 ? Eigen::AngleAxisd(angle, rvec / angle).toRotationMatrix()
                    : Eigen::Matrix3d::Identity();
  } else {
    throw InputError(path, 0, "'R' must be 3x3 (or a 3-vector)");
  }
  const double error =
      (R_right_left.transpose() * R_right_left - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  if (error > kOrthonormalTolerance || R_right_left.determinant() < 0.0) {
    throw InputError(path, 0, "'R' is not a rotation matrix");
  }
  if (t.size() != 3) throw InputError(path, 0, "'T' must have 3 values");
  const Eigen::Vector3d t_right_left(t[0], t[1], t[2]);
  if (t_right_left.norm() > kMaxPlausibleBaselineM) {
    std::ostringstream problem;
    problem << "baseline |T| = " << t_right_left.norm()
            << " is implausible in metres (millimetres?); rig.yaml needs T "
               "in metres";
    throw InputError(path, 0, problem.str());
  }

  // p_right = R p_left + T, i.e. T_right_left; the right camera sits at
  // T_body_right = T_body_left * T_left_right.
  Eigen::Isometry3d T_right_left = Eigen::Isometry3d::Identity();
  T_right_left.linear() = R_right_left;
  T_right_left.translation() = t_right_left;

  Rig rig;
  rig.cameras.push_back({left, T_body_left});
  rig.cameras.push_back({right, T_body_left * T_right_left.inverse()});
  rig.stereo_pairs.push_back({0, 1});
  return rig;
}

}  // namespace zebrageo
