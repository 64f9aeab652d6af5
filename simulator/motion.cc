#include "simulator/motion.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "simulator/gnss_outage.h"
#include "simulator/noise.h"
#include "survey/math_util.h"

namespace zebrageo::sim {
namespace {

// Half the distance between the wheels, for the roll on the camber.
constexpr double kHalfTrackM = 0.8;

enum Purpose : uint64_t {
  kSpeedSeed = 20,
  kSuspensionSeed = 21,
  kDriftSeed = 22,
  // 23: the GNSS outage (gnss_outage.cc)
  kExposureSeed = 24,
  kRigSeed = 25,
  kMultipathSeed = 26,
  kJitterSeed = 27,
};

// The cross-track switches of a multipath error: num_multipath_switches
// places along the drive, the sign alternating (the error switches to a
// new level and back), in order of s.
std::vector<MultipathSwitch> DrawMultipathSwitches(
    const SimulationOptions& options, const World& world) {
  std::mt19937_64 rng(SubSeed(options.seed, kMultipathSeed));
  std::vector<MultipathSwitch> switches;
  for (int i = 0; i < options.num_multipath_switches; ++i) {
    MultipathSwitch m;
    m.s_m = Uniform(&rng, world.s_drive_start, world.s_drive_end);
    m.length_m = options.multipath_switch_length_m * Uniform(&rng, 0.5, 1.0);
    m.cross_track_m = options.multipath_jump_m * Uniform(&rng, 0.7, 1.3);
    switches.push_back(m);
  }
  std::sort(switches.begin(), switches.end(),
            [](const MultipathSwitch& a, const MultipathSwitch& b) {
              return a.s_m < b.s_m;
            });
  const double first_sign = Bernoulli(&rng, 0.5) ? 1.0 : -1.0;
  for (size_t i = 0; i < switches.size(); ++i) {
    switches[i].cross_track_m *= (i % 2 == 0 ? first_sign : -first_sign);
  }
  return switches;
}

// The cross-track error of the switches at road position s.
double MultipathError(const std::vector<MultipathSwitch>& switches, double s) {
  double error = 0.0;
  for (const MultipathSwitch& m : switches) {
    error += m.cross_track_m *
             SmoothStep(m.s_m - 0.5 * m.length_m, m.s_m + 0.5 * m.length_m, s);
  }
  return error;
}

// A smooth random signal: a sum of sinusoids with periods in
// [min_period, 4 min_period], scaled so that its peak over `times` is 1.
class SmoothSignal {
 public:
  SmoothSignal(double min_period_s, std::mt19937_64* rng) {
    for (int i = 0; i < 4; ++i) {
      Wave w;
      w.amplitude = Uniform(rng, 0.3, 1.0);
      w.omega = 2.0 * kPi / (min_period_s * Uniform(rng, 1.0, 4.0));
      w.phase = Uniform(rng, 0.0, 2.0 * kPi);
      waves_.push_back(w);
    }
  }
  void Normalise(const std::vector<double>& times) {
    double peak = 0.0;
    for (double t : times) peak = std::max(peak, std::abs(Raw(t)));
    scale_ = peak > 0.0 ? 1.0 / peak : 0.0;
  }
  double operator()(double t) const { return scale_ * Raw(t); }

 private:
  struct Wave {
    double amplitude, omega, phase;
  };
  double Raw(double t) const {
    double sum = 0.0;
    for (const Wave& w : waves_)
      sum += w.amplitude * std::sin(w.omega * t + w.phase);
    return sum;
  }
  std::vector<Wave> waves_;
  double scale_ = 1.0;
};

// A drift component: constant part (bias_share of the peak, random sign)
// plus a smooth variation; |value| <= peak.
class Drift {
 public:
  Drift(double peak, double bias_share, double min_period_s,
        std::mt19937_64* rng)
      : peak_(peak),
        bias_(bias_share * (Bernoulli(rng, 0.5) ? 1.0 : -1.0)),
        variation_share_(1.0 - bias_share),
        signal_(min_period_s, rng) {}
  void Normalise(const std::vector<double>& times) { signal_.Normalise(times); }
  double operator()(double t) const {
    return peak_ * (bias_ + variation_share_ * signal_(t));
  }

