// Applanix SBET and smrmsg readers (geodata/trajectory_import.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "geodata/gps_time.h"
#include "geodata/trajectory_import.h"
#include "survey/input_error.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

constexpr double kArcMinuteRad = kPi / (180.0 * 60.0);

// A little-endian IEEE double, whatever the host's byte order.
double LittleEndianDouble(const unsigned char* bytes) {
  uint64_t bits = 0;
  for (int i = 7; i >= 0; --i) bits = (bits << 8) | bytes[i];
  double value = 0.0;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

// "" when `value` of the first record is plausible, or what is wrong.
std::string Implausible(double value, double low, double high,
                        const char* name) {
  if (std::isfinite(value) && value >= low && value <= high) return "";
  std::ostringstream problem;
  problem << "record 1's " << name << " is " << value << ", outside [" << low
          << ", " << high << "]";
  return problem.str();
}

// Whether the first record can be an SBET's (time in seconds of a week,
// latitude and longitude, a height on Earth) or an smrmsg's
// (time, non-negative RMS): random bytes fail it, so a file of another kind
// is named as such before its size or a later record is.
template <int kFields>
std::string FirstRecordProblem(const std::array<double, kFields>& record) {
  // Seconds of the week, unwrapped across a few weeks at most.
  std::string problem = Implausible(record[0], 0.0, 1e7, "time");
  if (kFields == 17) {
    // Degrees where radians belong pass here: ReadSbet names that mistake.
    if (problem.empty())
      problem = Implausible(record[1], -360, 360, "latitude");
    if (problem.empty()) {
      problem = Implausible(record[2], -360, 360, "longitude");
    }
    if (problem.empty()) problem = Implausible(record[3], -1e4, 1e5, "height");
  } else {
    for (int f = 1; f < kFields && problem.empty(); ++f) {
      problem = Implausible(record[f], 0.0, 1e6, "RMS");
    }
  }
  return problem;
}

// Every record of a file of fixed-size records of doubles. Throws when the
// first record is not of this kind ("not <what>"), the size is not whole
// records (naming the truncated one) or a value is not finite.
template <int kFields>
std::vector<std::array<double, kFields>> ReadRecords(const std::string& path,
                                                     const char* what) {
  constexpr int kBytes = kFields * 8;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(path, 0,
                     std::filesystem::exists(path, error)
                         ? std::string("not ") + what +
                               ": a device, pipe or folder, not a file of "
                               "records"
                         : std::string("cannot open ") + what);
  }
  const uintmax_t size = std::filesystem::file_size(path, error);
  std::ifstream in(path, std::ios::binary);
  if (error || !in) {
    throw InputError(path, 0, std::string("cannot read ") + what);
  }
  std::vector<std::array<double, kFields>> records(size / kBytes);
  std::array<unsigned char, kBytes> buffer;
  for (size_t r = 0; r < records.size(); ++r) {
    if (!in.read(reinterpret_cast<char*>(buffer.data()), kBytes)) {
      throw InputError(path, 0,
                       "read error at record " + std::to_string(r + 1));
    }
    for (int f = 0; f < kFields; ++f) {
      records[r][f] = LittleEndianDouble(buffer.data() + 8 * f);
    }
    if (r == 0) {
      const std::string problem = FirstRecordProblem<kFields>(records[0]);
      if (!problem.empty()) {
        throw InputError(path, 0,
                         std::string("not ") + what + " (" +
                             std::to_string(kFields) +
                             " little-endian doubles per record): " + problem);
      }
      if (size % kBytes != 0) {
        std::ostringstream problem_text;
        problem_text << "record " << size / kBytes + 1
                     << " is truncated: the file has " << size
                     << " bytes, not a whole number of " << kBytes
                     << "-byte records (" << kFields << " doubles)";
        throw InputError(path, 0, problem_text.str());
      }
    }
    for (int f = 0; f < kFields; ++f) {
      if (!std::isfinite(records[r][f])) {
        std::ostringstream problem;
        problem << "record " << r + 1 << " (byte " << r * kBytes << "): field "
                << f + 1 << " is not finite";
        throw InputError(path, 0, problem.str());
      }
    }
  }
  if (size % kBytes != 0) {  // shorter than one record
    std::ostringstream problem;
    problem << "not " << what << ": " << size << " bytes, less than one "
            << kBytes << "-byte record (" << kFields << " doubles)";
    throw InputError(path, 0, problem.str());
  }
  return records;
}

