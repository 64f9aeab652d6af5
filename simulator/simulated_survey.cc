#include "simulator/simulated_survey.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace zebrageo::sim {
namespace {

double RoundTo(double value, double step) {
  return std::round(value / step) * step;
}

// Exposures: one image per camera, all with the exposure's id and time.
ExposureTable MakeExposureTable(const VehicleMotion& motion, const Rig& rig) {
  ExposureTable table;
  for (const ExposureEvent& e : motion.exposures) {
    Exposure exposure;
    exposure.exposure_id = e.exposure_id;
    exposure.time = e.time;
    for (int c = 0; c < static_cast<int>(rig.cameras.size()); ++c) {
      ExposureImage image;
      image.exposure_id = e.exposure_id;
      image.time = e.time;
      image.camera = c;
      image.image = ImageName(e.exposure_id, rig.cameras[c].camera.name());
      exposure.image_of_camera.push_back(static_cast<int>(table.images.size()));
      table.images.push_back(image);
    }
    table.exposures.push_back(exposure);
  }
  return table;
}

}  // namespace

std::string ImageName(int64_t exposure_id, const std::string& camera) {
  char text[64];
  std::snprintf(text, sizeof(text), "images/%06lld_%s.png",
                static_cast<long long>(exposure_id), camera.c_str());
  return text;
}

SimulatedSurvey MakeSimulatedSurvey(const SimulationOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(error);
  SimulatedSurvey out;
  out.options = options;
  out.origin = Geodetic{options.origin_lat_deg, options.origin_lon_deg,
                        options.origin_h_m};
  out.frame = LocalFrame(out.origin);
  out.world = BuildWorld(options);
  out.motion = SimulateMotion(options, out.world, out.frame);
  // Times on a clean decimal grid (1 us), so the files read naturally.
  for (auto* samples : {&out.motion.truth, &out.motion.measured}) {
    for (TrajectorySample& s : *samples) s.time = RoundTo(s.time, 1e-6);
  }
  for (ExposureEvent& e : out.motion.exposures) e.time = RoundTo(e.time, 1e-4);
  out.rig = MakeRig(options);
  out.exposures = MakeExposureTable(out.motion, out.rig);
  out.database = MakeDatabaseRoadmarks(out.world, options, out.frame);
  out.truth = MakeTruthRoadmarks(out.world, out.frame);
  return out;
}

Survey ToSurvey(const SimulatedSurvey& simulated, const std::string& folder) {
  Survey survey;
  survey.folder = folder;
  survey.manifest.name = "zebrageo-sim-" + simulated.options.preset + "-seed" +
                         std::to_string(simulated.options.seed);
  survey.manifest.origin = simulated.origin;
  survey.rig = simulated.rig;
  survey.frame = simulated.frame;
  survey.trajectory = Trajectory(simulated.motion.measured, simulated.frame);
  survey.exposures = simulated.exposures;
  survey.roadmarks = simulated.database;
  return survey;
}

}  // namespace zebrageo::sim
