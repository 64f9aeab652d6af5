#include "tests/support/synthetic_survey.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <set>

#include "survey/math_util.h"
#include "survey/survey.h"

namespace zebrageo {
namespace {

constexpr double kDegToRad = kPi / 180.0;

// The road: heading and height as smooth functions of arc length s.
struct Road {
  double heading0 = 0.6;  // rad, ENU angle of the tangent from east
  double Theta(double s) const {
    return heading0 + 0.35 * std::sin(s / 260.0) + 0.2 * std::sin(s / 97.0);
  }
  double Height(double s) const {
    return 3.0 * std::sin(s / 400.0) + 0.8 * std::sin(s / 150.0);
  }
  double Grade(double s) const {
    return 3.0 / 400.0 * std::cos(s / 400.0) +
           0.8 / 150.0 * std::cos(s / 150.0);
  }
};

// Centreline positions, integrated on a fine grid of arc length.
class Centreline {
 public:
  Centreline(const Road& road, double length) : road_(road) {
    const int n = static_cast<int>(length / kStep) + 2;
    xy_.resize(n);
    xy_[0] = Eigen::Vector2d::Zero();
    for (int i = 1; i < n; ++i) {
      const double theta = road.Theta((i - 0.5) * kStep);
      xy_[i] = xy_[i - 1] +
               kStep * Eigen::Vector2d(std::cos(theta), std::sin(theta));
    }
  }
  // ENU point at arc length s, lateral offset l (positive to the left), on
  // the road surface.
  Eigen::Vector3d Point(double s, double l) const {
    const double x = s / kStep;
    const int i =
        std::clamp(static_cast<int>(x), 0, static_cast<int>(xy_.size()) - 2);
    const double u = x - i;
    const Eigen::Vector2d c = (1.0 - u) * xy_[i] + u * xy_[i + 1];
    const double theta = road_.Theta(s);
    const Eigen::Vector2d left(-std::sin(theta), std::cos(theta));
    const Eigen::Vector2d p = c + l * left;
    return Eigen::Vector3d(p.x(), p.y(), road_.Height(s));
  }

 private:
  static constexpr double kStep = 0.05;
  Road road_;
  std::vector<Eigen::Vector2d> xy_;
};

// A smooth zero-mean signal with |value| <= 1: sum of sinusoids of periods
// >= min_period, normalised by the sum of amplitudes.
class SmoothSignal {
 public:
  SmoothSignal(double min_period, std::mt19937_64* rng) {
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    double total = 0.0;
    for (int i = 0; i < 4; ++i) {
      Wave w;
      w.period = min_period * (1.0 + 3.0 * uniform(*rng));
      w.phase = 2.0 * kPi * uniform(*rng);
      w.amplitude = 0.5 + uniform(*rng);
      total += w.amplitude;
      waves_.push_back(w);
    }
    for (Wave& w : waves_) w.amplitude /= total;
  }
  double operator()(double t) const {
    double sum = 0.0;
    for (const Wave& w : waves_) {
      sum += w.amplitude * std::sin(2.0 * kPi * t / w.period + w.phase);
    }
    return sum;
  }

 private:
  struct Wave {
    double period, phase, amplitude;
  };
  std::vector<Wave> waves_;
};

// A drift component: a constant bias (30 % of the peak) plus a smooth
// variation; |value| <= peak.
class Drift {
 public:
  Drift(double peak, double period, std::mt19937_64* rng)
      : peak_(peak),
        bias_(std::bernoulli_distribution(0.5)(*rng) ? 0.3 : -0.3),
        signal_(period, rng) {}
  double operator()(double t) const {
    return peak_ * (bias_ + 0.7 * signal_(t));
  }

