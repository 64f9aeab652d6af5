#include "geodata/colmap_export.h"

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

// The lines of `path` that are neither empty nor comments, with their
// numbers.
std::vector<std::pair<int, std::string>> DataLines(const std::string& path,
                                                   const std::string& name) {
  std::ifstream in(path);
  if (!in) throw InputError(name, 0, "cannot open " + path);
  std::vector<std::pair<int, std::string>> lines;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

void ReadCameras(const std::string& folder, ColmapModel* model) {
  for (const auto& [number, line] :
       DataLines(folder + "/cameras.txt", "cameras.txt")) {
    std::istringstream in(line);
    ColmapCamera camera;
    if (!(in >> camera.id >> camera.model >> camera.width >> camera.height)) {
      throw InputError("cameras.txt", number,
                       "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
    }
    for (double value; in >> value;) camera.params.push_back(value);
    model->cameras.push_back(camera);
  }
}

void ReadPoints(const std::string& folder, ColmapModel* model) {
  for (const auto& [number, line] :
       DataLines(folder + "/points3D.txt", "points3D.txt")) {
    std::istringstream in(line);
    ColmapPoint3D point;
    if (!(in >> point.id >> point.X.x() >> point.X.y() >> point.X.z())) {
      throw InputError("points3D.txt", number, "expected ID X Y Z");
    }
    if (in >> point.rgb[0] >> point.rgb[1] >> point.rgb[2] >> point.error) {
      int64_t image = 0;
      int index = 0;
      while (in >> image >> index) point.track.emplace_back(image, index);
    }
    model->points.push_back(point);
  }
}

// Images have two lines, but COLMAP writes an empty POINTS2D line for an
// image without points, which DataLines skips: a points line is one of
// numbers only, in threes (a pose line ends with a name).
bool ReadPointsLine(const std::string& line, ColmapImage* image) {
  std::istringstream in(line);
  std::vector<double> values;
  for (double value; in >> value;) values.push_back(value);
  if (!in.eof() || values.empty() || values.size() % 3 != 0) return false;
  for (size_t k = 0; k < values.size(); k += 3) {
    image->points2d.emplace_back(Eigen::Vector2d(values[k], values[k + 1]),
                                 static_cast<int64_t>(values[k + 2]));
  }
  return true;
}

void ReadImages(const std::string& folder, ColmapModel* model) {
  std::map<int64_t, bool> cameras, points;
  for (const ColmapCamera& c : model->cameras) cameras[c.id] = true;
  for (const ColmapPoint3D& p : model->points) points[p.id] = true;
  const auto lines = DataLines(folder + "/images.txt", "images.txt");
  for (size_t i = 0; i < lines.size(); ++i) {
    std::istringstream in(lines[i].second);
    ColmapImage image;
    double qw, qx, qy, qz;
    if (!(in >> image.id >> qw >> qx >> qy >> qz >> image.t.x() >>
          image.t.y() >> image.t.z() >> image.camera_id >> image.name)) {
      throw InputError("images.txt", lines[i].first,
                       "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    }
    image.q = Eigen::Quaterniond(qw, qx, qy, qz);
    if (!cameras.count(image.camera_id)) {
      throw InputError("images.txt", lines[i].first,
                       "unknown camera " + std::to_string(image.camera_id));
    }
    if (i + 1 < lines.size() && ReadPointsLine(lines[i + 1].second, &image)) {
      ++i;
      for (const auto& [xy, point] : image.points2d) {
        if (point >= 0 && !points.count(point)) {
          throw InputError("images.txt", lines[i].first,
                           "unknown 3D point " + std::to_string(point));
        }
      }
    }
    model->images.push_back(image);
  }
}

}  // namespace

void WriteColmapModel(const ColmapModel& model, const std::string& folder) {
  std::filesystem::create_directories(folder);
  WriteFileAtomically(folder + "/cameras.txt", [&](std::ostream& out) {
    out << "# Camera list with one line of data per camera:\n"
           "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
    for (const std::string& note : model.camera_notes) {
      out << "# " << note << "\n";
    }
    for (const ColmapCamera& c : model.cameras) {
      out << c.id << " " << c.model << " " << c.width << " " << c.height;
      for (double p : c.params) out << " " << FormatDouble(p);
      out << "\n";
    }
  });
  WriteFileAtomically(folder + "/images.txt", [&](std::ostream& out) {
    out << "# Image list with two lines of data per image:\n"
           "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
           "#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
    for (const std::string& note : model.image_notes) {
      out << "# " << note << "\n";
    }
    for (const ColmapImage& image : model.images) {
      out << image.id << " " << FormatDouble(image.q.w()) << " "
          << FormatDouble(image.q.x()) << " " << FormatDouble(image.q.y())
          << " " << FormatDouble(image.q.z()) << " "
          << FormatDouble(image.t.x()) << " " << FormatDouble(image.t.y())
          << " " << FormatDouble(image.t.z()) << " " << image.camera_id << " "
          << image.name << "\n";
      bool first = true;
      for (const auto& [xy, point] : image.points2d) {
        out << (first ? "" : " ") << FormatDouble(xy.x()) << " "
            << FormatDouble(xy.y()) << " " << point;
        first = false;
      }
      out << "\n";
    }
  });
  WriteFileAtomically(folder + "/points3D.txt", [&](std::ostream& out) {
    out << "# 3D point list with one line of data per point:\n"
           "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, "
           "POINT2D_IDX)\n";
    for (const ColmapPoint3D& p : model.points) {
      out << p.id << " " << FormatDouble(p.X.x()) << " "
          << FormatDouble(p.X.y()) << " " << FormatDouble(p.X.z()) << " "
          << p.rgb[0] << " " << p.rgb[1] << " " << p.rgb[2] << " "
          << FormatDouble(p.error);
      for (const auto& [image, index] : p.track) {
        out << " " << image << " " << index;
      }
      out << "\n";
    }
  });
}

ColmapModel ReadColmapModel(const std::string& folder) {
  ColmapModel model;
  ReadCameras(folder, &model);
  ReadPoints(folder, &model);
  ReadImages(folder, &model);
  return model;
}

}  // namespace zebrageo
