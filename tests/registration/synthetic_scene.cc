#include "tests/registration/synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <set>

#include "survey/math_util.h"
#include "survey/survey.h"

namespace zebrageo {
namespace {

constexpr double kBandWidthM = 0.5;
constexpr double kBandPeriodM = 1.0;
constexpr double kBodyHeightM = 1.0;  // body origin above the road

Eigen::Matrix3d RotationZ3(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Body (FRD) to ENU for a vehicle heading east.
Eigen::Matrix3d EastboundEnuFromBody() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(1, 0, 0);   // forward -> east
  r.col(1) = Eigen::Vector3d(0, -1, 0);  // right -> south
  r.col(2) = Eigen::Vector3d(0, 0, -1);  // down -> down
  return r;
}

Rig ForwardStereoRig(double horizontal_fov_deg, double pitch_down_deg) {
  const int width = 1920;
  const int height = 1080;
  const double f =
      0.5 * width / std::tan(0.5 * horizontal_fov_deg * kPi / 180.0);
  const double a = pitch_down_deg * kPi / 180.0;
  Eigen::Matrix3d R_body_cam;
  R_body_cam.col(0) = Eigen::Vector3d(0, 1, 0);
  R_body_cam.col(1) = Eigen::Vector3d(-std::sin(a), 0, std::cos(a));
  R_body_cam.col(2) = Eigen::Vector3d(std::cos(a), 0, std::sin(a));
  Rig rig;
  for (int side = 0; side < 2; ++side) {
    RigCamera camera;
    camera.camera = Camera(side == 0 ? "left" : "right", width, height, f, f,
                           0.5 * (width - 1), 0.5 * (height - 1),
                           {0.0, 0.0, 0.0, 0.0, 0.0});
    camera.T_body_cam.linear() = R_body_cam;
    camera.T_body_cam.translation() =
        Eigen::Vector3d(1.5, side == 0 ? -0.3 : 0.3, -1.0);
    rig.cameras.push_back(camera);
  }
  rig.stereo_pairs.push_back({0, 1});
  return rig;
}

// True when every corner projects at least `margin_px` inside both images of
// `pair` and the band is within `max_range_m` of the left camera.
bool FullyVisible(const Rig& rig, const std::array<int, 2>& pair,
                  const Pose& pose,
                  const std::array<Eigen::Vector3d, 4>& corners_enu,
                  double max_range_m, double margin_px) {
  const Eigen::Isometry3d T_enu_body = pose.T_enu_body();
  const Eigen::Vector3d centre = 0.25 * (corners_enu[0] + corners_enu[1] +
                                         corners_enu[2] + corners_enu[3]);
  const Eigen::Vector3d left_centre =
      T_enu_body * rig.cameras[pair[0]].T_body_cam.translation();
  if ((centre - left_centre).norm() > max_range_m) return false;
  for (int cam : pair) {
    const Eigen::Isometry3d T_cam_enu =
        (T_enu_body * rig.cameras[cam].T_body_cam).inverse();
    for (const Eigen::Vector3d& corner : corners_enu) {
      const Eigen::Vector3d p_cam = T_cam_enu * corner;
      Eigen::Vector2d uv;
      if (p_cam.z() < 0.5 || !rig.cameras[cam].camera.Project(p_cam, &uv) ||
          !rig.cameras[cam].camera.IsInImage(uv, margin_px)) {
        return false;
      }
    }
  }
  return true;
}

std::array<Eigen::Vector3d, 4> BandCorners(double x_centre, double y_centre,
                                           double length, double skew) {
  const Eigen::Vector3d c(x_centre, y_centre, 0.0);
  const Eigen::Vector3d along(0.5 * length, 0.0, 0.0);
  const Eigen::Vector3d across(0.5 * kBandWidthM * std::tan(skew),
                               0.5 * kBandWidthM, 0.0);
  return {c - along - across, c + along - across, c + along + across,
          c - along + across};
}

// The scene's random draws: one generator, drawn in scene order.
struct SceneRandom {
  explicit SceneRandom(int seed) : rng(seed) {}
  std::mt19937 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
};

// A band of the street (truth), as the drive sees it.
struct StreetBand {
  std::string crossing_id;
  int band;
  int group;
  std::array<Eigen::Vector3d, 4> corners;
  double hidden_beyond_x = -std::numeric_limits<double>::infinity();
};

// The crossings' bands: the street's in scene->truth (returned for the
// drive) and the database's, offset per crossing and noisy per vertex, in
// scene->database.
std::vector<StreetBand> PaintCrossings(const SyntheticSceneOptions& options,
                                       SceneRandom* random,
                                       SyntheticScene* scene) {
  std::mt19937& rng = random->rng;
  std::normal_distribution<double>& normal = random->normal;
  std::uniform_real_distribution<double>& uniform = random->uniform;
  std::vector<StreetBand> street;
  for (size_t c = 0; c < options.crossings.size(); ++c) {
    const SyntheticCrossingSpec& spec = options.crossings[c];
    char id[16];
    std::snprintf(id, sizeof(id), "C%02d", static_cast<int>(c + 1));
    const double y0 = spec.y0_m.value_or(options.road_y0_m);
    const double y_mid = y0 + 0.5 * spec.bands * kBandPeriodM;
    const Eigen::Vector3d offset(
        options.database_offset_m * (2.0 * uniform(rng) - 1.0),
        options.database_offset_m * (2.0 * uniform(rng) - 1.0), 0.0);
    for (int n = 1; n <= spec.bands; ++n) {
      const double y = y0 + (n - 0.5) * kBandPeriodM;
      std::array<Eigen::Vector3d, 4> corners =
          BandCorners(spec.x_m + std::tan(spec.skew_rad) * (y - y_mid), y,
                      spec.band_length_m, spec.skew_rad);
      std::rotate(corners.begin(),
                  corners.begin() + static_cast<int>(uniform(rng) * 4) % 4,
                  corners.end());
      const bool in_street =
          spec.in_street &&
          std::find(spec.street_lacks.begin(), spec.street_lacks.end(), n) ==
              spec.street_lacks.end();
      const bool in_database =
          spec.in_database &&
          std::find(spec.database_lacks.begin(), spec.database_lacks.end(),
                    n) == spec.database_lacks.end();
      if (in_street) {
        scene->truth[{id, n}] = corners;
        StreetBand street_band{id, n, static_cast<int>(c + 1), corners};
        if (n <= spec.occluded_bands) {
          street_band.hidden_beyond_x = spec.x_m - spec.occluded_beyond_m;
        }
        street.push_back(street_band);
      }
      if (in_database) {
        RoadmarkBand band;
        band.crossing_id = id;
        band.band = n;
        band.sigma_xy_m = 0.05;
        band.sigma_z_m = 0.1;
        for (int k = 0; k < 4; ++k) {
          Eigen::Vector3d p = corners[k] + offset;
          p.head<2>() += spec.database_shift_m;
          p.x() += options.database_vertex_noise_m * normal(rng);
          p.y() += options.database_vertex_noise_m * normal(rng);
          band.corners[k] = scene->frame.GeodeticFromEnu(p);
        }
        scene->database.bands.push_back(band);
      }
    }
  }
  return street;
}

// The measured pose at time t: the true one with the drifting position
// error and heading error of the options.
Pose MeasuredPoseAt(const SyntheticSceneOptions& options, const Pose& truth,
                    const Eigen::Matrix3d& R_true, double t) {
  const double angle =
      options.drift_phase_rad + options.drift_turn_rate_rad_per_s * t;
  const Eigen::Vector2d drift =
      options.drift_m * Eigen::Vector2d(std::cos(angle), std::sin(angle)) +
      options.constant_shift_m;
  const double heading_error =
      options.heading_drift_rad * std::sin(0.05 * t + 0.3);
  Pose measured;
  measured.q_enu_body = Eigen::Quaterniond(RotationZ3(heading_error) * R_true);
  measured.p_enu = truth.p_enu;
  measured.p_enu.head<2>() += drift;
  return measured;
}

// Band `enu` as reconstructed from the true pose (R_true, p_enu_true):
// vertices in the body frame, with noise, from any starting vertex, in
// either sense (the matcher must not care).
ObservedBand ObservedBandOf(const SyntheticSceneOptions& options,
                            const Eigen::Matrix3d& R_true,
                            const Eigen::Vector3d& p_enu_true,
                            const std::array<Eigen::Vector3d, 4>& enu,
                            int64_t band_id, SceneRandom* random) {
  std::mt19937& rng = random->rng;
  std::normal_distribution<double>& normal = random->normal;
  std::uniform_real_distribution<double>& uniform = random->uniform;
  ObservedBand band;
  band.band_id = band_id;
  const int start = static_cast<int>(uniform(rng) * 4) % 4;
  const bool reverse = uniform(rng) < 0.5;
  for (int k = 0; k < 4; ++k) {
    const int src = reverse ? (start - k + 4) % 4 : (start + k) % 4;
    const Eigen::Vector3d p_body = R_true.transpose() * (enu[src] - p_enu_true);
    band.p_body[k] =
        p_body + options.vertex_noise_m *
                     Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    band.vertex[k] = k;
  }
  return band;
}

// A band-shaped false detection somewhere ahead of x, any direction.
std::array<Eigen::Vector3d, 4> FalseBandCorners(
    const SyntheticSceneOptions& options, double x, SceneRandom* random) {
  std::mt19937& rng = random->rng;
  std::uniform_real_distribution<double>& uniform = random->uniform;
  const double fx = x + 5.0 + 7.0 * uniform(rng);
  const double fy = options.lane_y_m + 6.0 * (uniform(rng) - 0.5);
  const double yaw = kPi * uniform(rng);
  std::array<Eigen::Vector3d, 4> corners =
      BandCorners(0.0, 0.0, 2.5 + 3.0 * uniform(rng), 0.0);
  for (Eigen::Vector3d& p : corners) {
    p = RotationZ3(yaw) * p + Eigen::Vector3d(fx, fy, 0.0);
  }
  return corners;
}

// The exposure at time t, the vehicle at x: its true and measured poses,
// and the groups of bands reconstructed there (the street's bands it fully
// sees, unless missed or hidden, and perhaps a false band).
void ObserveExposure(const SyntheticSceneOptions& options,
                     const std::vector<StreetBand>& street, double t, double x,
                     int64_t exposure_id, int64_t* band_id, SceneRandom* random,
                     SyntheticScene* scene) {
  std::mt19937& rng = random->rng;
  std::uniform_real_distribution<double>& uniform = random->uniform;
  const Eigen::Matrix3d R_true = EastboundEnuFromBody();
  Pose truth;
  truth.q_enu_body = Eigen::Quaterniond(R_true);
  truth.p_enu = Eigen::Vector3d(x, options.lane_y_m, kBodyHeightM);
  const Pose measured = MeasuredPoseAt(options, truth, R_true, t);
  scene->true_pose[exposure_id] = truth;
  scene->exposures.push_back({exposure_id, t, measured});

  std::map<int, CrossingObservation> groups;
  auto observe = [&](int group, const std::array<Eigen::Vector3d, 4>& enu,
                     const std::pair<std::string, int>* key) {
    CrossingObservation& obs = groups[group];
    obs.exposure_id = exposure_id;
    obs.group_id = group;
    obs.time_s = t;
    obs.pose = measured;
    obs.sd_horizontal_m = 0.05;
    obs.bands.push_back(ObservedBandOf(options, R_true, truth.p_enu, enu,
                                       (*band_id)++, random));
    if (key != nullptr) {
      scene->band_truth[{exposure_id, obs.bands.back().band_id}] = *key;
    }
  };
  for (const StreetBand& band : street) {
    if (!FullyVisible(scene->rig, scene->rig.stereo_pairs[0], truth,
                      band.corners, options.max_range_m, 5.0)) {
      continue;
    }
    if (uniform(rng) < options.miss_probability) continue;
    if (x < band.hidden_beyond_x) continue;  // behind a parked vehicle
    const std::pair<std::string, int> key(band.crossing_id, band.band);
    observe(band.group, band.corners, &key);
  }
  if (uniform(rng) < options.false_band_probability) {
    const std::array<Eigen::Vector3d, 4> corners =
        FalseBandCorners(options, x, random);
    // Either alone or inside the group of a crossing seen.
    const int group = !groups.empty() && uniform(rng) < 0.5
                          ? groups.begin()->first
                          : 900 + static_cast<int>(exposure_id % 7);
    observe(group, corners, nullptr);
  }
  for (auto& [group, obs] : groups) {
    scene->observations.push_back(std::move(obs));
  }
}

}  // namespace

MatchInput SyntheticScene::Input(const RoadmarkIndex& index) const {
  MatchInput input;
  input.observations = observations;
  input.exposures = exposures;
  input.index = &index;
  input.rig = &rig;
  return input;
}

std::vector<SyntheticCrossingSpec> RandomCrossings(int count, double spacing_m,
                                                   int seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> bands(4, 12);
  std::uniform_real_distribution<double> length(2.5, 6.0);
  std::uniform_real_distribution<double> skew(-0.4, 0.4);
  std::vector<SyntheticCrossingSpec> crossings;
  for (int i = 0; i < count; ++i) {
    SyntheticCrossingSpec spec;
    spec.x_m = spacing_m * i;
    spec.bands = bands(rng);
    spec.band_length_m = length(rng);
    if (i % 3 == 2) spec.skew_rad = skew(rng);
    crossings.push_back(spec);
  }
  return crossings;
}

SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options) {
  SyntheticScene scene;
  SceneRandom random(options.seed);
  scene.rig =
      ForwardStereoRig(options.horizontal_fov_deg, options.pitch_down_deg);
  // Bands: truth (the street) and the database.
  const std::vector<StreetBand> street =
      PaintCrossings(options, &random, &scene);
  double last_x = 0.0;
  for (const SyntheticCrossingSpec& spec : options.crossings) {
    last_x = std::max(last_x, spec.x_m);
  }
  // Drive.
  const double end_x = options.end_x_m != 0.0 ? options.end_x_m : last_x + 40.0;
  int64_t band_id = 1;
  int64_t exposure_id = 1000;
  for (double t = 0.0;; t += options.exposure_interval_s) {
    const double x = options.start_x_m + options.speed_m_per_s * t;
    if (x > end_x) break;
    exposure_id += 3;  // labels, not indices
    ObserveExposure(options, street, t, x, exposure_id, &band_id, &random,
                    &scene);
  }
  return scene;
}

