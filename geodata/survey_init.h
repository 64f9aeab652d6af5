// zebrageo init: a survey folder (SURVEY_FORMAT.md) from a mapping
// engineer's own files: a folder of images, a trajectory, a calibration and
// a road-mark source. The conversions are the imports' (the caller reads the
// trajectory and the calibration); this file lays out the folder: images
// and a road-mark file outside the survey are hard-linked into it (copied
// across file systems), since every file a survey names must lie inside
// it; rig.yaml, trajectory.csv, exposures.csv and survey.yaml are written;
// then the caller's check runs. Any failure, the check's included, removes
// everything init wrote and the folder if init created it.
#ifndef ZEBRAGEO_GEODATA_SURVEY_INIT_H_
#define ZEBRAGEO_GEODATA_SURVEY_INIT_H_

#include <functional>
#include <string>
#include <vector>

#include "geodata/exposure_times.h"
#include "survey/rig.h"
#include "survey/survey.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct SurveyInitInputs {
  std::string survey_folder;
  std::string images_folder;
  Rig rig;
  std::vector<TrajectorySample> trajectory;  // on GPS seconds of week
  // A vector file or a "PG:..." connection string.
  std::string roadmarks;
  // Optional survey.yaml keys: roadmarks_layer, roadmarks_crs, output_crs.
  SurveyManifest manifest;
  ExposureTimeOptions times;
  PairingOptions pairing;
};

struct SurveyInitSummary {
  ExposureListing listing;
  int images_linked = 0;      // hard links (or copies) made into the survey
  int images_copied = 0;      // of them, copies (another file system)
  std::string images_prefix;  // of exposures.csv's paths
};

// The survey files init writes; an existing one is not overwritten (the
// caller refuses).
std::vector<std::string> SurveyInitFiles();

// Writes the survey, then calls `check(survey_folder)`. Throws what fails
// (InputError for an input, std::runtime_error for the file system) after
// removing what it wrote.
SurveyInitSummary InitSurvey(
    const SurveyInitInputs& inputs,
    const std::function<void(const std::string&)>& check);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_SURVEY_INIT_H_
