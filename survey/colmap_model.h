// A COLMAP text model as data (cameras.txt, images.txt, points3D.txt): what
// geodata/colmap_export.h writes and reads, what the adjust stage exports
// (pipeline/adjust_outputs.h) and the BAL benchmark converts
// (adjustment/bal/bal_problem.h).
#ifndef ZEBRAGEO_SURVEY_COLMAP_MODEL_H_
#define ZEBRAGEO_SURVEY_COLMAP_MODEL_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace zebrageo {

struct ColmapCamera {
  int64_t id = 0;
  std::string model;  // RADIAL, FULL_OPENCV, ...
  int width = 0;
  int height = 0;
  std::vector<double> params;  // in the model's order
};

struct ColmapImage {
  int64_t id = 0;
  // cam_from_world: x_cam = q * X + t.
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int64_t camera_id = 0;
  std::string name;
  // Pixel positions (COLMAP's: pixel centres at +0.5) and the 3D point
  // each observes (-1: none).
  std::vector<std::pair<Eigen::Vector2d, int64_t>> points2d;
};

struct ColmapPoint3D {
  int64_t id = 0;
  Eigen::Vector3d X = Eigen::Vector3d::Zero();
  std::array<int, 3> rgb = {255, 255, 255};
  double error = 0.0;
  // (image id, index in that image's points2d).
  std::vector<std::pair<int64_t, int>> track;
};

struct ColmapModel {
  std::vector<ColmapCamera> cameras;
  std::vector<ColmapImage> images;
  std::vector<ColmapPoint3D> points;
  // More comment lines after each file's standard header (the frame, the
  // producer).
  std::vector<std::string> camera_notes;
  std::vector<std::string> image_notes;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_COLMAP_MODEL_H_
