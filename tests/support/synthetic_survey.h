// Synthetic surveys with known truth for the adjustment's tests and bench
// (the role of COLMAP's scene/synthetic.h): a vehicle drives a gently
// curving, undulating road at constant speed, with zebra crossings at
// regular spacing; the measured trajectory is the true one plus a smooth
// GNSS/INS drift; the reconstruction and registration stages are replaced by
// their ideal outputs: each visible band vertex is projected with the TRUE
// pose into both cameras of the stereo pair (+ pixel noise), placed in the
// body frame (+ noise), and matched to its database vertex.
//
// Frames as everywhere: ENU working frame, body FRD, camera OpenCV.
#ifndef ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_SURVEY_H_
#define ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_SURVEY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/tie_tracks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct SyntheticSurveyOptions {
  uint64_t seed = 1;
  int num_exposures = 300;
  double speed_mps = 10.0;
  // Time between exposures (0.3 s at 10 m/s = 3 m, as the simulator).
  double exposure_interval_s = 0.3;
  double trajectory_rate_hz = 20.0;
  // Crossings along the road, the first one 40 m after the start.
  double crossing_spacing_m = 80.0;
  int bands_per_crossing = 6;
  // Band visible when all four corners are in both images and the band's
  // centre is within this range of the left camera.
  double max_range_m = 16.0;
  // Measured minus true: peak horizontal and vertical position drift, and
  // peak heading and tilt drift; smooth with periods >= drift_period_s.
  double drift_horizontal_m = 2.0;
  double drift_vertical_m = 0.3;
  double heading_drift_deg = 0.1;
  double tilt_drift_deg = 0.03;
  double drift_period_s = 60.0;
  // Observation noise: vertex pixels (both images) and body coordinates.
  double pixel_noise_px = 0.3;
  double body_noise_m = 0.015;
  // Database: per-vertex noise and per-crossing offset (horizontal, per
  // axis; vertical) drawn once per crossing; sigma_xy/sigma_z written.
  double database_sigma_xy_m = 0.02;
  double database_sigma_z_m = 0.03;
  double database_offset_m = 0.0;
  // Ideal tie points: new points per exposure (on the road ahead and on
  // facades beside it), each observed in both cameras of up to
  // tie_track_exposures consecutive exposures with tie_noise_px; 0 = none.
  int tie_points_per_exposure = 0;
  int tie_track_exposures = 4;
  double tie_noise_px = 0.5;
  double origin_lat_deg = 49.8941;
  double origin_lon_deg = 2.2958;
  double origin_h_m = 60.0;
};

struct SyntheticSurvey {
  Rig rig;
  LocalFrame frame{Geodetic{}};
  std::vector<TrajectorySample> truth_samples;
  std::vector<TrajectorySample> measured_samples;
  ExposureTable exposures;
  RoadmarkDatabase database;        // as the survey's roadmarks.geojson
  RoadmarkDatabase truth_database;  // the true corners
  std::vector<ReconstructedVertex> vertices;
  std::vector<VertexMatch> matches;
  // Initial positions triangulated as from the drifting trajectory.
  std::vector<TieTrack> tie_tracks;
};

SyntheticSurvey MakeSyntheticSurvey(const SyntheticSurveyOptions& options);

// The adjustment's input on `survey` with `trajectory` (its measured
// samples; both outlive the input), with its tie tracks when it has any.
AdjustmentInput SyntheticAdjustmentInput(const SyntheticSurvey& survey,
                                         const Trajectory& trajectory);

// Writes the survey folder (survey.yaml, rig.yaml, trajectory.csv,
// exposures.csv, roadmarks.geojson, truth/trajectory.csv,
// truth/roadmarks.geojson) and, in `results_folder`, the stage outputs the
// adjustment reads (reconstructed_bands.csv, matches.csv). No images.
// Ideal reconstruction and registration outputs for a survey with truth:
// every band of `truth_bands` whose four corners are in both images of the
// first stereo pair (5 px margin) and within max_range_m of the left camera
// becomes 4 ReconstructedVertex rows (true pose, + noise, vertex order
// rotated per band), and 4 VertexMatch rows when `database` has the band.
struct IdealObservationOptions {
  uint64_t seed = 1;
  double pixel_noise_px = 0.3;
  double body_noise_m = 0.015;
  double max_range_m = 16.0;
};
void MakeIdealObservations(const IdealObservationOptions& options,
                           const Rig& rig, const LocalFrame& frame,
                           const Trajectory& truth,
                           const ExposureTable& exposures,
                           const RoadmarkDatabase& truth_bands,
                           const RoadmarkDatabase& database,
                           std::vector<ReconstructedVertex>* vertices,
                           std::vector<VertexMatch>* matches);
// The same for a survey folder with truth/ (e.g. from `zebrageo simulate`):
// writes reconstructed_bands.csv and matches.csv into `results_folder`.
void WriteIdealStageOutputs(const IdealObservationOptions& options,
                            const std::string& survey_folder,
                            const std::string& results_folder);

void WriteSyntheticSurvey(const SyntheticSurvey& survey,
                          const std::string& survey_folder,
                          const std::string& results_folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_SURVEY_H_
