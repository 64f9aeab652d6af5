#include "pipeline/boresight_check.h"

#include <glog/logging.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "survey/input_error.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

constexpr const char* kAxisNames[3] = {"roll", "pitch", "yaw"};

std::string Angles(const MountMisalignment& estimate) {
  std::ostringstream text;
  text.precision(2);
  text << std::fixed;
  for (int k = 0; k < 3; ++k) {
    text << (k ? ", " : "") << kAxisNames[k] << " "
         << RadToDeg(estimate.rotation_body_rad[k]) << " +- "
         << RadToDeg(estimate.sd_rad[k]) << " deg";
  }
  return text.str();
}

}  // namespace

std::string BoresightCheckOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, min_significant_rad, 0.0);
  OPTION_GT(check, min_sigmas, 0.0);
  OPTION_GT(check, max_applied_sd_rad, 0.0);
  OPTION_GE(check, max_observed_sd_rad, max_applied_sd_rad);
  OPTION_NESTED(check, attitude);
  OPTION_NESTED(check, observations);
  OPTION_NESTED(check, estimate);
  return check.problem();
}

BoresightCheck CheckBoresight(const Survey& survey,
                              const BoresightCheckOptions& options,
                              const ProgressListener& progress,
                              const CancellationToken& cancel) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("BoresightCheckOptions: " + problem);
  }
  BoresightCheck check;
  if (!options.enabled || survey.rig.stereo_pairs.empty()) return check;
  StepProgress step(progress, "boresight check");
  const MountObservations observations = ObserveMount(
      options.observations, survey.folder, survey.rig, survey.trajectory,
      survey.exposures, step.Callback(), cancel);
  step.Finish();
  check.estimate =
      EstimateMountMisalignment(options.estimate, survey.rig, observations);
  check.checked = check.estimate.estimated;
  const MountMisalignment& e = check.estimate;
  LOG(INFO) << "boresight check: " << e.steps_used << " camera motions, "
            << e.planes_used << " road planes: " << Angles(e)
            << " (scatter: direction " << RadToDeg(e.direction_sigma_rad)
            << ", turn " << RadToDeg(e.turn_sigma_rad) << ", road "
            << RadToDeg(e.plane_sigma_rad) << " deg)";
  if (!check.checked) {
    LOG(INFO) << "boresight check: too few camera motions and road planes "
                 "in the images to check the rig's mount";
    return check;
  }
  bool unappliable = false;
  for (int k = 0; k < 3; ++k) {
    const double angle = std::abs(e.rotation_body_rad[k]);
    if (e.sd_rad[k] > options.max_observed_sd_rad) continue;
    if (angle > options.min_significant_rad &&
        angle > options.min_sigmas * e.sd_rad[k]) {
      check.significant = true;
      unappliable |= e.sd_rad[k] > options.max_applied_sd_rad;
    }
  }
  if (!check.significant) return check;
  const std::string rig_file = survey.manifest.rig;
  std::ostringstream text;
  text << "diagnosis: the images observe the cameras' mount turned from the "
       << "one " << rig_file << " states: " << Angles(e) << " (from "
       << e.steps_used << " camera motions and " << e.planes_used
       << " road planes; body axes forward, right, down)";
  if (!options.apply || unappliable) {
    text << "; not applied ("
         << (options.apply ? "observed too poorly" : "boresight.apply is off")
         << "): state the mount angles in " << rig_file
         << " (a calibration imported without them loses them)";
    throw InputError(rig_file, 0, text.str());
  }
  for (int k = 0; k < 3; ++k) {
    if (e.sd_rad[k] <= options.max_applied_sd_rad) {
      check.applied_rad[k] = e.rotation_body_rad[k];
    }
  }
  text << "; the run applies it (T_body_cam = R * T_body_cam of " << rig_file
       << " for every camera); state the mount angles in " << rig_file
       << " if they are known";
  check.message = text.str();
  LOG(WARNING) << check.message;
  return check;
}

nlohmann::json BoresightCheckJson(const BoresightCheck& check) {
  const MountMisalignment& e = check.estimate;
  // Not checked: the images gave too few camera motions and road planes
  // (the counts say how few).
  nlohmann::json json = {{"checked", check.checked},
                         {"camera_motions", e.steps_used},
                         {"road_planes", e.planes_used},
                         {"significant", check.significant},
                         {"applied", !check.applied_rad.isZero()}};
  if (!check.checked) return json;
  for (int k = 0; k < 3; ++k) {
    const std::string axis = kAxisNames[k];
    json[axis + "_deg"] = RadToDeg(e.rotation_body_rad[k]);
    json[axis + "_sd_deg"] = RadToDeg(e.sd_rad[k]);
    json[axis + "_applied_deg"] = RadToDeg(check.applied_rad[k]);
  }
  return json;
}

}  // namespace zebrageo