// Linear interpolation of the smrmsg accuracies at `time`, held at the ends.
std::array<double, 10> AccuracyAt(
    const std::vector<std::array<double, 10>>& rms, double time) {
  auto after = std::upper_bound(
      rms.begin(), rms.end(), time,
      [](double t, const std::array<double, 10>& r) { return t < r[0]; });
  if (after == rms.begin()) return rms.front();
  if (after == rms.end()) return rms.back();
  const std::array<double, 10>& a = *std::prev(after);
  const std::array<double, 10>& b = *after;
  const double u = (time - a[0]) / (b[0] - a[0]);
  std::array<double, 10> out;
  for (int i = 0; i < 10; ++i) out[i] = a[i] + u * (b[i] - a[i]);
  return out;
}

void AddAccuracies(const std::string& smrmsg_path,
                   std::vector<TrajectorySample>* samples) {
  std::vector<std::array<double, 10>> rms =
      ReadRecords<10>(smrmsg_path, "an smrmsg accuracy file");
  if (rms.empty()) throw InputError(smrmsg_path, 0, "no record");
  std::vector<double> times;
  for (const auto& r : rms) times.push_back(r[0]);
  UnwrapGpsWeekSeconds(&times);
  for (size_t i = 0; i < rms.size(); ++i) {
    rms[i][0] = times[i];
    if (i > 0 && !(times[i] > times[i - 1])) {
      throw InputError(
          smrmsg_path, 0,
          "record " + std::to_string(i + 1) + ": time does not increase");
    }
    for (int f = 1; f < 10; ++f) {
      if (rms[i][f] < 0.0) {
        throw InputError(smrmsg_path, 0,
                         "record " + std::to_string(i + 1) + ": field " +
                             std::to_string(f + 1) + " is a negative RMS");
      }
    }
  }
  // The accuracy file must cover the trajectory's clock: a smrmsg of
  // another day would give plausible but wrong numbers.
  const double overlap_start = std::max(samples->front().time, rms.front()[0]);
  const double overlap_end = std::min(samples->back().time, rms.back()[0]);
  if (overlap_end < overlap_start) {
    std::ostringstream problem;
    problem << "its times [" << rms.front()[0] << ", " << rms.back()[0]
            << "] do not overlap the SBET's [" << samples->front().time << ", "
            << samples->back().time << "]";
    throw InputError(smrmsg_path, 0, problem.str());
  }
  for (TrajectorySample& sample : *samples) {
    const std::array<double, 10> a = AccuracyAt(rms, sample.time);
    sample.sd_enu_m = Eigen::Vector3d(a[2], a[1], a[3]);  // east, north, down
    sample.sd_attitude_rad = Eigen::Vector3d(a[7], a[8], a[9]) * kArcMinuteRad;
  }
}

}  // namespace

std::vector<TrajectorySample> ReadSbet(const std::string& sbet_path,
                                       const std::string& smrmsg_path) {
  const std::vector<std::array<double, 17>> records =
      ReadRecords<17>(sbet_path, "an SBET file");
  std::vector<double> times;
  for (const auto& r : records) times.push_back(r[0]);
  UnwrapGpsWeekSeconds(&times);
  std::vector<TrajectorySample> samples;
  samples.reserve(records.size());
  for (size_t i = 0; i < records.size(); ++i) {
    const std::array<double, 17>& r = records[i];
    const std::string where = "record " + std::to_string(i + 1) + " (byte " +
                              std::to_string(i * kSbetRecordBytes) + "): ";
    if (std::abs(r[1]) > kPi / 2 + 1e-12 || std::abs(r[2]) > 2 * kPi + 1e-12) {
      // Degrees written where radians belong are the usual culprit.
      throw InputError(sbet_path, 0,
                       where + "latitude/longitude out of range for radians");
    }
    TrajectorySample sample;
    sample.time = times[i];
    sample.position.lat_deg = RadToDeg(r[1]);
    double lon = RadToDeg(r[2]);
    if (lon > 180.0) lon -= 360.0;
    sample.position.lon_deg = lon;
    sample.position.h_m = r[3];
    sample.attitude = NormalizedAttitude({r[7], r[8], r[9]});
    sample.line = static_cast<int>(i + 1);
    samples.push_back(sample);
  }
  CheckImportedSamples(samples, sbet_path, "record");
  if (!smrmsg_path.empty()) AddAccuracies(smrmsg_path, &samples);
  return samples;
}

}  // namespace zebrageo