 private:
  double peak_;
  double bias_;
  SmoothSignal signal_;
};

Rig MakeRig() {
  Rig rig;
  const double pitch_down = 20.0 * kDegToRad;
  // Camera axes in the body frame before the pitch: x_cam = right (body y),
  // y_cam = down (body z), z_cam = forward (body x).
  Eigen::Matrix3d base;
  base.col(0) = Eigen::Vector3d::UnitY();
  base.col(1) = Eigen::Vector3d::UnitZ();
  base.col(2) = Eigen::Vector3d::UnitX();
  // Pitch the optical axis down (towards body +z) about the body y axis.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(-pitch_down, Eigen::Vector3d::UnitY()) * base;
  const char* names[2] = {"left", "right"};
  for (int c = 0; c < 2; ++c) {
    RigCamera camera;
    camera.camera =
        Camera(names[c], 1280, 960, 1100.0 + 3.0 * c, 1100.0 + 2.0 * c,
               640.5 - c, 480.25 + c, {-0.15, 0.06, 4e-4, -3e-4, -0.01});
    camera.T_body_cam.linear() = R;
    camera.T_body_cam.translation() =
        Eigen::Vector3d(0.8, c == 0 ? -0.5 : 0.5, -1.5);
    rig.cameras.push_back(camera);
  }
  rig.stereo_pairs.push_back({0, 1});
  return rig;
}

// The drift of the measured trajectory: east, north, up, heading, roll and
// pitch, drawn from `rng` in this order.
struct TrajectoryDrift {
  Drift e, n, u, heading, roll, pitch;
};

TrajectoryDrift DrawTrajectoryDrift(const SyntheticSurveyOptions& options,
                                    std::mt19937_64* rng) {
  Drift drift_e(options.drift_horizontal_m / std::sqrt(2.0),
                options.drift_period_s, rng);
  Drift drift_n(options.drift_horizontal_m / std::sqrt(2.0),
                options.drift_period_s, rng);
  Drift drift_u(options.drift_vertical_m, options.drift_period_s, rng);
  Drift drift_heading(options.heading_drift_deg * kDegToRad,
                      options.drift_period_s, rng);
  Drift drift_roll(options.tilt_drift_deg * kDegToRad, options.drift_period_s,
                   rng);
  Drift drift_pitch(options.tilt_drift_deg * kDegToRad, options.drift_period_s,
                    rng);
  return {drift_e, drift_n, drift_u, drift_heading, drift_roll, drift_pitch};
}

// The true and the measured (drifting) trajectory over `duration` from t0,
// the vehicle at road position 20 m + speed * t.
void AddTrajectorySamples(const SyntheticSurveyOptions& options,
                          const Road& road, const Centreline& centreline,
                          const TrajectoryDrift& drift, double t0,
                          double duration, SyntheticSurvey* survey) {
  const double imu_height = 1.0;
  const int num_samples =
      static_cast<int>(std::ceil(duration * options.trajectory_rate_hz)) + 1;
  const Eigen::Vector3d sd_enu(0.03, 0.03, 0.05);
  const Eigen::Vector3d sd_att(0.01 * kDegToRad, 0.01 * kDegToRad,
                               0.03 * kDegToRad);
  for (int i = 0; i < num_samples; ++i) {
    const double t = i / options.trajectory_rate_hz;
    const double s = 20.0 + options.speed_mps * t;
    const double theta = road.Theta(s);
    Attitude attitude;
    attitude.heading = 0.5 * kPi - theta;
    attitude.pitch = std::atan(road.Grade(s));
    attitude.roll = 0.002 * std::sin(2.0 * kPi * 1.5 * t);
    Pose truth;
    truth.p_enu = centreline.Point(s, 0.0) + Eigen::Vector3d(0, 0, imu_height);
    truth.q_enu_body = Eigen::Quaterniond(RotationEnuFromNed() *
                                          RotationNedFromBody(attitude));
    survey->truth_samples.push_back(
        SampleFromPose(t0 + t, truth, survey->frame, sd_enu, sd_att));
    Pose measured;
    measured.p_enu =
        truth.p_enu + Eigen::Vector3d(drift.e(t), drift.n(t), drift.u(t));
    // Attitude error in the body frame: R_meas = R_true * Exp(error).
    const Eigen::Vector3d error(drift.roll(t), drift.pitch(t),
                                drift.heading(t));
    const double angle = error.norm();
    const Eigen::Quaterniond dq =
        angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, error / angle))
                  : Eigen::Quaterniond::Identity();
    measured.q_enu_body = (truth.q_enu_body * dq).normalized();
    survey->measured_samples.push_back(
        SampleFromPose(t0 + t, measured, survey->frame, sd_enu, sd_att));
  }
}

