// A simulated survey in memory: everything `zebrageo simulate` writes (the
// survey's inputs and its truth) before it is written, and before any image
// is rendered. The geometry sweep (bench/geometry_sweep) runs the matcher and
// the adjustment on it directly; SimulateSurvey writes it.
//
// Frames and units as in world.h and motion.h: the survey's ENU frame at
// the options' origin, metres, radians, seconds. Times are rounded as in the
// files (trajectory samples to 1 us, exposures to 0.1 ms), so the in-memory
// survey is the one a reader of the written folder would load.
#ifndef ZEBRAGEO_SIMULATOR_SIMULATED_SURVEY_H_
#define ZEBRAGEO_SIMULATOR_SIMULATED_SURVEY_H_

#include <cstdint>
#include <string>

#include "simulator/motion.h"
#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/survey.h"

namespace zebrageo::sim {

struct SimulatedSurvey {
  SimulationOptions options;
  Geodetic origin;
  LocalFrame frame{Geodetic{}};
  World world;
  VehicleMotion motion;
  Rig rig;
  // One image per camera and exposure, named images/<id>_<camera>.png.
  ExposureTable exposures;
  RoadmarkDatabase database;  // roadmarks.geojson
  RoadmarkDatabase truth;     // truth/roadmarks.geojson
};

// Builds the world, the motion, the rig, the exposures and both road-mark
// files from `options` (deterministic in options.seed). Throws
// std::invalid_argument when options.Check() fails.
SimulatedSurvey MakeSimulatedSurvey(const SimulationOptions& options);

// The Survey (survey/survey.h) a reader of the written folder would load:
// measured trajectory, database road marks, the manifest with the origin.
// `folder` is recorded as the survey's folder (images are not read).
Survey ToSurvey(const SimulatedSurvey& simulated, const std::string& folder);

// The image file of one exposure's camera, relative to the survey folder.
std::string ImageName(int64_t exposure_id, const std::string& camera);

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_SIMULATED_SURVEY_H_