 private:
  double peak_;
  double bias_;
  double variation_share_;
  SmoothSignal signal_;
};

Eigen::Matrix3d GeometricRotationEnuBody(double theta, double pitch,
                                         double roll) {
  Attitude attitude;
  attitude.roll = roll;
  attitude.pitch = pitch;
  attitude.heading = 0.5 * kPi - theta;  // compass heading of the tangent
  return RotationEnuFromNed() * RotationNedFromBody(attitude);
}

// The speed profile around vehicle_speed_mps, and the lateral wander in the
// lane: both drawn from the speed generator, in this order.
struct SpeedProfile {
  SmoothSignal speed_wave;
  SmoothSignal wander;
  double vehicle_speed_mps;
  double speed_variation;

  double Speed(double t) const {
    return vehicle_speed_mps * (1.0 + speed_variation * speed_wave(t));
  }
};

SpeedProfile DrawSpeedProfile(const SimulationOptions& options) {
  std::mt19937_64 speed_rng(SubSeed(options.seed, kSpeedSeed));
  SmoothSignal speed_wave(25.0, &speed_rng);
  SmoothSignal wander(12.0, &speed_rng);
  std::vector<double> probe_times;
  for (double t = 0.0; t < 4000.0; t += 1.0) probe_times.push_back(t);
  speed_wave.Normalise(probe_times);
  wander.Normalise(probe_times);
  return {speed_wave, wander, options.vehicle_speed_mps,
          options.speed_variation};
}

DriveSamples SampleDrive(const World& world, const SpeedProfile& speed,
                         double dt) {
  DriveSamples drive;
  double s = world.s_drive_start;
  double t_rel = 0.0;
  for (int k = 0;; ++k) {
    t_rel = k * dt;
    drive.times.push_back(t_rel);
    drive.s_of.push_back(s);
    if (s >= world.s_drive_end) break;
    s += 0.5 * (speed.Speed(t_rel) + speed.Speed(t_rel + dt)) * dt;
  }
  return drive;
}

// Suspension: two incommensurate sinusoids per axis, and heave.
class Suspension {
 public:
  explicit Suspension(const SimulationOptions& options)
      : roll_deg_(options.suspension_roll_deg),
        pitch_deg_(options.suspension_pitch_deg),
        f_(options.suspension_frequency_hz) {
    std::mt19937_64 susp_rng(SubSeed(options.seed, kSuspensionSeed));
    for (double& p : phase_) p = Uniform(&susp_rng, 0.0, 2.0 * kPi);
  }
  double Roll(double t) const {
    return DegToRad(roll_deg_) *
           (std::sin(2 * kPi * f_ * t + phase_[0]) +
            0.4 * std::sin(2 * kPi * 1.63 * f_ * t + phase_[1])) /
           1.4;
  }
  double Pitch(double t) const {
    return DegToRad(pitch_deg_) *
           (std::sin(2 * kPi * 0.83 * f_ * t + phase_[2]) +
            0.4 * std::sin(2 * kPi * 1.37 * f_ * t + phase_[3])) /
           1.4;
  }
  double Heave(double t) const {
    return 0.008 * std::sin(2 * kPi * 1.1 * f_ * t + phase_[4]);
  }

 private:
  double roll_deg_;
  double pitch_deg_;
  double f_;
  double phase_[6];
};

// The INS drift: position along and across the road and vertical, then
// heading, roll and pitch, drawn from the drift generator in this order.
struct InsDrift {
  Drift along;
  Drift across;
  Drift vertical;
  Drift heading_error;
  Drift roll_error;
  Drift pitch_error;
};

InsDrift DrawInsDrift(const SimulationOptions& options,
                      const std::vector<double>& times) {
  std::mt19937_64 drift_rng(SubSeed(options.seed, kDriftSeed));
  const double bias = options.drift_bias_share;
  const double period = options.drift_period_s;
  Drift along(options.drift_along_track_m, bias, period, &drift_rng);
  Drift across(options.drift_cross_track_m, bias, period, &drift_rng);
  Drift vertical(options.drift_vertical_m, bias, period, &drift_rng);
  Drift heading_error(DegToRad(options.heading_drift_deg), 0.3, period,
                      &drift_rng);
  Drift roll_error(DegToRad(options.tilt_drift_deg), 0.3, period, &drift_rng);
  Drift pitch_error(DegToRad(options.tilt_drift_deg), 0.3, period, &drift_rng);
  for (Drift* d : {&along, &across, &vertical, &heading_error, &roll_error,
                   &pitch_error}) {
    d->Normalise(times);
  }
  return {along, across, vertical, heading_error, roll_error, pitch_error};
}

// Sample-rate jitter: AR(1) per axis, its step sized for the direction of
// travel (speed * dt per sample) to depart from the heading by
// jitter_direction_deg RMS.
class Jitter {
 public:
  Jitter(const SimulationOptions& options, double dt)
      : rng_(SubSeed(options.seed, kJitterSeed)),
        step_m_(options.vehicle_speed_mps * dt *
                std::tan(DegToRad(options.jitter_direction_deg))),
        decay_(std::exp(-dt / options.jitter_correlation_s)) {}
  bool active() const { return step_m_ > 0.0; }
  // The offset of the next sample.
  const Eigen::Vector3d& Next() {
    jitter_ = decay_ * jitter_ + Eigen::Vector3d(Gaussian(&rng_, step_m_),
                                                 Gaussian(&rng_, step_m_),
                                                 Gaussian(&rng_, step_m_));
    return jitter_;
  }