// Crossings every crossing_spacing_m up to s_end: bands across the road,
// long sides along it, corners counter-clockwise seen from above. The
// database's copy is offset per crossing and noisy per vertex.
void AddCrossings(const SyntheticSurveyOptions& options,
                  const Centreline& centreline, double s_end,
                  std::mt19937_64* rng,
                  std::normal_distribution<double>* normal,
                  SyntheticSurvey* survey) {
  int num_crossings = 0;
  for (double s = 60.0; s < s_end; s += options.crossing_spacing_m) {
    const int crossing = num_crossings++;
    const Eigen::Vector3d offset(options.database_offset_m * (*normal)(*rng),
                                 options.database_offset_m * (*normal)(*rng),
                                 options.database_offset_m * (*normal)(*rng));
    for (int b = 0; b < options.bands_per_crossing; ++b) {
      const double l = (b - 0.5 * (options.bands_per_crossing - 1)) * 1.0;
      const std::array<Eigen::Vector3d, 4> corners = {
          centreline.Point(s - 1.5, l - 0.25),
          centreline.Point(s + 1.5, l - 0.25),
          centreline.Point(s + 1.5, l + 0.25),
          centreline.Point(s - 1.5, l + 0.25)};
      RoadmarkBand truth_band, db_band;
      truth_band.crossing_id = db_band.crossing_id =
          "X" + std::to_string(crossing + 1);
      truth_band.band = db_band.band = b + 1;
      truth_band.sigma_xy_m = db_band.sigma_xy_m = options.database_sigma_xy_m;
      truth_band.sigma_z_m = db_band.sigma_z_m = options.database_sigma_z_m;
      for (int v = 0; v < 4; ++v) {
        truth_band.corners[v] = survey->frame.GeodeticFromEnu(corners[v]);
        const Eigen::Vector3d noisy =
            corners[v] + offset +
            Eigen::Vector3d(options.database_sigma_xy_m * (*normal)(*rng),
                            options.database_sigma_xy_m * (*normal)(*rng),
                            options.database_sigma_z_m * (*normal)(*rng));
        db_band.corners[v] = survey->frame.GeodeticFromEnu(noisy);
      }
      survey->truth_database.bands.push_back(truth_band);
      survey->database.bands.push_back(db_band);
    }
  }
}

// num_exposures exposures of both cameras, exposure_interval_s apart from
// `start`; ids are labels, 7 apart.
ExposureTable ExposuresOf(const SyntheticSurveyOptions& options, double start) {
  ExposureTable table;
  for (int e = 0; e < options.num_exposures; ++e) {
    const double time = start + e * options.exposure_interval_s;
    const int64_t exposure_id = 1000 + 7 * e;
    Exposure exposure;
    exposure.exposure_id = exposure_id;
    exposure.time = time;
    for (int c = 0; c < 2; ++c) {
      ExposureImage image;
      image.exposure_id = exposure_id;
      image.time = time;
      image.camera = c;
      image.image = std::string("images/") + (c == 0 ? "left" : "right") + "/" +
                    std::to_string(exposure_id) + ".png";
      exposure.image_of_camera.push_back(static_cast<int>(table.images.size()));
      table.images.push_back(image);
    }
    table.exposures.push_back(exposure);
  }
  return table;
}

