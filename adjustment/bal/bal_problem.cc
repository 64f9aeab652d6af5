#include "adjustment/bal/bal_problem.h"

#include <bzlib.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// Reads a whole file, decompressing bzip2 when it starts with "BZh".
std::string ReadMaybeCompressed(const std::string& path) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"),
                                             &std::fclose);
  if (!file) {
    throw InputError(path, 0,
                     std::string("cannot open: ") + std::strerror(errno));
  }
  char magic[3] = {0, 0, 0};
  const size_t got = std::fread(magic, 1, 3, file.get());
  std::rewind(file.get());
  std::string text;
  if (got == 3 && magic[0] == 'B' && magic[1] == 'Z' && magic[2] == 'h') {
    int status = BZ_OK;
    BZFILE* bz = BZ2_bzReadOpen(&status, file.get(), 0, 0, nullptr, 0);
    if (status != BZ_OK) {
      BZ2_bzReadClose(&status, bz);
      throw InputError(path, 0, "not a readable bzip2 stream");
    }
    char buffer[1 << 16];
    while (status == BZ_OK) {
      const int n = BZ2_bzRead(&status, bz, buffer, sizeof(buffer));
      if (status != BZ_OK && status != BZ_STREAM_END) break;
      text.append(buffer, n);
    }
    const int read_status = status;
    BZ2_bzReadClose(&status, bz);
    if (read_status != BZ_STREAM_END) {
      throw InputError(path, 0,
                       "corrupt or truncated bzip2 data (libbz2 status " +
                           std::to_string(read_status) + ")");
    }
    return text;
  }
  char buffer[1 << 16];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) {
    text.append(buffer, n);
  }
  if (std::ferror(file.get())) throw InputError(path, 0, "read error");
  return text;
}

// Whitespace-token reader over a text buffer that knows the line it is on.
class TokenReader {
 public:
  TokenReader(const std::string& text, std::string display_name)
      : text_(text), display_name_(std::move(display_name)) {}

  double NextDouble(const char* what) {
    SkipSpace();
    if (pos_ >= text_.size()) Fail(std::string("file ends before ") + what);
    const char* begin = text_.c_str() + pos_;
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin) {
      Fail(std::string("expected a number for ") + what + ", found \"" +
           Token() + "\"");
    }
    if (!std::isfinite(value)) Fail(std::string(what) + " is not finite");
    pos_ += end - begin;
    return value;
  }

  int64_t NextInt(const char* what) {
    SkipSpace();
    if (pos_ >= text_.size()) Fail(std::string("file ends before ") + what);
    const char* begin = text_.c_str() + pos_;
    char* end = nullptr;
    errno = 0;
    const long long value = std::strtoll(begin, &end, 10);
    if (end == begin || errno != 0 ||
        (*end != '\0' && !std::isspace(static_cast<unsigned char>(*end)))) {
      Fail(std::string("expected an integer for ") + what + ", found \"" +
           Token() + "\"");
    }
    pos_ += end - begin;
    return value;
  }

  [[noreturn]] void Fail(const std::string& problem) const {
    throw InputError(display_name_, line_, problem);
  }

 private:
  void SkipSpace() {
    while (pos_ < text_.size() &&
           std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string Token() const {
    size_t end = pos_;
    while (end < text_.size() && end - pos_ < 32 &&
           !std::isspace(static_cast<unsigned char>(text_[end]))) {
      ++end;
    }
    return text_.substr(pos_, end - pos_);
  }

  const std::string& text_;
  std::string display_name_;
  size_t pos_ = 0;
  int line_ = 1;
};

// Camera-frame point P = R(w) X + t of a BAL camera.
Eigen::Vector3d BalCameraPoint(const std::array<double, kBalCameraSize>& camera,
                               const Eigen::Vector3d& point) {
  Eigen::Vector3d p;
  ceres::AngleAxisRotatePoint(camera.data(), point.data(), p.data());
  return p + Eigen::Vector3d(camera[3], camera[4], camera[5]);
}

// COLMAP's +z-looking camera differs from BAL's -z-looking one by a rotation
// of pi about x: P_colmap = F P_bal.
const Eigen::Matrix3d& FlipYZ() {
  static const Eigen::Matrix3d kFlip =
      Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  return kFlip;
}

// Principal point used in the COLMAP export: an integer half-size just
// larger than every observation, so all image coordinates are positive.
Eigen::Vector2d ExportPrincipalPoint(const BalProblem& problem, int camera) {
  double max_abs = 1.0;
  for (const BalObservation& o : problem.observations) {
    if (o.camera == camera)
      max_abs = std::max(max_abs, o.xy.cwiseAbs().maxCoeff());
  }
  const double half = std::ceil(max_abs) + 1.0;
  return Eigen::Vector2d(half, half);
}

}  // namespace