SyntheticSceneOptions RandomStreetScene(int seed, int crossings,
                                        double spacing_m) {
  SyntheticSceneOptions options;
  options.seed = seed;
  options.crossings = RandomCrossings(crossings, spacing_m, seed);
  return options;
}

bool HasFault(const MatchResult& result, FaultKind kind,
              const std::string& crossing_id, int band) {
  for (const DatabaseFault& fault : result.faults) {
    if (fault.kind == kind && fault.crossing_id == crossing_id &&
        (band == 0 || fault.band == band)) {
      return true;
    }
  }
  return false;
}

const UnrecognisedMark* FindUnrecognised(const MatchResult& result,
                                         const std::string& crossing_id,
                                         int band) {
  for (const UnrecognisedMark& mark : result.unrecognised) {
    if (mark.crossing_id == crossing_id && mark.band == band) return &mark;
  }
  return nullptr;
}

MatchScore ScoreMatches(const SyntheticScene& scene,
                        const std::vector<VertexMatch>& matches) {
  std::map<std::pair<int64_t, int64_t>, const ObservedBand*> bands;
  for (const CrossingObservation& obs : scene.observations) {
    for (const ObservedBand& band : obs.bands) {
      bands[{obs.exposure_id, band.band_id}] = &band;
    }
  }
  MatchScore score;
  std::set<std::string> matched;
  for (const VertexMatch& m : matches) {
    const auto band = bands.find({m.exposure_id, m.band_id});
    const auto truth = scene.truth.find({m.crossing_id, m.band});
    if (band == bands.end() || truth == scene.truth.end() || m.vertex < 0 ||
        m.vertex > 3 || m.db_vertex < 0 || m.db_vertex > 3) {
      ++score.wrong;
      continue;
    }
    const Pose& pose = scene.true_pose.at(m.exposure_id);
    const Eigen::Vector3d p =
        pose.q_enu_body * band->second->p_body[m.vertex] + pose.p_enu;
    if ((p - truth->second[m.db_vertex]).norm() > 0.2) {
      ++score.wrong;
    } else {
      ++score.right;
      matched.insert(m.crossing_id);
    }
  }
  std::set<std::string> in_database;
  for (const RoadmarkBand& band : scene.database.bands) {
    in_database.insert(band.crossing_id);
  }
  std::set<std::string> eligible;
  for (const auto& [key, truth] : scene.band_truth) {
    if (in_database.count(truth.first)) eligible.insert(truth.first);
  }
  score.crossings_eligible.assign(eligible.begin(), eligible.end());
  for (const std::string& id : matched) {
    if (eligible.count(id)) score.crossings_matched.push_back(id);
  }
  return score;
}