// The observations of point X (ENU) in the images of exposures e to
// e + tie_track_exposures - 1 that see it within 40 m, with pixel noise.
TieTrack TieTrackOf(const SyntheticSurveyOptions& options,
                    const SyntheticSurvey& survey,
                    const Trajectory& truth_trajectory,
                    const Eigen::Vector3d& X, int e, std::mt19937_64* rng,
                    std::normal_distribution<double>* normal) {
  TieTrack track;
  for (int f = e;
       f < std::min(options.num_exposures, e + options.tie_track_exposures);
       ++f) {
    const Exposure& exposure = survey.exposures.exposures[f];
    Pose pose;
    CHECK(truth_trajectory.InterpolatePose(exposure.time, &pose));
    for (int c = 0; c < 2; ++c) {
      const RigCamera& camera = survey.rig.cameras[c];
      const Eigen::Vector3d p_cam =
          (pose.T_enu_body() * camera.T_body_cam).inverse() * X;
      Eigen::Vector2d uv;
      if (p_cam.z() < 2.0 || p_cam.norm() > 40.0 ||
          !camera.camera.Project(p_cam, &uv) ||
          !camera.camera.IsInImage(uv, 5.0)) {
        continue;
      }
      uv += options.tie_noise_px *
            Eigen::Vector2d((*normal)(*rng), (*normal)(*rng));
      track.observations.push_back(
          {exposure.image_of_camera[c], exposure.time, c, uv});
    }
  }
  return track;
}

// Ideal tie points: per exposure, points on the road ahead and on the
// facades, tracked over the next exposures, each placed as triangulated
// with the drifting trajectory.
void AddTiePoints(const SyntheticSurveyOptions& options,
                  const Centreline& centreline,
                  const Trajectory& truth_trajectory, double t0,
                  std::mt19937_64* rng,
                  std::normal_distribution<double>* normal,
                  SyntheticSurvey* survey) {
  const Trajectory measured_trajectory(survey->measured_samples, survey->frame);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int e = 0;
       e < options.num_exposures && options.tie_points_per_exposure > 0; ++e) {
    const double time = survey->exposures.exposures[e].time;
    const double s0 = 20.0 + options.speed_mps * (time - t0);
    Pose true_pose, measured_pose;
    CHECK(truth_trajectory.InterpolatePose(time, &true_pose));
    CHECK(measured_trajectory.InterpolatePose(time, &measured_pose));
    for (int k = 0; k < options.tie_points_per_exposure; ++k) {
      Eigen::Vector3d X;
      if (k % 2 == 0) {  // road surface ahead
        X = centreline.Point(s0 + 6.0 + 14.0 * uniform(*rng),
                             -4.0 + 8.0 * uniform(*rng));
      } else {  // facade
        const double side = uniform(*rng) < 0.5 ? -1.0 : 1.0;
        X = centreline.Point(s0 + 10.0 + 20.0 * uniform(*rng), side * 8.0) +
            Eigen::Vector3d(0, 0, 6.0 * uniform(*rng));
      }
      TieTrack track =
          TieTrackOf(options, *survey, truth_trajectory, X, e, rng, normal);
      if (track.observations.size() < 3) continue;
      // As triangulated with the drifting trajectory.
      track.p_enu =
          measured_pose.T_enu_body() * (true_pose.T_enu_body().inverse() * X);
      survey->tie_tracks.push_back(track);
    }
  }
}

}  // namespace

SyntheticSurvey MakeSyntheticSurvey(const SyntheticSurveyOptions& options) {
  CHECK_GT(options.num_exposures, 1);
  SyntheticSurvey survey;
  survey.rig = MakeRig();
  survey.frame = LocalFrame(Geodetic{
      options.origin_lat_deg, options.origin_lon_deg, options.origin_h_m});
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);

  const double t0 = 302400.0;
  const double margin_s = 2.0;  // trajectory before/after the exposures
  const double duration =
      (options.num_exposures - 1) * options.exposure_interval_s + 2 * margin_s;
  const double length = duration * options.speed_mps + 200.0;
  const Road road;
  const Centreline centreline(road, length);

  const TrajectoryDrift drift = DrawTrajectoryDrift(options, &rng);
  AddTrajectorySamples(options, road, centreline, drift, t0, duration, &survey);
  const Trajectory truth_trajectory(survey.truth_samples, survey.frame);
  const double s_end = 20.0 + options.speed_mps * duration;
  AddCrossings(options, centreline, s_end, &rng, &normal, &survey);
  survey.exposures = ExposuresOf(options, t0 + margin_s);
  IdealObservationOptions observe;
  observe.seed = options.seed + 1000;
  observe.pixel_noise_px = options.pixel_noise_px;
  observe.body_noise_m = options.body_noise_m;
  observe.max_range_m = options.max_range_m;
  MakeIdealObservations(observe, survey.rig, survey.frame, truth_trajectory,
                        survey.exposures, survey.truth_database,
                        survey.database, &survey.vertices, &survey.matches);
  AddTiePoints(options, centreline, truth_trajectory, t0, &rng, &normal,
               &survey);
  return survey;
}

