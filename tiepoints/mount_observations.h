// What the images say about the cameras' mount on the vehicle, measured
// without the mount's rotation (issue 47): the stereo pair's own calibration
// (the cameras' pose relative to each other) triangulates features of each
// exposure, and those points seen again in the next exposure give the
// camera's motion (stereo_odometry.h). Compared with the trajectory, whose
// motion and attitude are the body's, they observe the rotation between
// body and camera that rig.yaml states (mount_misalignment.h).
//
// Frames: camera (x right, y down, z forward) and body (FRD); metres.
#ifndef ZEBRAGEO_TIEPOINTS_MOUNT_OBSERVATIONS_H_
#define ZEBRAGEO_TIEPOINTS_MOUNT_OBSERVATIONS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <string>
#include <vector>

#include "survey/cancellation.h"
#include "survey/exposures.h"
#include "survey/rig.h"
#include "survey/trajectory.h"
#include "tiepoints/stereo_odometry.h"

namespace zebrageo {

struct MountObservationOptions {
  // ORB features per image and Lowe's ratio for the stereo matches.
  int max_features_per_image = 2000;
  double max_descriptor_ratio = 0.8;
  // A stereo match is kept within this distance (pixels) of its epipolar
  // line (the rig's own relative pose: no trajectory, no mount involved).
  double max_epipolar_distance_px = 1.5;
  // The motion between exposures; its bounds against the trajectory's
  // motion are wide enough for a mount wrong by several degrees.
  StereoOdometryOptions odometry;
  // One mount holds for the whole survey: a long survey is sampled, this
  // many exposures at most, in runs of consecutive ones (the motion is
  // measured between neighbours) spread evenly along it. 0: every one.
  int max_exposures = 120;
  // Consecutive exposures per run of that sample.
  int run_length = 4;

  std::string Check() const;
};

// The left camera of a stereo pair between two consecutive exposures.
struct CameraStep {
  int camera = -1;
  int exposure_a = -1, exposure_b = -1;
  // Measured from the images: camera a's coordinates into camera b's.
  Eigen::Isometry3d T_cb_ca = Eigen::Isometry3d::Identity();
  // From the trajectory: body a's coordinates into body b's.
  Eigen::Isometry3d T_bb_ba = Eigen::Isometry3d::Identity();
  int inliers = 0;
};

// An exposure's stereo points (the left camera of a stereo pair, its
// frame): mostly road surface, some kerbs, cars and facades.
struct StereoPoints {
  int camera = -1;
  int exposure = -1;
  std::vector<Eigen::Vector3d> points_cam;
};

struct MountObservations {
  std::vector<CameraStep> steps;
  std::vector<StereoPoints> stereo_points;
  int images_read = 0;
  int motion_steps = 0;  // steps tried (both exposures readable)
};

// Reads every stereo pair's images of the sampled exposures once (all of
// them on a survey of up to options.max_exposures). Unreadable images and
// exposures outside the trajectory are skipped. Throws std::invalid_argument
// when options.Check() fails, CancelledError between exposures.
MountObservations ObserveMount(
    const MountObservationOptions& options, const std::string& survey_folder,
    const Rig& rig, const Trajectory& trajectory,
    const ExposureTable& exposures,
    const std::function<void(int, int)>& progress = nullptr,
    const CancellationToken& cancel = {});

// Which of num_exposures exposures ObserveMount reads: all of them up to
// max_exposures (or with max_exposures 0), else max_exposures / run_length
// runs of run_length consecutive exposures, the first run at the survey's
// start, the last at its end.
std::vector<bool> SampledExposures(int num_exposures, int max_exposures,
                                   int run_length);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TIEPOINTS_MOUNT_OBSERVATIONS_H_
