// Plausibility of a survey that the readers accept: valid files that cannot
// be what they claim (issue 18).
//
// The readers check each file against the contract; these checks compare
// the files with each other and with the physics of a vehicle:
//   - the trajectory's gaps (a lost INS solution) and its rate (the
//     contract asks for 10 to 200 Hz); an exposure inside a long gap;
//   - the heading against the direction of travel (angles in radians, or
//     not the vehicle's heading, show as a large systematic disagreement);
//   - the distance of the trajectory from survey.yaml's origin and from
//     the road-mark database (latitude and longitude swapped, a database of
//     another city).
// What cannot give a usable result is an InputError naming the file, the
// line and the problem (exit 1); what is doubtful is a warning, for
// report.json. Frames: distances in the survey's ENU frame or on the WGS84
// ellipsoid (GeographicLib), angles in radians inside, degrees in messages.
#ifndef ZEBRAGEO_SURVEY_PLAUSIBILITY_H_
#define ZEBRAGEO_SURVEY_PLAUSIBILITY_H_

#include <optional>
#include <string>
#include <vector>

#include "survey/database_height.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct PlausibilityOptions {
  // What a gap of the trajectory is (survey/trajectory.h).
  TrajectoryGapOptions gaps;
  // An exposure inside a gap longer than this (s) is an error: its pose
  // would be interpolated over the gap, at 15 m/s 15 m per second of any
  // turn or braking. In a shorter gap it is a warning.
  double max_exposure_gap_s = 1.0;
  // The contract's lowest trajectory rate (Hz): slower is a warning (poses
  // are interpolated linearly between samples further apart).
  double min_rate_hz = 10.0;
  // Heading check: the direction of travel is the chord of the positions
  // over heading_chord_s (s), where the vehicle moves at min_speed_mps or
  // more; at least min_heading_chords such chords are needed to judge.
  double heading_chord_s = 1.0;
  double min_speed_mps = 2.0;
  int min_heading_chords = 5;
  // A median disagreement between heading and direction of travel above
  // this (degrees) is an error: a vehicle's crab angle is a few degrees.
  double max_heading_disagreement_deg = 20.0;
  // The nearest trajectory sample may lie this far (m) from survey.yaml's
  // origin at most: the origin is the survey's working frame.
  double max_origin_distance_m = 100e3;
  // The nearest road mark of the database may lie this far (m) from the
  // trajectory at most: farther, nothing in it can control the trajectory.
  double max_database_distance_m = 5e3;
  // The database's bands against the road under the trajectory (a
  // vertical datum mix-up: survey/database_height.h).
  DatabaseHeightOptions database_height;

  std::string Check() const;
};

// What the checks read; files are named as the survey names them.
struct PlausibilityInput {
  const Trajectory* trajectory = nullptr;  // required
  std::string trajectory_file = "trajectory.csv";
  const ExposureTable* exposures = nullptr;  // required
  std::string exposures_file = "exposures.csv";
  // Null when the command does not load the database (reconstruct): its
  // distance is then not checked.
  const RoadmarkDatabase* roadmarks = nullptr;
  std::string roadmarks_file = "roadmarks.geojson";
  // survey.yaml's origin and its line; nullopt when the origin defaults to
  // the first trajectory sample.
  std::optional<Geodetic> origin;
  int origin_line = 0;
  std::string manifest_file = "survey.yaml";
  const LocalFrame* frame = nullptr;  // required: the survey's ENU frame
};

// Throws InputError for a survey that cannot give a usable result; returns
// the warnings (each naming its file, and line where there is one). Throws
// std::invalid_argument when options.Check() fails.
std::vector<std::string> CheckPlausibility(const PlausibilityInput& input,
                                           const PlausibilityOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_PLAUSIBILITY_H_
