// The GNSS/INS trajectory: samples as in trajectory.csv, their poses in the
// working ENU frame, and interpolation.
//
// Pose convention: T_enu_body maps body (FRD) coordinates into ENU,
// p_enu = q_enu_body * p_body + p_enu_body. Positions are the body (IMU)
// origin. Quaternions are Eigen's (stored x, y, z, w; Hamilton).
// Interpolation (SURVEY_FORMAT.md): linear in position, slerp of the
// body-to-ENU rotation between the two bracketing samples; heading is never
// interpolated as a number.
#ifndef ZEBRAGEO_SURVEY_TRAJECTORY_H_
#define ZEBRAGEO_SURVEY_TRAJECTORY_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "survey/geodesy.h"

namespace zebrageo {

class OutputCrs;

class CrsTransformer;

struct TrajectorySample {
  double time = 0.0;  // seconds, the survey's clock
  Geodetic position;
  Attitude attitude;  // radians
  // Standard deviations the GNSS/INS claims (often optimistic).
  Eigen::Vector3d sd_enu_m = Eigen::Vector3d::Zero();         // e, n, u
  Eigen::Vector3d sd_attitude_rad = Eigen::Vector3d::Zero();  // r, p, h
  int line = 0;  // line in trajectory.csv, for messages; 0: not from a file
};

struct Pose {
  Eigen::Quaterniond q_enu_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();

  Eigen::Isometry3d T_enu_body() const;
  static Pose FromIsometry(const Eigen::Isometry3d& T_enu_body);
};

// Interpolates between two poses, u in [0, 1]: lerp position, slerp rotation.
Pose InterpolatePoses(const Pose& a, const Pose& b, double u);

class Trajectory {
 public:
  Trajectory() = default;
  // Precomputes the ENU pose of every sample in `frame`. Samples must be
  // valid (see ReadTrajectorySamples); CHECKs at least 2 samples and
  // strictly increasing times.
  Trajectory(std::vector<TrajectorySample> samples, const LocalFrame& frame);

  const std::vector<TrajectorySample>& samples() const { return samples_; }
  const std::vector<Pose>& poses() const { return poses_; }
  int size() const { return static_cast<int>(samples_.size()); }
  double start_time() const { return samples_.front().time; }
  double end_time() const { return samples_.back().time; }
  bool Covers(double time) const {
    return time >= start_time() && time <= end_time();
  }

  // Index i of the segment [t_i, t_i+1] holding `time` (the last segment for
  // time == end_time), or -1 outside the span.
  int FindSegment(double time) const;
  // Pose at `time`; false outside the trajectory's span.
  bool InterpolatePose(double time, Pose* pose) const;

 private:
  std::vector<TrajectorySample> samples_;
  std::vector<Pose> poses_;
};

// A hole in the trajectory: an interval between consecutive samples much
// longer than its median interval (a lost INS solution, cut rows). A pose
// interpolated inside it is a guess, and nothing measured across it (a
// velocity, a jump, a chord) is the vehicle's motion.
struct TrajectoryGap {
  int before = 0;           // index of the last sample before the gap
  double start_time = 0.0;  // of samples[before]
  double end_time = 0.0;    // of samples[before + 1]
  double duration() const { return end_time - start_time; }
};

struct TrajectoryGapOptions {
  // An interval is a gap when longer than `factor` median intervals and at
  // least `min_duration_s`: a dropped sample or two of a 100 Hz solution is
  // not a gap, a second without one is.
  double factor = 5.0;
  double min_duration_s = 0.25;

  std::string Check() const;
};

// Median interval between consecutive `times` (increasing); 0 for fewer
// than 2 times.
double MedianSampleInterval(const std::vector<double>& times);
// The gaps of increasing `times`, in time order.
std::vector<TrajectoryGap> FindTrajectoryGaps(
    const std::vector<double>& times,
    const TrajectoryGapOptions& options = TrajectoryGapOptions());
// The sample times of a trajectory.
std::vector<double> SampleTimes(const std::vector<TrajectorySample>& samples);

// Reads trajectory.csv (columns time,lat,lon,h,roll,pitch,heading,sd_e,sd_n,
// sd_u,sd_roll,sd_pitch,sd_heading; degrees in the file). Throws InputError:
// unreadable, missing columns, short rows, non-numbers, NaN/inf, latitude out
// of [-90, 90], longitude out of [-180, 180], negative sd, fewer than 2
// samples, times not strictly increasing (duplicates included).
std::vector<TrajectorySample> ReadTrajectorySamples(
    const std::string& path, const std::string& display_name);
// The same file with positions in another CRS (survey.yaml's
// `trajectory_crs`): columns x, y, z in place of lat, lon, h, in the CRS's
// units and east-first order (survey/crs.h: easting, northing, height; or
// longitude, latitude, height). Attitude, heading from true north, and the
// standard deviations are as in trajectory.csv. Positions are converted to
// WGS84 as they are read; a point PROJ cannot convert is an InputError on
// its line.
std::vector<TrajectorySample> ReadTrajectorySamplesInCrs(
    const std::string& path, const std::string& display_name,
    const CrsTransformer& crs);
std::vector<TrajectorySample> ParseTrajectorySamples(
    const std::string& text, const std::string& display_name);
// Writes samples in the same format, angles normalised (heading [0, 360),
// roll (-180, 180], pitch [-90, 90]), atomically.
void WriteTrajectorySamples(const std::vector<TrajectorySample>& samples,
                            const std::string& path,
                            const OutputCrs* crs = nullptr);

// The sample for an ENU pose (inverse of the frame chain), keeping `time`
// and the given standard deviations.
TrajectorySample SampleFromPose(double time, const Pose& pose,
                                const LocalFrame& frame,
                                const Eigen::Vector3d& sd_enu_m,
                                const Eigen::Vector3d& sd_attitude_rad);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_TRAJECTORY_H_