int WriteSyntheticReconstruction(const std::string& survey_folder,
                                 const std::string& results_folder, int seed,
                                 double vertex_noise_m, double max_range_m) {
  SurveyLoadOptions load;
  load.load_roadmarks = false;
  const Survey survey = LoadSurvey(survey_folder, load);
  const std::string truth_folder = survey.PathOf("truth");
  const Trajectory truth(ReadTrajectorySamples(truth_folder + "/trajectory.csv",
                                               "truth/trajectory.csv"),
                         survey.frame);
  const RoadmarkDatabase bands = ReadRoadmarks(
      truth_folder + "/roadmarks.geojson", "truth/roadmarks.geojson");
  std::vector<std::array<Eigen::Vector3d, 4>> enu(bands.bands.size());
  std::map<std::string, int> group_of;
  for (size_t b = 0; b < bands.bands.size(); ++b) {
    for (int k = 0; k < 4; ++k) {
      enu[b][k] = survey.frame.EnuFromGeodetic(bands.bands[b].corners[k]);
    }
    group_of.emplace(bands.bands[b].crossing_id,
                     static_cast<int>(group_of.size()) + 1);
  }
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> start(0, 3);
  std::vector<ReconstructedVertex> vertices;
  int64_t band_id = 1;
  int written = 0;
  for (const Exposure& exposure : survey.exposures.exposures) {
    Pose pose;
    if (!truth.InterpolatePose(exposure.time, &pose)) continue;
    for (size_t p = 0; p < survey.rig.stereo_pairs.size(); ++p) {
      const std::array<int, 2>& pair = survey.rig.stereo_pairs[p];
      if (exposure.image_of_camera[pair[0]] < 0 ||
          exposure.image_of_camera[pair[1]] < 0) {
        continue;
      }
      for (size_t b = 0; b < enu.size(); ++b) {
        if (!FullyVisible(survey.rig, pair, pose, enu[b], max_range_m, 5.0)) {
          continue;
        }
        const int first = start(rng);
        for (int k = 0; k < 4; ++k) {
          ReconstructedVertex v;
          v.exposure_id = exposure.exposure_id;
          v.pair = static_cast<int>(p);
          v.band_id = band_id;
          v.group_id = group_of[bands.bands[b].crossing_id];
          v.vertex = k;
          const Eigen::Vector3d corner = enu[b][(first + k) % 4];
          v.p_body = pose.q_enu_body.conjugate() * (corner - pose.p_enu) +
                     vertex_noise_m *
                         Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
          v.covariance_body =
              Eigen::Matrix3d::Identity() * vertex_noise_m * vertex_noise_m;
          v.score = 0.9;
          vertices.push_back(v);
        }
        ++band_id;
        ++written;
      }
    }
  }
  std::filesystem::create_directories(results_folder);
  WriteReconstructedBands(
      vertices, {"synthetic reconstruction from truth (registration tests)"},
      results_folder + "/" + kReconstructedBandsFile);
  return written;
}

}  // namespace zebrageo
