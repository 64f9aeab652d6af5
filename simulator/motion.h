// The vehicle's true motion along the simulated road, the GNSS/INS error of
// the measured trajectory, the stereo rig and the exposure times.
//
// Frames: ENU of the survey; body FRD with its origin at the IMU,
// imu_height_m above the road; R_enu_body is built from the road geometry
// (heading from the tangent, pitch from the grade, roll from the camber,
// plus suspension oscillations) and converted to the INS attitude relative
// to NED AT THE VEHICLE (LocalFrame::AttitudeFromRotationEnuBody).
// Camera frame OpenCV; T_body_cam maps camera into body coordinates.
#ifndef ZEBRAGEO_SIMULATOR_MOTION_H_
#define ZEBRAGEO_SIMULATOR_MOTION_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "simulator/simulator.h"
#include "simulator/world.h"
#include "survey/geodesy.h"
#include "survey/rig.h"
#include "survey/trajectory.h"

namespace zebrageo::sim {

struct ExposureEvent {
  int64_t exposure_id = 0;
  double time = 0.0;
  double s_m = 0.0;  // road s of the vehicle at that time
};

// A switch of the cross-track error (multipath): by cross_track_m (signed,
// along the road's left normal) over length_m of travel centred on s_m.
struct MultipathSwitch {
  double s_m = 0.0;
  double length_m = 0.0;
  double cross_track_m = 0.0;
};

struct VehicleMotion {
  std::vector<TrajectorySample> truth;     // true, sd_* = 0
  std::vector<TrajectorySample> measured;  // true + error, sd_* optimistic
  std::vector<double> s_m;                 // road s of each sample
  // Measured minus true IMU position (ENU) and attitude error (roll, pitch,
  // heading; radians) of each sample.
  std::vector<Eigen::Vector3d> position_error_enu;
  std::vector<Eigen::Vector3d> attitude_error_rad;
  std::vector<ExposureEvent> exposures;
  std::vector<MultipathSwitch> multipath_switches;
  double outage_begin_time = 0.0;  // both 0 without an outage
  double outage_end_time = 0.0;
};

// Simulates the drive over [world.s_drive_start, world.s_drive_end].
VehicleMotion SimulateMotion(const SimulationOptions& options,
                             const World& world, const LocalFrame& frame);

// The stereo rig: "left" and "right", stereo pair [left, right].
Rig MakeRig(const SimulationOptions& options);

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_MOTION_H_