BalProblem ParseBalProblem(const std::string& text,
                           const std::string& display_name) {
  TokenReader reader(text, display_name);
  const int64_t num_cameras = reader.NextInt("the number of cameras");
  const int64_t num_points = reader.NextInt("the number of points");
  const int64_t num_observations = reader.NextInt("the number of observations");
  constexpr int64_t kMaxCount = 100'000'000;
  if (num_cameras <= 0 || num_points <= 0 || num_observations <= 0 ||
      num_cameras > kMaxCount || num_points > kMaxCount ||
      num_observations > kMaxCount) {
    reader.Fail("header counts must be positive (and below 1e8): " +
                std::to_string(num_cameras) + " " + std::to_string(num_points) +
                " " + std::to_string(num_observations));
  }
  BalProblem problem;
  problem.observations.resize(num_observations);
  for (BalObservation& o : problem.observations) {
    const int64_t camera = reader.NextInt("an observation's camera index");
    const int64_t point = reader.NextInt("an observation's point index");
    if (camera < 0 || camera >= num_cameras) {
      reader.Fail("camera index " + std::to_string(camera) +
                  " is outside [0, " + std::to_string(num_cameras) + ")");
    }
    if (point < 0 || point >= num_points) {
      reader.Fail("point index " + std::to_string(point) + " is outside [0, " +
                  std::to_string(num_points) + ")");
    }
    o.camera = static_cast<int>(camera);
    o.point = static_cast<int>(point);
    o.xy.x() = reader.NextDouble("an observation's x");
    o.xy.y() = reader.NextDouble("an observation's y");
  }
  problem.cameras.resize(num_cameras);
  for (auto& camera : problem.cameras) {
    for (double& value : camera)
      value = reader.NextDouble("a camera parameter");
  }
  problem.points.resize(num_points);
  for (Eigen::Vector3d& point : problem.points) {
    for (int i = 0; i < 3; ++i)
      point[i] = reader.NextDouble("a point coordinate");
  }
  return problem;
}

BalProblem ReadBalProblem(const std::string& path) {
  return ParseBalProblem(ReadMaybeCompressed(path),
                         fs::path(path).filename().string());
}

double BalDepth(const BalProblem& problem, const BalObservation& observation) {
  return -BalCameraPoint(problem.cameras[observation.camera],
                         problem.points[observation.point])
              .z();
}

bool BalResidual(const BalProblem& problem, const BalObservation& observation,
                 Eigen::Vector2d* residual) {
  const auto& camera = problem.cameras[observation.camera];
  const Eigen::Vector3d P =
      BalCameraPoint(camera, problem.points[observation.point]);
  if (P.z() == 0.0) return false;
  const Eigen::Vector2d p = -P.head<2>() / P.z();
  const double r2 = p.squaredNorm();
  const double distortion = 1.0 + r2 * (camera[7] + camera[8] * r2);
  *residual = camera[6] * distortion * p - observation.xy;
  return true;
}

double BalCost(const BalProblem& problem) {
  double cost = 0.0;
  for (const BalObservation& o : problem.observations) {
    Eigen::Vector2d r;
    if (!BalResidual(problem, o, &r)) return HUGE_VAL;
    cost += 0.5 * r.squaredNorm();
  }
  return cost;
}

BalProblem ReduceLikeColmap(const BalProblem& problem, int min_track_length,
                            BalReduction* reduction) {
  BalReduction counts;
  std::vector<char> keep(problem.observations.size(), 1);
  std::vector<int> track_length(problem.points.size(), 0);
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (!(BalDepth(problem, problem.observations[i]) > 0.0)) {
      keep[i] = 0;
      ++counts.dropped_behind;
    } else {
      ++track_length[problem.observations[i].point];
    }
  }
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (keep[i] &&
        track_length[problem.observations[i].point] < min_track_length) {
      keep[i] = 0;
      ++counts.dropped_short_track;
    }
  }
  std::vector<int> new_point(problem.points.size(), -1);
  std::vector<int> new_camera(problem.cameras.size(), -1);
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (!keep[i]) continue;
    new_point[problem.observations[i].point] = 0;
    new_camera[problem.observations[i].camera] = 0;
  }
  BalProblem reduced;
  for (size_t i = 0; i < problem.points.size(); ++i) {
    if (new_point[i] < 0) {
      ++counts.dropped_points;
      continue;
    }
    new_point[i] = reduced.num_points();
    reduced.points.push_back(problem.points[i]);
  }
  for (size_t i = 0; i < problem.cameras.size(); ++i) {
    if (new_camera[i] < 0) {
      ++counts.dropped_cameras;
      continue;
    }
    new_camera[i] = reduced.num_cameras();
    reduced.cameras.push_back(problem.cameras[i]);
  }
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (!keep[i]) continue;
    BalObservation o = problem.observations[i];
    o.camera = new_camera[o.camera];
    o.point = new_point[o.point];
    reduced.observations.push_back(o);
  }
  if (reduction != nullptr) *reduction = counts;
  return reduced;
}

