// exposures.csv: which image was taken when, by which camera.
#ifndef ZEBRAGEO_SURVEY_EXPOSURES_H_
#define ZEBRAGEO_SURVEY_EXPOSURES_H_

#include <cstdint>
#include <string>
#include <vector>

#include "survey/rig.h"

namespace zebrageo {

struct ExposureImage {
  int64_t exposure_id = 0;  // a label: neither 0-based nor contiguous
  double time = 0.0;
  int camera = -1;    // index into Rig::cameras
  std::string image;  // relative to the survey folder
  int line = 0;       // line in exposures.csv, for messages
};

// All images of one exposure (one instant), one per camera at most.
struct Exposure {
  int64_t exposure_id = 0;
  double time = 0.0;
  // image_of_camera[c] = index into the images vector, or -1.
  std::vector<int> image_of_camera;
};

struct ExposureTable {
  std::vector<ExposureImage> images;  // file order
  std::vector<Exposure> exposures;    // sorted by time, then id
};

// Reads exposures.csv (columns exposure_id,time,camera,image). Throws
// InputError: unreadable, missing columns, non-integer id, NaN/inf time,
// empty image path, camera not in `rig`, two images of one exposure_id with
// different times, two images of the same camera in one exposure, no rows.
ExposureTable ReadExposures(const std::string& path,
                            const std::string& display_name, const Rig& rig);
ExposureTable ParseExposures(const std::string& text,
                             const std::string& display_name, const Rig& rig);
void WriteExposures(const ExposureTable& table, const Rig& rig,
                    const std::string& path);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_EXPOSURES_H_
