#include "survey/trajectory.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

#include "survey/atomic_file.h"
#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"
#include "survey/output_crs.h"

namespace zebrageo {
namespace {

// Bounds of a plausible ellipsoidal height of a vehicle (metres).
constexpr double kMinHeightM = -1000.0;
constexpr double kMaxHeightM = 10000.0;

const std::vector<std::string>& TrajectoryColumns() {
  static const std::vector<std::string> kColumns = {
      "time", "lat",  "lon",  "h",       "roll",     "pitch",     "heading",
      "sd_e", "sd_n", "sd_u", "sd_roll", "sd_pitch", "sd_heading"};
  return kColumns;
}

// The columns of a trajectory whose positions are x, y, z of another CRS.
std::vector<std::string> TrajectoryColumnsInCrs() {
  std::vector<std::string> columns = TrajectoryColumns();
  columns[1] = "x";
  columns[2] = "y";
  columns[3] = "z";
  return columns;
}

// `crs`: null for the contract's lat, lon, h columns; else the columns x, y,
// z of that CRS, converted to WGS84 here.
std::vector<TrajectorySample> SamplesFromTable(
    const CsvTable& table, const CrsTransformer* crs = nullptr) {
  std::vector<TrajectorySample> samples;
  samples.reserve(table.NumRows());
  for (int row = 0; row < table.NumRows(); ++row) {
    TrajectorySample s;
    s.line = table.LineOf(row);
    s.time = table.GetDouble(row, "time");
    if (crs == nullptr) {
      s.position.lat_deg = table.GetDouble(row, "lat");
      s.position.lon_deg = table.GetDouble(row, "lon");
      s.position.h_m = table.GetDouble(row, "h");
    } else {
      const Eigen::Vector3d xyz(table.GetDouble(row, "x"),
                                table.GetDouble(row, "y"),
                                table.GetDouble(row, "z"));
      try {
        s.position = crs->ToWgs84(xyz);
      } catch (const CrsError& error) {
        table.Fail(row, error.what());
      }
    }
    s.attitude.roll = DegToRad(table.GetDouble(row, "roll"));
    s.attitude.pitch = DegToRad(table.GetDouble(row, "pitch"));
    s.attitude.heading = DegToRad(table.GetDouble(row, "heading"));
    s.sd_enu_m = {table.GetDouble(row, "sd_e"), table.GetDouble(row, "sd_n"),
                  table.GetDouble(row, "sd_u")};
    s.sd_attitude_rad = {DegToRad(table.GetDouble(row, "sd_roll")),
                         DegToRad(table.GetDouble(row, "sd_pitch")),
                         DegToRad(table.GetDouble(row, "sd_heading"))};
    if (std::abs(s.position.lat_deg) > 90.0) {
      table.Fail(row, "latitude " + FormatDouble(s.position.lat_deg) +
                          " is outside [-90, 90]");
    }
    if (std::abs(s.position.lon_deg) > 180.0) {
      table.Fail(row, "longitude " + FormatDouble(s.position.lon_deg) +
                          " is outside [-180, 180]");
    }
    // Ellipsoidal heights on land lie between about -450 m (the Dead Sea
    // shore) and 8850 m: a height far outside is a broken number (1e308
    // overflows the adjustment's residuals), not a drift.
    if (!(s.position.h_m >= kMinHeightM && s.position.h_m <= kMaxHeightM)) {
      table.Fail(row, "height " + FormatDouble(s.position.h_m) +
                          " m is not a height on Earth (a vehicle's "
                          "ellipsoidal height lies between " +
                          FormatDouble(kMinHeightM) + " and " +
                          FormatDouble(kMaxHeightM) +
                          " m): a broken number in the GNSS/INS export");
    }
    if (std::abs(table.GetDouble(row, "pitch")) > 90.0) {
      table.Fail(row, "pitch " + table.GetString(row, "pitch") +
                          " is outside [-90, 90] degrees");
    }
    if ((s.sd_enu_m.array() < 0.0).any() ||
        (s.sd_attitude_rad.array() < 0.0).any()) {
      table.Fail(row, "a standard deviation (sd_*) is negative");
    }
    if (!samples.empty() && !(s.time > samples.back().time)) {
      table.Fail(row, "time " + FormatDouble(s.time) +
                          (s.time == samples.back().time
                               ? " repeats the previous sample's time"
                               : " is earlier than the previous sample's " +
                                     FormatDouble(samples.back().time)) +
                          ": times must increase strictly");
    }
    samples.push_back(s);
  }
  if (samples.size() < 2) {
    throw InputError(
        table.display_name(), 0,
        "needs at least 2 samples, has " + std::to_string(samples.size()));
  }
  return samples;
}

// Wraps an angle in degrees into (-180, 180].
double WrapDegrees180(double degrees) {
  double wrapped = std::remainder(degrees, 360.0);
  if (wrapped <= -180.0) wrapped += 360.0;
  return wrapped;
}

}  // namespace

Eigen::Isometry3d Pose::T_enu_body() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q_enu_body.toRotationMatrix();
  T.translation() = p_enu;
  return T;
}

Pose Pose::FromIsometry(const Eigen::Isometry3d& T_enu_body) {
  Pose pose;
  pose.q_enu_body = Eigen::Quaterniond(T_enu_body.linear()).normalized();
  pose.p_enu = T_enu_body.translation();
  return pose;
}

Pose InterpolatePoses(const Pose& a, const Pose& b, double u) {
  Pose pose;
  pose.p_enu = (1.0 - u) * a.p_enu + u * b.p_enu;
  // Eigen's slerp takes the shorter arc (it flips the sign of b if needed).
  pose.q_enu_body = a.q_enu_body.slerp(u, b.q_enu_body).normalized();
  return pose;
}

