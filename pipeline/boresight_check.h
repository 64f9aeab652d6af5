// The boresight check of `zebrageo run` (issue 47): before anything is
// reconstructed, the rotation between the cameras' mount that rig.yaml
// states and the one the images observe (tiepoints/mount_misalignment.h).
//
// A calibration imported without its mount angles (import-opencv-stereo,
// import-kalibr, import-ros-camera-info take a lever arm and a pitch-down)
// turns every reconstructed band about the vehicle: at 10 m, 1 degree is
// 17 cm, so bands match the wrong database band and the adjustment bends
// the attitude to fit them, a result worse than the input with exit 0.
// Where the misalignment is significant (beyond what a stated mount is good
// for and beyond min_sigmas standard deviations), the run applies the
// estimate of every axis the data observe well enough, and says so
// (stderr, report.json): "diagnosis: ... rig.yaml ...". It stops instead
// (InputError naming rig.yaml and the angles: exit 1) when an axis that
// is significant is observed too poorly to apply, or when apply is off.
#ifndef ZEBRAGEO_PIPELINE_BORESIGHT_CHECK_H_
#define ZEBRAGEO_PIPELINE_BORESIGHT_CHECK_H_

#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/mount_attitude_check.h"
#include "pipeline/progress.h"
#include "survey/cancellation.h"
#include "survey/math_util.h"
#include "survey/survey.h"
#include "tiepoints/mount_misalignment.h"
#include "tiepoints/mount_observations.h"

namespace zebrageo {

struct BoresightCheckOptions {
  bool enabled = true;
  // Apply a significant, well-observed estimate (else stop with exit 1).
  bool apply = true;
  // A misalignment is significant beyond this angle on an axis (what a
  // stated mount is good for: a boresight calibration gives 0.01-0.05
  // degrees, a rig drawing 0.1-0.2)...
  double min_significant_rad = DegToRad(0.2);
  // ... and beyond this many of its standard deviations.
  double min_sigmas = 4.0;
  // An axis with a larger sd is not observed: it is neither evidence of a
  // misalignment nor applied.
  double max_observed_sd_rad = DegToRad(0.5);
  // An axis is applied only with a standard deviation below this: a
  // turn left of 0.15 degrees moves a band 10 m away by 2.6 cm, which the
  // registration's tolerances and the adjustment take.
  double max_applied_sd_rad = DegToRad(0.15);
  // When the estimate is applied, the adjustment calibrates the rig's
  // boresight too, with the estimate's sd as its prior
  // (adjustment.rig_calibration).
  bool self_calibrate_after = true;
  // After the adjustment: a mount rotation too small for this check that
  // bent the body's attitude (mount_attitude_check.h).
  MountAttitudeOptions attitude;
  MountObservationOptions observations;
  MountMisalignmentOptions estimate;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("enabled", enabled);
    v("apply", apply);
    v("min_significant_rad", min_significant_rad);
    v("min_sigmas", min_sigmas);
    v("max_observed_sd_rad", max_observed_sd_rad);
    v("max_applied_sd_rad", max_applied_sd_rad);
    v("self_calibrate_after", self_calibrate_after);
    // The exposures read at most (tiepoints/mount_observations.h): the
    // check costs the same on a survey of 100 and of 100,000 exposures.
    v("max_exposures", observations.max_exposures);
    v("attitude", attitude);
  }
};

struct BoresightCheck {
  bool checked = false;
  MountMisalignment estimate;
  bool significant = false;
  // What was applied to the rig (zero where nothing).
  Eigen::Vector3d applied_rad = Eigen::Vector3d::Zero();
  std::string message;  // the diagnosis, when significant
};

// The check's verdict on `survey`'s rig. Throws InputError (rig.yaml) when
// a significant misalignment cannot be applied, std::invalid_argument for
// bad options, CancelledError.
BoresightCheck CheckBoresight(const Survey& survey,
                              const BoresightCheckOptions& options,
                              const ProgressListener& progress = {},
                              const CancellationToken& cancel = {});

// For report.json: angles in degrees (roll, pitch, yaw about the body's
// forward, right and down axes), their standard deviations, what was
// applied.
nlohmann::json BoresightCheckJson(const BoresightCheck& check);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_BORESIGHT_CHECK_H_
