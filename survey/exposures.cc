#include "survey/exposures.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"

namespace zebrageo {
namespace {

const std::vector<std::string>& Columns() {
  static const std::vector<std::string>* const kColumns =
      new std::vector<std::string>{"exposure_id", "time", "camera", "image"};
  return *kColumns;
}

std::string CameraNames(const Rig& rig) {
  std::string names;
  for (const RigCamera& camera : rig.cameras) {
    names += (names.empty() ? "" : ", ") + camera.camera.name();
  }
  return names;
}

// True when two image paths (relative to the survey folder) name one file.
bool SameImagePath(const std::string& a, const std::string& b) {
  return std::filesystem::path(a).lexically_normal() ==
         std::filesystem::path(b).lexically_normal();
}

ExposureTable BuildTable(const CsvTable& csv, const Rig& rig) {
  if (csv.NumRows() == 0) {
    throw InputError(csv.display_name(), 0, "no exposures (no data rows)");
  }
  ExposureTable table;
  // exposure_id -> index into table.exposures.
  std::map<int64_t, int> exposure_of_id;
  for (int row = 0; row < csv.NumRows(); ++row) {
    ExposureImage image;
    image.exposure_id = csv.GetInt(row, "exposure_id");
    image.time = csv.GetDouble(row, "time");
    const std::string& camera = csv.GetString(row, "camera");
    image.camera = rig.FindCamera(camera);
    if (image.camera < 0) {
      csv.Fail(row, "camera '" + camera + "' is not in the rig (cameras: " +
                        CameraNames(rig) + ")");
    }
    image.image = csv.GetString(row, "image");
    if (image.image.empty()) csv.Fail(row, "empty image path");
    image.line = csv.LineOf(row);

    const int image_index = static_cast<int>(table.images.size());
    auto [it, inserted] = exposure_of_id.emplace(
        image.exposure_id, static_cast<int>(table.exposures.size()));
    if (inserted) {
      Exposure exposure;
      exposure.exposure_id = image.exposure_id;
      exposure.time = image.time;
      exposure.image_of_camera.assign(rig.cameras.size(), -1);
      table.exposures.push_back(std::move(exposure));
    }
    Exposure& exposure = table.exposures[it->second];
    // The images of one exposure are one instant: a different time is a
    // broken file, not jitter we could average away.
    if (image.time != exposure.time) {
      const ExposureImage& first = table.images[*std::max_element(
          exposure.image_of_camera.begin(), exposure.image_of_camera.end())];
      csv.Fail(row, "exposure " + std::to_string(image.exposure_id) +
                        " has time " + FormatDouble(image.time) + " here but " +
                        FormatDouble(exposure.time) + " on line " +
                        std::to_string(first.line));
    }
    int& slot = exposure.image_of_camera[image.camera];
    if (slot >= 0) {
      csv.Fail(row, "exposure " + std::to_string(image.exposure_id) +
                        " has two images of camera '" + camera +
                        "' (the other on line " +
                        std::to_string(table.images[slot].line) + ")");
    }
    // Two cameras of one instant naming one file see the street from one
    // place: no disparity anywhere, so no band can be reconstructed.
    for (int other : exposure.image_of_camera) {
      if (other >= 0 && SameImagePath(table.images[other].image, image.image)) {
        csv.Fail(row,
                 "exposure " + std::to_string(image.exposure_id) +
                     ": camera '" + camera + "' names image " + image.image +
                     ", the image camera '" +
                     rig.cameras.at(table.images[other].camera).camera.name() +
                     "' names on line " +
                     std::to_string(table.images[other].line) +
                     ": the two cameras of a stereo pair would see identical "
                     "images (zero disparity everywhere, no depth); name each "
                     "camera's own image");
      }
    }
    slot = image_index;
    table.images.push_back(std::move(image));
  }
  std::stable_sort(table.exposures.begin(), table.exposures.end(),
                   [](const Exposure& a, const Exposure& b) {
                     if (a.time != b.time) return a.time < b.time;
                     return a.exposure_id < b.exposure_id;
                   });
  return table;
}

}  // namespace

ExposureTable ReadExposures(const std::string& path,
                            const std::string& display_name, const Rig& rig) {
  return BuildTable(CsvTable::Read(path, display_name, Columns()), rig);
}

ExposureTable ParseExposures(const std::string& text,
                             const std::string& display_name, const Rig& rig) {
  return BuildTable(CsvTable::Parse(text, display_name, Columns()), rig);
}

void WriteExposures(const ExposureTable& table, const Rig& rig,
                    const std::string& path) {
  AtomicFile file(path);
  CsvWriter csv(&file.stream());
  csv.Header(Columns());
  for (const ExposureImage& image : table.images) {
    csv.Add(image.exposure_id)
        .Add(image.time)
        .Add(rig.cameras.at(image.camera).camera.name())
        .Add(image.image);
    csv.EndRow();
  }
  file.Commit();
}

}  // namespace zebrageo
