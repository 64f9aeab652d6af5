// The rotation between the cameras' mount that rig.yaml states and the one
// the images observe (issue 47), from MountObservations:
//
// - the camera's motion between consecutive exposures, measured by stereo
//   odometry, against the trajectory's body motion carried through the
//   mount: its direction of travel observes yaw and pitch (a mount turned
//   by 1 degree sees the vehicle travel 1 degree off its axis), its turns
//   observe all three angles, weakly;
// - the road plane of each stereo pair's points against the body's
//   down axis: roll and pitch (the vehicle stands on the road it sees, up to
//   the road's change of slope within 25 m and the suspension's tilt).
//
// One rotation for the whole rig: the stereo pair's relative pose is its
// own calibration, checked by the stereo matches; what an import loses is
// the rig's rotation on the vehicle. The model: T_body_cam = Exp(rotation)
// * T_body_cam_stated for every camera (the lever arm turns with it, so the
// stereo pair's relative pose is kept).
//
// Frames: body FRD; the rotation as a rotation vector (radians), its x, y,
// z components roll, pitch and yaw for small angles.
#ifndef ZEBRAGEO_TIEPOINTS_MOUNT_MISALIGNMENT_H_
#define ZEBRAGEO_TIEPOINTS_MOUNT_MISALIGNMENT_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "survey/rig.h"
#include "tiepoints/mount_observations.h"

namespace zebrageo {

struct MountMisalignmentOptions {
  // A step shorter than this (metres) has no direction of travel.
  double min_step_m = 0.5;
  // Road points: ahead of the body origin by this much (metres), within
  // this distance of its axis (the vehicle's own lane: a crowned road
  // tilts the other way beyond it), fitted to a plane within the
  // tolerance; a plane needs this many points.
  double min_road_ahead_m = 3.0;
  double max_road_ahead_m = 20.0;
  double max_road_lateral_m = 2.5;
  double road_tolerance_m = 0.03;
  int min_road_points = 20;
  // The road's normal may be this far from the body's down axis (radians):
  // beyond, the plane is a car's roof or a facade.
  double max_road_tilt_rad = 0.15;
  // The systematic part of the plane's evidence that the scatter does not
  // show (radians, added in quadrature to the roll and pitch the road
  // observes): the road's slope ahead against the one the vehicle stands
  // on, its suspension, the IMU's own tilt in the vehicle.
  double road_bias_sd_rad = 0.0015;
  // The same for yaw from the direction of travel: side slip, and what
  // the field cases show with their stated rigs (yaw -0.17 +- 0.11 and
  // 0.15 +- 0.17 degrees).
  double direction_bias_sd_rad = 0.0015;
  // The rotation's prior sd on each axis (radians): what an import can
  // lose is a few degrees.
  double prior_sd_rad = 0.035;
  // Fewer motions or planes: that evidence is not used.
  int min_steps = 4;
  int min_planes = 4;

  std::string Check() const;
};

struct MountMisalignment {
  // Found: enough motions or road planes to estimate anything.
  bool estimated = false;
  Eigen::Vector3d rotation_body_rad = Eigen::Vector3d::Zero();
  // Standard deviations of the three components (radians): large where
  // the data barely observe the axis.
  Eigen::Vector3d sd_rad = Eigen::Vector3d::Constant(1.0);
  int steps_used = 0;
  int planes_used = 0;
  // Robust scatter of each kind of evidence (radians).
  double direction_sigma_rad = 0.0;
  double turn_sigma_rad = 0.0;
  double plane_sigma_rad = 0.0;
};

// Throws std::invalid_argument when options.Check() fails.
MountMisalignment EstimateMountMisalignment(
    const MountMisalignmentOptions& options, const Rig& rig,
    const MountObservations& observations);

// The rig with every camera's mount turned by `rotation_body_rad`
// (T_body_cam = Exp(rotation) * T_body_cam).
Rig RotateRigMount(const Rig& rig, const Eigen::Vector3d& rotation_body_rad);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TIEPOINTS_MOUNT_MISALIGNMENT_H_