ColmapModel ColmapModelOf(const BalProblem& problem) {
  ColmapModel model;
  model.camera_notes = {
      "Converted from a BAL problem by zebrageo (RADIAL: f, cx, cy, k1, k2)"};
  // Index of each observation within its image's POINTS2D list.
  std::vector<std::vector<int>> image_observations(problem.cameras.size());
  std::vector<int> index_in_image(problem.observations.size());
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    auto& list = image_observations[problem.observations[i].camera];
    index_in_image[i] = static_cast<int>(list.size());
    list.push_back(static_cast<int>(i));
  }
  for (int c = 0; c < problem.num_cameras(); ++c) {
    const auto& camera = problem.cameras[c];
    const Eigen::Vector2d principal = ExportPrincipalPoint(problem, c);
    model.cameras.push_back(
        {c + 1,
         "RADIAL",
         static_cast<int>(2 * principal.x()),
         static_cast<int>(2 * principal.y()),
         {camera[6], principal.x(), principal.y(), camera[7], camera[8]}});
    Eigen::Matrix3d R_bal;
    ceres::AngleAxisToRotationMatrix(
        camera.data(), ceres::ColumnMajorAdapter3x3(R_bal.data()));
    ColmapImage image;
    image.id = c + 1;
    image.q = Eigen::Quaterniond(FlipYZ() * R_bal);
    image.t = FlipYZ() * Eigen::Vector3d(camera[3], camera[4], camera[5]);
    image.camera_id = c + 1;
    image.name = "camera" + std::to_string(c) + ".jpg";
    for (int i : image_observations[c]) {
      const BalObservation& o = problem.observations[i];
      image.points2d.emplace_back(
          Eigen::Vector2d(o.xy.x() + principal.x(), -o.xy.y() + principal.y()),
          o.point + 1);
    }
    model.images.push_back(std::move(image));
  }
  std::vector<std::vector<int>> point_observations(problem.points.size());
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    point_observations[problem.observations[i].point].push_back(
        static_cast<int>(i));
  }
  for (int p = 0; p < problem.num_points(); ++p) {
    ColmapPoint3D point;
    point.id = p + 1;
    point.X = problem.points[p];
    point.rgb = {128, 128, 128};
    for (int i : point_observations[p]) {
      point.track.emplace_back(problem.observations[i].camera + 1,
                               index_in_image[i]);
    }
    model.points.push_back(std::move(point));
  }
  return model;
}

BalProblem BalProblemOf(const ColmapModel& model) {
  BalProblem problem;
  std::map<int64_t, int> camera_index;  // COLMAP camera id -> BAL camera
  std::map<int64_t, Eigen::Vector2d> principal;
  for (const ColmapCamera& camera : model.cameras) {
    if (camera.model != "RADIAL" || camera.params.size() != 5) {
      throw InputError("cameras.txt", 0,
                       "camera " + std::to_string(camera.id) + ": model " +
                           camera.model + " is not RADIAL (f cx cy k1 k2)");
    }
    camera_index[camera.id] = static_cast<int>(problem.cameras.size());
    principal[camera.id] = Eigen::Vector2d(camera.params[1], camera.params[2]);
    problem.cameras.push_back({0, 0, 0, 0, 0, 0, camera.params[0],
                               camera.params[3], camera.params[4]});
  }
  std::map<int64_t, int> point_index;
  for (const ColmapPoint3D& point : model.points) {
    point_index[point.id] = static_cast<int>(problem.points.size());
    problem.points.push_back(point.X);
  }
  for (const ColmapImage& image : model.images) {
    const int camera = camera_index.at(image.camera_id);
    auto& params = problem.cameras[camera];
    const Eigen::Matrix3d R_bal =
        FlipYZ() * image.q.normalized().toRotationMatrix();
    ceres::RotationMatrixToAngleAxis(ceres::ColumnMajorAdapter3x3(R_bal.data()),
                                     params.data());
    const Eigen::Vector3d t_bal = FlipYZ() * image.t;
    params[3] = t_bal.x();
    params[4] = t_bal.y();
    params[5] = t_bal.z();
    const Eigen::Vector2d& c = principal[image.camera_id];
    for (const auto& [xy, point_id] : image.points2d) {
      if (point_id < 0) continue;
      BalObservation o;
      o.camera = camera;
      o.point = point_index.at(point_id);
      o.xy = Eigen::Vector2d(xy.x() - c.x(), -(xy.y() - c.y()));
      problem.observations.push_back(o);
    }
  }
  return problem;
}

}  // namespace zebrageo
