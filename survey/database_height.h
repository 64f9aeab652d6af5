// The road-mark database's heights against the road under the trajectory
// (issue 48): a layer of heights above sea level read as ellipsoidal ones
// (a 2D CRS on a national agency's 3D layer) puts every band tens of metres
// below the road, where the reconstruction never finds it, and nothing is
// matched. The bands near the trajectory tell it before anything runs.
#ifndef ZEBRAGEO_SURVEY_DATABASE_HEIGHT_H_
#define ZEBRAGEO_SURVEY_DATABASE_HEIGHT_H_

#include <string>

#include "survey/geodesy.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct DatabaseHeightOptions {
  // Bands whose centre lies within this (m, horizontally) of a trajectory
  // sample are compared with the road below it.
  double max_band_distance_m = 30.0;
  // The INS's nominal height above the road (m): a car roof 1.5 to 2.5 m.
  double nominal_imu_height_m = 1.5;
  // A median band height departing from the road by more than this (m) is
  // an error: the database's own accuracy and the INS's height on the
  // vehicle are decimetres to a metre; a vertical datum mix-up is tens.
  double max_height_offset_m = 10.0;

  std::string Check() const;
};

// The problem ("" when none): the median height of the database's bands
// (those with heights) near the trajectory against the trajectory's height
// less the nominal IMU height, in the ENU frame `frame`, with the geoid's
// undulation (EGM96 through PROJ, when its grid is installed) as the likely
// cause when it matches. Files are named as the survey names them.
std::string DatabaseHeightProblem(const Trajectory& trajectory,
                                  const std::string& trajectory_file,
                                  const RoadmarkDatabase& database,
                                  const LocalFrame& frame,
                                  const DatabaseHeightOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_DATABASE_HEIGHT_H_