void MakeIdealObservations(const IdealObservationOptions& options,
                           const Rig& rig, const LocalFrame& frame,
                           const Trajectory& truth,
                           const ExposureTable& exposures,
                           const RoadmarkDatabase& truth_bands,
                           const RoadmarkDatabase& database,
                           std::vector<ReconstructedVertex>* vertices,
                           std::vector<VertexMatch>* matches) {
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::set<std::pair<std::string, int>> in_database;
  for (const RoadmarkBand& b : database.bands) {
    in_database.insert({b.crossing_id, b.band});
  }
  struct Band {
    const RoadmarkBand* band;
    int group;
    std::array<Eigen::Vector3d, 4> corners;
  };
  std::vector<Band> bands;
  std::map<std::string, int> group_of;
  for (const RoadmarkBand& b : truth_bands.bands) {
    Band band;
    band.band = &b;
    band.group =
        group_of.emplace(b.crossing_id, static_cast<int>(group_of.size()))
            .first->second;
    for (int v = 0; v < 4; ++v)
      band.corners[v] = frame.EnuFromGeodetic(b.corners[v]);
    bands.push_back(band);
  }
  const int pair_left = rig.stereo_pairs.at(0)[0];
  const int pair_right = rig.stereo_pairs.at(0)[1];
  int64_t band_id = 1;
  for (const Exposure& exposure : exposures.exposures) {
    const int64_t exposure_id = exposure.exposure_id;
    Pose pose;
    if (!truth.InterpolatePose(exposure.time, &pose)) continue;
    const Eigen::Isometry3d T_enu_body = pose.T_enu_body();
    const Eigen::Isometry3d T_body_enu = T_enu_body.inverse();
    const Eigen::Vector3d left_centre =
        T_enu_body * rig.cameras[pair_left].T_body_cam.translation();
    for (const Band& band : bands) {
      const Eigen::Vector3d centre = 0.25 * (band.corners[0] + band.corners[1] +
                                             band.corners[2] + band.corners[3]);
      if ((centre - left_centre).norm() > options.max_range_m) continue;
      std::array<Eigen::Vector2d, 4> uv[2];
      bool visible = true;
      const int cameras[2] = {pair_left, pair_right};
      for (int c = 0; c < 2 && visible; ++c) {
        const RigCamera& camera = rig.cameras[cameras[c]];
        const Eigen::Isometry3d T_cam_enu =
            (T_enu_body * camera.T_body_cam).inverse();
        for (int v = 0; v < 4 && visible; ++v) {
          const Eigen::Vector3d p_cam = T_cam_enu * band.corners[v];
          visible = p_cam.z() > 1.0 &&
                    camera.camera.Project(p_cam, &uv[c][v]) &&
                    camera.camera.IsInImage(uv[c][v], 5.0);
        }
      }
      if (!visible) continue;
      const int rotation = static_cast<int>(band_id % 4);
      const bool matched =
          in_database.count({band.band->crossing_id, band.band->band}) > 0;
      for (int db_vertex = 0; db_vertex < 4; ++db_vertex) {
        ReconstructedVertex vertex;
        vertex.exposure_id = exposure_id;
        vertex.pair = 0;
        vertex.band_id = band_id;
        vertex.group_id = 100 + band.group;
        vertex.vertex = (db_vertex + rotation) % 4;
        vertex.p_body =
            T_body_enu * band.corners[db_vertex] +
            options.body_noise_m *
                Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
        vertex.covariance_body = Eigen::Matrix3d::Identity() *
                                 options.body_noise_m * options.body_noise_m;
        vertex.uv_left =
            uv[0][db_vertex] +
            options.pixel_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        vertex.uv_right =
            uv[1][db_vertex] +
            options.pixel_noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        vertex.score = 0.9;
        vertices->push_back(vertex);
        if (!matched) continue;
        VertexMatch match;
        match.exposure_id = exposure_id;
        match.band_id = band_id;
        match.vertex = vertex.vertex;
        match.crossing_id = band.band->crossing_id;
        match.band = band.band->band;
        match.db_vertex = db_vertex;
        matches->push_back(match);
      }
      ++band_id;
    }
  }
}