Trajectory::Trajectory(std::vector<TrajectorySample> samples,
                       const LocalFrame& frame)
    : samples_(std::move(samples)) {
  CHECK_GE(samples_.size(), 2u);
  poses_.reserve(samples_.size());
  for (size_t i = 0; i < samples_.size(); ++i) {
    if (i > 0) CHECK_GT(samples_[i].time, samples_[i - 1].time);
    const TrajectorySample& s = samples_[i];
    Pose pose;
    pose.p_enu = frame.EnuFromGeodetic(s.position);
    pose.q_enu_body =
        Eigen::Quaterniond(frame.RotationEnuFromBody(s.position, s.attitude));
    poses_.push_back(pose);
  }
}

int Trajectory::FindSegment(double time) const {
  if (!Covers(time)) return -1;
  const auto upper = std::upper_bound(
      samples_.begin(), samples_.end(), time,
      [](double t, const TrajectorySample& s) { return t < s.time; });
  const int index = static_cast<int>(upper - samples_.begin()) - 1;
  return std::min(index, size() - 2);
}

bool Trajectory::InterpolatePose(double time, Pose* pose) const {
  const int i = FindSegment(time);
  if (i < 0) return false;
  const double t0 = samples_[i].time;
  const double t1 = samples_[i + 1].time;
  *pose = InterpolatePoses(poses_[i], poses_[i + 1], (time - t0) / (t1 - t0));
  return true;
}

std::string TrajectoryGapOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, factor, 1.0);
  OPTION_GE(check, min_duration_s, 0.0);
  return check.problem();
}

double MedianSampleInterval(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<double> intervals;
  intervals.reserve(times.size() - 1);
  for (size_t i = 1; i < times.size(); ++i) {
    intervals.push_back(times[i] - times[i - 1]);
  }
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2,
                   intervals.end());
  return intervals[intervals.size() / 2];
}

std::vector<TrajectoryGap> FindTrajectoryGaps(
    const std::vector<double>& times, const TrajectoryGapOptions& options) {
  std::vector<TrajectoryGap> gaps;
  const double threshold = std::max(
      options.factor * MedianSampleInterval(times), options.min_duration_s);
  for (size_t i = 1; i < times.size(); ++i) {
    if (times[i] - times[i - 1] > threshold) {
      gaps.push_back({static_cast<int>(i) - 1, times[i - 1], times[i]});
    }
  }
  return gaps;
}

std::vector<double> SampleTimes(const std::vector<TrajectorySample>& samples) {
  std::vector<double> times;
  times.reserve(samples.size());
  for (const TrajectorySample& sample : samples) times.push_back(sample.time);
  return times;
}

std::vector<TrajectorySample> ReadTrajectorySamples(
    const std::string& path, const std::string& display_name) {
  return SamplesFromTable(
      CsvTable::Read(path, display_name, TrajectoryColumns()));
}

std::vector<TrajectorySample> ReadTrajectorySamplesInCrs(
    const std::string& path, const std::string& display_name,
    const CrsTransformer& crs) {
  return SamplesFromTable(
      CsvTable::Read(path, display_name, TrajectoryColumnsInCrs()), &crs);
}

std::vector<TrajectorySample> ParseTrajectorySamples(
    const std::string& text, const std::string& display_name) {
  return SamplesFromTable(
      CsvTable::Parse(text, display_name, TrajectoryColumns()));
}

void WriteTrajectorySamples(const std::vector<TrajectorySample>& samples,
                            const std::string& path, const OutputCrs* crs) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    CsvWriter csv(&out);
    std::vector<std::string> columns = TrajectoryColumns();
    if (crs != nullptr) crs->AddHeader(&csv, &columns);
    csv.Header(columns);
    for (const TrajectorySample& s : samples) {
      double heading = std::fmod(RadToDeg(s.attitude.heading), 360.0);
      if (heading < 0.0) heading += 360.0;
      if (heading >= 360.0) heading -= 360.0;
      csv.Add(s.time)
          .Add(s.position.lat_deg)
          .Add(s.position.lon_deg)
          .Add(s.position.h_m)
          .Add(WrapDegrees180(RadToDeg(s.attitude.roll)))
          .Add(std::clamp(RadToDeg(s.attitude.pitch), -90.0, 90.0))
          .Add(heading)
          .Add(s.sd_enu_m.x())
          .Add(s.sd_enu_m.y())
          .Add(s.sd_enu_m.z())
          .Add(RadToDeg(s.sd_attitude_rad.x()))
          .Add(RadToDeg(s.sd_attitude_rad.y()))
          .Add(RadToDeg(s.sd_attitude_rad.z()));
      if (crs != nullptr) crs->AddColumns(s.position, &csv);
      csv.EndRow();
    }
  });
}

TrajectorySample SampleFromPose(double time, const Pose& pose,
                                const LocalFrame& frame,
                                const Eigen::Vector3d& sd_enu_m,
                                const Eigen::Vector3d& sd_attitude_rad) {
  TrajectorySample sample;
  sample.time = time;
  sample.position = frame.GeodeticFromEnu(pose.p_enu);
  sample.attitude = frame.AttitudeFromRotationEnuBody(
      sample.position, pose.q_enu_body.toRotationMatrix());
  sample.sd_enu_m = sd_enu_m;
  sample.sd_attitude_rad = sd_attitude_rad;
  return sample;
}

}  // namespace zebrageo