 private:
  std::mt19937_64 rng_;
  double step_m_;
  double decay_;
  Eigen::Vector3d jitter_ = Eigen::Vector3d::Zero();
};

// The vehicle's true pose at time t from the start of the drive, at road
// position s: lateral wander in the lane and the yaw it implies, pitch from
// the grade, roll from the camber, plus the suspension.
struct TruePose {
  Eigen::Matrix3d R_enu_body;
  Eigen::Vector3d p_enu;
};

TruePose TruePoseAt(const SimulationOptions& options, const World& world,
                    const SpeedProfile& speed, const Suspension& suspension,
                    double t, double sk) {
  const Road& road = world.road;
  const double l = LaneOffsetAt(world, sk) + 0.08 * speed.wander(t);
  const double dl_dt =
      0.08 * (speed.wander(t + 0.01) - speed.wander(t - 0.01)) / 0.02;
  // Lane changes (issue 52) turn the vehicle by atan(dl/ds).
  const double theta = road.Heading(sk) + std::atan2(dl_dt, speed.Speed(t)) +
                       std::atan(LaneOffsetSlopeAt(world, sk));
  const double pitch = std::atan(road.Grade(sk)) + suspension.Pitch(t);
  const double roll = std::atan2(road.Height(sk, l + kHalfTrackM) -
                                     road.Height(sk, l - kHalfTrackM),
                                 2.0 * kHalfTrackM) +
                      suspension.Roll(t);
  TruePose pose;
  pose.R_enu_body = GeometricRotationEnuBody(theta, pitch, roll);
  pose.p_enu =
      road.SurfacePoint(sk, l) +
      pose.R_enu_body * Eigen::Vector3d(0.0, 0.0, -options.imu_height_m) +
      Eigen::Vector3d(0.0, 0.0, suspension.Heave(t));
  return pose;
}

// The position error of a sample, and how far into the outage it is with
// the heading error the outage adds.
struct SampleError {
  Eigen::Vector3d position;
  double outage_fraction = 0.0;
  double extra_heading = 0.0;
};

// Drift in the road frame at the vehicle, multipath, jitter, outage growth,
// jump at GNSS return.
SampleError SampleErrorAt(const SimulationOptions& options, const Road& road,
                          const InsDrift& drift,
                          const std::vector<MultipathSwitch>& switches,
                          const Outage& outage, Jitter* jitter, int k, double t,
                          double sk) {
  const Eigen::Vector2d tangent = road.Tangent(sk);
  const Eigen::Vector2d normal = road.LeftNormal(sk);
  const Eigen::Vector2d horizontal =
      drift.along(t) * tangent + drift.across(t) * normal;
  SampleError sample;
  Eigen::Vector3d& error = sample.position;
  error = Eigen::Vector3d(horizontal.x(), horizontal.y(), drift.vertical(t));
  if (!switches.empty()) {
    error.head<2>() += MultipathError(switches, sk) * normal;
  }
  if (jitter->active()) error += jitter->Next();
  if (outage.active && t >= outage.begin && t < outage.end) {
    sample.outage_fraction = (t - outage.begin) / (outage.end - outage.begin);
    if (options.outage_ins_drift) {
      error += outage.ins_error[k];
      sample.extra_heading =
          DegToRad(options.outage_heading_drift_deg) * sample.outage_fraction;
    } else {
      error += options.outage_drift_m * sample.outage_fraction *
               sample.outage_fraction * outage.direction;
      sample.extra_heading =
          DegToRad(options.heading_drift_deg) * sample.outage_fraction;
    }
  }
  if (outage.active && t >= outage.end) {
    error += options.gnss_return_jump_m *
             std::exp(-(t - outage.end) / options.gnss_return_decay_s) *
             outage.jump_direction;
  }
  return sample;
}

// The measured sample: the true one moved by the errors, with the
// standard deviations the INS reports (growing through the outage).
TrajectorySample MeasuredSampleOf(const SimulationOptions& options,
                                  const LocalFrame& frame,
                                  const TrajectorySample& truth,
                                  const Eigen::Vector3d& p_enu,
                                  const SampleError& error,
                                  const Eigen::Vector3d& attitude_error) {
  TrajectorySample measured;
  measured.time = truth.time;
  measured.position = frame.GeodeticFromEnu(p_enu + error.position);
  measured.attitude.roll = truth.attitude.roll + attitude_error.x();
  measured.attitude.pitch = truth.attitude.pitch + attitude_error.y();
  measured.attitude.heading = truth.attitude.heading + attitude_error.z();
  const double grow = options.outage_sd_growth_m * error.outage_fraction;
  measured.sd_enu_m = Eigen::Vector3d(options.reported_sd_horizontal_m + grow,
                                      options.reported_sd_horizontal_m + grow,
                                      options.reported_sd_vertical_m + grow);
  measured.sd_attitude_rad = Eigen::Vector3d(options.reported_sd_tilt_deg,
                                             options.reported_sd_tilt_deg,
                                             options.reported_sd_heading_deg) *
                             DegToRad(1.0);
  return measured;
}

// Exposures: every exposure_spacing_m +- jitter of road, times rounded to
// 0.1 ms; ids start at 1000 with occasional gaps.
std::vector<ExposureEvent> DrawExposures(const SimulationOptions& options,
                                         const World& world,
                                         const DriveSamples& drive, double dt,
                                         double t0) {
  const std::vector<double>& times = drive.times;
  const std::vector<double>& s_of = drive.s_of;
  const int n = static_cast<int>(times.size());
  const double duration = times.back();
  std::mt19937_64 exposure_rng(SubSeed(options.seed, kExposureSeed));
  std::vector<ExposureEvent> exposures;
  int64_t id = 1000;
  double next = world.s_drive_start + 1.0;
  int k = 0;
  while (true) {
    while (k + 1 < n && s_of[k + 1] < next) ++k;
    if (k + 1 >= n) break;
    const double u = (next - s_of[k]) / (s_of[k + 1] - s_of[k]);
    double t = std::round((times[k] + u * dt) * 1e4) / 1e4;
    t = std::clamp(t, times.front() + 1e-4, duration - 1e-4);
    exposures.push_back({id, t0 + t, next});
    id += Bernoulli(&exposure_rng, 0.05) ? UniformInt(&exposure_rng, 2, 6) : 1;
    next += options.exposure_spacing_m +
            Uniform(&exposure_rng, -options.exposure_spacing_jitter_m,
                    options.exposure_spacing_jitter_m);
  }
  return exposures;
}

}  // namespace

VehicleMotion SimulateMotion(const SimulationOptions& options,
                             const World& world, const LocalFrame& frame) {
  const double dt = 1.0 / options.trajectory_rate_hz;
  const SpeedProfile speed = DrawSpeedProfile(options);
  const DriveSamples drive = SampleDrive(world, speed, dt);
  const int n = static_cast<int>(drive.times.size());
  const Suspension suspension(options);
  const InsDrift drift = DrawInsDrift(options, drive.times);
  Outage outage = DrawOutage(options);
  PlaceOutage(options, world, drive, &outage);
  std::vector<TruePose> poses;
  poses.reserve(n);
  std::vector<Eigen::Vector3d> p_enu;
  p_enu.reserve(n);
  for (int k = 0; k < n; ++k) {
    poses.push_back(TruePoseAt(options, world, speed, suspension,
                               drive.times[k], drive.s_of[k]));
    p_enu.push_back(poses.back().p_enu);
  }
  IntegrateInsDrift(options, drive, p_enu, &outage);
  const double t0 = options.start_time_s;
  VehicleMotion motion;
  if (outage.active) {
    motion.outage_begin_time = t0 + outage.begin;
    motion.outage_end_time = t0 + outage.end;
  }
  motion.multipath_switches = DrawMultipathSwitches(options, world);
  Jitter jitter(options, dt);

  motion.truth.reserve(n);
  motion.measured.reserve(n);
  for (int k = 0; k < n; ++k) {
    const double t = drive.times[k];
    const double sk = drive.s_of[k];
    const TruePose& pose = poses[k];
    TrajectorySample truth;
    truth.time = t0 + t;
    truth.position = frame.GeodeticFromEnu(pose.p_enu);
    truth.attitude =
        frame.AttitudeFromRotationEnuBody(truth.position, pose.R_enu_body);
    motion.truth.push_back(truth);
    motion.s_m.push_back(sk);

    const SampleError error =
        SampleErrorAt(options, world.road, drift, motion.multipath_switches,
                      outage, &jitter, k, t, sk);
    const Eigen::Vector3d attitude_error(
        drift.roll_error(t), drift.pitch_error(t),
        drift.heading_error(t) + error.extra_heading);
    motion.measured.push_back(MeasuredSampleOf(
        options, frame, truth, pose.p_enu, error, attitude_error));
    motion.position_error_enu.push_back(error.position);
    motion.attitude_error_rad.push_back(attitude_error);
  }
  motion.exposures = DrawExposures(options, world, drive, dt, t0);
  return motion;
}

Rig MakeRig(const SimulationOptions& options) {
  std::mt19937_64 rng(SubSeed(options.seed, kRigSeed));
  Rig rig;
  const double alpha = DegToRad(options.camera_pitch_down_deg);
  // Camera axes in the body (FRD): x_cam = right, z_cam = forward pitched
  // down by alpha, y_cam = z_cam x x_cam (down-ish). Looking backwards, the
  // image's right is the body's left.
  auto nominal_rotation = [alpha](bool backwards) {
    const double f = backwards ? -1.0 : 1.0;
    Eigen::Matrix3d R;
    R.col(0) = Eigen::Vector3d(0.0, f, 0.0);
    R.col(1) = Eigen::Vector3d(-f * std::sin(alpha), 0.0, std::cos(alpha));
    R.col(2) = Eigen::Vector3d(f * std::cos(alpha), 0.0, std::sin(alpha));
    return R;
  };
  struct Mount {
    const char* name;
    bool backwards;
    double side;  // across the pair's own view: -0.5 left, +0.5 right
  };
  std::vector<Mount> mounts = {{"left", false, -0.5}, {"right", false, 0.5}};
  if (options.rear_pair) {
    mounts.push_back({"rear_left", true, -0.5});
    mounts.push_back({"rear_right", true, 0.5});
  }
  for (size_t c = 0; c < mounts.size(); ++c) {
    const Mount& mount = mounts[c];
    const double f = mount.backwards ? -1.0 : 1.0;
    const double m = DegToRad(options.camera_misalignment_deg);
    const Eigen::Matrix3d misalignment =
        (Eigen::AngleAxisd(Uniform(&rng, -m, m), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(Uniform(&rng, -m, m), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(Uniform(&rng, -m, m), Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    RigCamera camera;
    camera.T_body_cam.linear() =
        nominal_rotation(mount.backwards) * misalignment;
    camera.T_body_cam.translation() =
        Eigen::Vector3d((mount.backwards ? -options.rear_camera_back_m
                                         : options.camera_forward_m) +
                            Uniform(&rng, -0.01, 0.01),
                        f * mount.side * options.stereo_baseline_m +
                            Uniform(&rng, -0.005, 0.005),
                        -(options.camera_height_m - options.imu_height_m));
    const bool first = c % 2 == 0;
    const double scale = first ? 1.0 : Uniform(&rng, 0.995, 1.005);
    const double fx = options.focal_px * scale;
    const double fy = fx * Uniform(&rng, 0.999, 1.001);
    const double cx =
        0.5 * (options.image_width - 1) + Uniform(&rng, -8.0, 8.0);
    const double cy =
        0.5 * (options.image_height - 1) + Uniform(&rng, -8.0, 8.0);
    const double d = first ? 1.0 : Uniform(&rng, 0.97, 1.03);
    camera.camera = Camera(mount.name, options.image_width,
                           options.image_height, fx, fy, cx, cy,
                           {options.k1 * d, options.k2 * d, options.p1 * d,
                            options.p2 * d, options.k3 * d});
    rig.cameras.push_back(camera);
  }
  rig.stereo_pairs.push_back({0, 1});
  if (options.rear_pair) rig.stereo_pairs.push_back({2, 3});
  return rig;
}

}  // namespace zebrageo::sim