void WriteIdealStageOutputs(const IdealObservationOptions& options,
                            const std::string& survey_folder,
                            const std::string& results_folder) {
  const SurveyManifest manifest = ReadManifest(survey_folder);
  auto path_of = [&](const std::string& name) {
    return (std::filesystem::path(survey_folder) / name).string();
  };
  const Rig rig = ReadRig(path_of(manifest.rig), manifest.rig);
  std::vector<TrajectorySample> measured =
      ReadTrajectorySamples(path_of(manifest.trajectory), manifest.trajectory);
  const LocalFrame frame(manifest.origin.value_or(measured.front().position));
  const Trajectory truth(ReadTrajectorySamples(path_of("truth/trajectory.csv"),
                                               "truth/trajectory.csv"),
                         frame);
  const ExposureTable exposures =
      ReadExposures(path_of(manifest.exposures), manifest.exposures, rig);
  const RoadmarkDatabase truth_bands = ReadRoadmarks(
      path_of("truth/roadmarks.geojson"), "truth/roadmarks.geojson");
  const RoadmarkDatabase database =
      ReadRoadmarks(path_of(manifest.roadmarks), manifest.roadmarks);
  std::vector<ReconstructedVertex> vertices;
  std::vector<VertexMatch> matches;
  MakeIdealObservations(options, rig, frame, truth, exposures, truth_bands,
                        database, &vertices, &matches);
  std::filesystem::create_directories(results_folder);
  WriteReconstructedBands(vertices,
                          {"ideal observations from truth (adjustment tests)"},
                          results_folder + "/" + kReconstructedBandsFile);
  WriteMatches(matches, {"ideal matches from truth (adjustment tests)"},
               results_folder + "/" + kMatchesFile);
}

void WriteSyntheticSurvey(const SyntheticSurvey& survey,
                          const std::string& survey_folder,
                          const std::string& results_folder) {
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(survey_folder) / "truth");
  fs::create_directories(results_folder);
  SurveyManifest manifest;
  manifest.name = "synthetic";
  manifest.origin = survey.frame.origin();
  WriteManifest(manifest, survey_folder + "/survey.yaml");
  WriteRig(survey.rig, survey_folder + "/rig.yaml");
  WriteTrajectorySamples(survey.measured_samples,
                         survey_folder + "/trajectory.csv");
  WriteExposures(survey.exposures, survey.rig,
                 survey_folder + "/exposures.csv");
  WriteRoadmarks(survey.database, survey_folder + "/roadmarks.geojson");
  WriteTrajectorySamples(survey.truth_samples,
                         survey_folder + "/truth/trajectory.csv");
  WriteRoadmarks(survey.truth_database,
                 survey_folder + "/truth/roadmarks.geojson");
  WriteReconstructedBands(survey.vertices, {"synthetic: ideal reconstruction"},
                          results_folder + "/" + kReconstructedBandsFile);
  WriteMatches(survey.matches, {"synthetic: true matches"},
               results_folder + "/" + kMatchesFile);
}

AdjustmentInput SyntheticAdjustmentInput(const SyntheticSurvey& survey,
                                         const Trajectory& trajectory) {
  AdjustmentInput input;
  input.rig = &survey.rig;
  input.frame = &survey.frame;
  input.trajectory = &trajectory;
  input.exposures = &survey.exposures;
  input.roadmarks = &survey.database;
  input.vertices = &survey.vertices;
  input.matches = &survey.matches;
  if (!survey.tie_tracks.empty()) input.tie_tracks = &survey.tie_tracks;
  return input;
}

}  // namespace zebrageo
