// Test utilities for the registration tests: synthetic streets with zebra
// crossings, a drifting trajectory, and "reconstructed" bands generated from
// the truth, independently of the reconstruction stage.
//
// Frames: the scene is built directly in the working ENU frame (x east, y
// north, z up) of a LocalFrame at `origin`; the vehicle drives east along
// y = lane_y_m; body frame FRD. Reconstructed bands are the TRUE band corners
// in the body frame of the TRUE pose, plus noise; the observations carry the
// MEASURED (drifting) pose, as the reconstruction stage would.
#ifndef ZEBRAGEO_TESTS_REGISTRATION_SYNTHETIC_SCENE_H_
#define ZEBRAGEO_TESTS_REGISTRATION_SYNTHETIC_SCENE_H_

#include <Eigen/Core>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "registration/band_matcher.h"
#include "registration/roadmark_index.h"
#include "survey/geodesy.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct SyntheticCrossingSpec {
  double x_m = 0.0;  // centre along the road (east)
  int bands = 8;     // 4..12
  double band_length_m = 3.0;
  double skew_rad = 0.0;  // shift of each band along the road per metre across
  // South edge of band 1 (default: SyntheticSceneOptions::road_y0_m).
  std::optional<double> y0_m;
  // Faults.
  bool in_database = true;
  bool in_street = true;
  std::vector<int> database_lacks;  // band numbers missing from the database
  std::vector<int> street_lacks;    // band numbers missing from the street
  Eigen::Vector2d database_shift_m = Eigen::Vector2d::Zero();  // repainted
  // A vehicle parked at the kerb before the crossing hides its first
  // `occluded_bands` bands from viewpoints further than
  // `occluded_beyond_m` from the crossing (0: no occluder).
  int occluded_bands = 0;
  double occluded_beyond_m = 0.0;
};

struct SyntheticSceneOptions {
  int seed = 1;
  std::vector<SyntheticCrossingSpec> crossings;
  // Road: the crossings span y in [road_y0_m, road_y0_m + bands] (band 1 at
  // the south kerb); the vehicle drives east at lane_y_m.
  double road_y0_m = -4.0;
  double lane_y_m = -2.0;
  double speed_m_per_s = 8.0;
  double exposure_interval_s = 0.2;
  double start_x_m = -40.0;
  double end_x_m = 0.0;  // 0: 40 m past the last crossing
  // Trajectory error: shift = drift_m * (cos, sin)(phase + rate * t) +
  // constant_shift_m; heading error heading_drift_rad * sin(0.05 t).
  double drift_m = 2.0;
  double drift_phase_rad = 0.7;
  double drift_turn_rate_rad_per_s = 0.01;
  Eigen::Vector2d constant_shift_m = Eigen::Vector2d::Zero();
  double heading_drift_rad = 0.005;
  // Database accuracy: per-crossing offset (uniform in +-) and per-vertex
  // noise (sd).
  double database_offset_m = 0.08;
  double database_vertex_noise_m = 0.01;
  // Reconstruction: vertex noise (sd, body frame), range limit, missed
  // bands, false bands per exposure.
  double vertex_noise_m = 0.015;
  double max_range_m = 15.0;
  double miss_probability = 0.03;
  double false_band_probability = 0.1;
  // Cameras: one forward stereo pair.
  double horizontal_fov_deg = 90.0;
  double pitch_down_deg = 15.0;
};

struct SyntheticScene {
  LocalFrame frame{Geodetic{43.7384, 7.4246, 50.0}};
  RoadmarkDatabase database;  // what the matcher is given
  // True band corners in ENU, by (crossing_id, band), in the database's
  // ring order.
  std::map<std::pair<std::string, int>, std::array<Eigen::Vector3d, 4>> truth;
  Rig rig;
  std::vector<CrossingObservation> observations;  // measured poses
  std::vector<ExposurePose> exposures;            // measured poses
  std::map<int64_t, Pose> true_pose;              // by exposure_id
  // Observation band -> the truth band it is (false bands absent).
  std::map<std::pair<int64_t, int64_t>, std::pair<std::string, int>>
      band_truth;  // (exposure_id, band_id) -> (crossing_id, band)

  // The input for MatchBands (points into this scene and `index`).
  MatchInput Input(const RoadmarkIndex& index) const;
};

SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options);

// A street of `count` crossings every `spacing_m`, random band counts,
// lengths and (one in three) skews.
std::vector<SyntheticCrossingSpec> RandomCrossings(int count, double spacing_m,
                                                   int seed);

// A scene of `crossings` random crossings every `spacing_m` (RandomCrossings).
SyntheticSceneOptions RandomStreetScene(int seed, int crossings = 8,
                                        double spacing_m = 45.0);

// Whether `result` claims a fault of `kind` on `crossing_id` (on `band`, or
// on any band when `band` is 0).
bool HasFault(const MatchResult& result, FaultKind kind,
              const std::string& crossing_id, int band = 0);

// The mark `result` lists as not recognised for that band, or null.
const UnrecognisedMark* FindUnrecognised(const MatchResult& result,
                                         const std::string& crossing_id,
                                         int band);

// Scores matches against the scene's truth like score_results.py: a match
// is wrong if the reconstructed vertex placed with the TRUE pose is more than
// 0.2 m from the named truth vertex, or names a band not in the street.
struct MatchScore {
  int right = 0;
  int wrong = 0;
  std::vector<std::string> crossings_matched;
  std::vector<std::string> crossings_eligible;  // seen and in the database
};
MatchScore ScoreMatches(const SyntheticScene& scene,
                        const std::vector<VertexMatch>& matches);

// From a simulated survey folder (truth/ present): writes
// reconstructed_bands.csv in `results_folder` with the truth bands fully
// visible in both images of a pair within `max_range_m`, in the body frame
// of the TRUE pose, plus noise, grouped by crossing. Returns the number of
// bands written.
int WriteSyntheticReconstruction(const std::string& survey_folder,
                                 const std::string& results_folder, int seed,
                                 double vertex_noise_m, double max_range_m);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TESTS_REGISTRATION_SYNTHETIC_SCENE_H_
