// The GNSS outage of the simulated drive (issue 43): where it falls
// (outage_clear_after_m), and the INS error that grows through it
// (outage_ins_drift). Internal to the simulator; motion.cc adds it to the
// measured trajectory.
#ifndef ZEBRAGEO_SIMULATOR_GNSS_OUTAGE_H_
#define ZEBRAGEO_SIMULATOR_GNSS_OUTAGE_H_

#include <Eigen/Core>
#include <vector>

#include "simulator/simulator.h"
#include "simulator/world.h"

namespace zebrageo::sim {

// The trajectory's samples: times from the start of the drive, and the road
// position s of each, the speed integrated sample by sample until
// s_drive_end.
struct DriveSamples {
  std::vector<double> times;
  std::vector<double> s_of;
};

// The GNSS outage, in seconds from the start of the drive: the direction
// its error grows in, and that of the jump when GNSS returns. With
// outage_ins_drift, the directions of the velocity and acceleration biases
// and the share of the first.
struct Outage {
  bool active = false;
  double begin = 0.0;
  double end = 0.0;
  Eigen::Vector3d direction;
  Eigen::Vector3d jump_direction;
  Eigen::Vector2d velocity_direction = Eigen::Vector2d::UnitX();
  Eigen::Vector2d acceleration_direction = Eigen::Vector2d::UnitX();
  double velocity_share = 0.5;
  double vertical_sign = 1.0;
  // The INS error of each sample (outage_ins_drift), zero outside.
  std::vector<Eigen::Vector3d> ins_error;
};

// The outage's timing from the options and its directions drawn from the
// seed (the same draws, in the same order, as before issue 43's
// outage_ins_drift: the quadratic outages stay as they were).
Outage DrawOutage(const SimulationOptions& options);

// outage_clear_after_m: the outage moved to end past a crossing of the
// street, with at least that many metres ahead before the next one (or the
// drive's end), its whole duration after the drive's first seconds, and a
// crossing before it where it can: of the places that allow the most of
// these (in this order), one at random; the clear stretch the longest
// where none allows it.
void PlaceOutage(const SimulationOptions& options, const World& world,
                 const DriveSamples& drive, Outage* outage);

// outage_ins_drift: the INS error of each sample through the outage, from
// the true positions `p_enu`: the heading error (growing linearly to
// outage_heading_drift_deg) turning each step travelled, plus a velocity
// and an acceleration bias sized so that the horizontal error at the
// outage's end is outage_drift_m.
void IntegrateInsDrift(const SimulationOptions& options,
                       const DriveSamples& drive,
                       const std::vector<Eigen::Vector3d>& p_enu,
                       Outage* outage);

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_GNSS_OUTAGE_H_
