// NovAtel SPAN ASCII INSPVAXA / INSPVAA reader (geodata/trajectory_import.h).
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "geodata/gps_time.h"
#include "geodata/text_input.h"
#include "geodata/trajectory_import.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Fields of the ASCII header before ';' (name, port, sequence, idle, time
// status, week, seconds, receiver status, reserved, software version).
constexpr int kHeaderFields = 10;
constexpr int kWeekField = 5;
constexpr int kSecondsField = 6;

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(text);
  while (std::getline(in, field, separator)) fields.push_back(field);
  if (!text.empty() && text.back() == separator) fields.push_back("");
  return fields;
}

// NovAtel's CRC-32 (reflected polynomial 0xEDB88320, initial value 0, no
// final XOR) is zlib's CRC-32 with the pre- and post-inversion undone.
uint32_t NovatelCrc32(const std::string& text) {
  const uLong crc =
      crc32(0xFFFFFFFFUL, reinterpret_cast<const Bytef*>(text.data()),
            static_cast<uInt>(text.size()));
  return static_cast<uint32_t>(crc ^ 0xFFFFFFFFUL);
}

double Number(const std::vector<std::string>& fields, int index,
              const char* name, const std::string& path, int line) {
  const std::string& text = fields[index];
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size() || !std::isfinite(value)) {
    throw InputError(path, line,
                     std::string(name) + " \"" + text + "\" is not a number");
  }
  return value;
}

// R_ned_body (FRD) of SPAN's attitude: R_enu_rfu = Rz(-azimuth) Rx(pitch)
// Ry(roll), its vehicle frame x right, y forward, z up.
Attitude AttitudeFromSpan(double roll, double pitch, double azimuth) {
  const Eigen::Matrix3d R_enu_rfu =
      RotationZ(-azimuth) * RotationX(pitch) * RotationY(roll);
  Eigen::Matrix3d R_rfu_frd;  // columns: forward, right, down in RFU
  R_rfu_frd << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d R_ned_enu = RotationEnuFromNed().transpose();
  return AttitudeFromRotationNedBody(R_ned_enu * R_enu_rfu * R_rfu_frd);
}

struct Record {
  double week = 0.0;
  TrajectorySample sample;
};

// One INSPVAXA / INSPVAA line (without '\r').
Record ParseRecord(const std::string& line, bool extended,
                   const std::string& path, int line_number) {
  const size_t star = line.rfind('*');
  if (star == std::string::npos || line.size() != star + 9) {
    throw InputError(path, line_number,
                     "record without its '*' and 8-digit CRC (truncated?)");
  }
  const std::string crc_text = line.substr(star + 1);
  uint32_t crc = 0;
  std::istringstream crc_in(crc_text);
  if (!(crc_in >> std::hex >> crc) || !crc_in.eof()) {
    throw InputError(path, line_number,
                     "CRC \"" + crc_text + "\" is not 8 hexadecimal digits");
  }
  const std::string content = line.substr(1, star - 1);
  if (NovatelCrc32(content) != crc) {
    std::ostringstream problem;
    problem << "CRC mismatch (record says " << crc_text << ", content gives "
            << std::hex << NovatelCrc32(content) << "): the record is garbled";
    throw InputError(path, line_number, problem.str());
  }
  const size_t semicolon = content.find(';');
  if (semicolon == std::string::npos) {
    throw InputError(path, line_number, "no ';' after the header");
  }
  const std::vector<std::string> header =
      Split(content.substr(0, semicolon), ',');
  const std::vector<std::string> body =
      Split(content.substr(semicolon + 1), ',');
  const size_t expected = extended ? 23 : 12;
  if (header.size() != kHeaderFields || body.size() != expected) {
    std::ostringstream problem;
    problem << "expected " << kHeaderFields << " header and " << expected
            << " data fields, got " << header.size() << " and " << body.size();
    throw InputError(path, line_number, problem.str());
  }
  Record record;
  record.week = Number(header, kWeekField, "week", path, line_number);
  TrajectorySample& s = record.sample;
  s.time = Number(header, kSecondsField, "seconds", path, line_number);
  s.line = line_number;
  // INSPVAXA: status, type, lat, lon, height (MSL), undulation, v n/e/u,
  // roll, pitch, azimuth, sd lat/lon/height (m), sd v, sd roll/pitch/azimuth
  // (deg), ... INSPVAA: week, seconds, lat, lon, height (ellipsoidal), v
  // n/e/u, roll, pitch, azimuth, status.
  const int first = 2;
  s.position.lat_deg = Number(body, first, "latitude", path, line_number);
  s.position.lon_deg = Number(body, first + 1, "longitude", path, line_number);
  s.position.h_m = Number(body, first + 2, "height", path, line_number);
  const int attitude = extended ? 9 : 8;
  if (extended) {
    s.position.h_m += Number(body, 5, "undulation", path, line_number);
  }
  const double roll = Number(body, attitude, "roll", path, line_number);
  const double pitch = Number(body, attitude + 1, "pitch", path, line_number);
  const double azimuth =
      Number(body, attitude + 2, "azimuth", path, line_number);
  s.attitude =
      AttitudeFromSpan(DegToRad(roll), DegToRad(pitch), DegToRad(azimuth));
  if (extended) {
    s.sd_enu_m =
        Eigen::Vector3d(Number(body, 13, "longitude sd", path, line_number),
                        Number(body, 12, "latitude sd", path, line_number),
                        Number(body, 14, "height sd", path, line_number));
    // SPAN's roll and pitch sd are about its y and x axes: FRD's x and y.
    s.sd_attitude_rad =
        Eigen::Vector3d(Number(body, 18, "roll sd", path, line_number),
                        Number(body, 19, "pitch sd", path, line_number),
                        Number(body, 20, "azimuth sd", path, line_number)) *
        (kPi / 180.0);
  }
  return record;
}

}  // namespace

std::vector<TrajectorySample> ReadNovatelAscii(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read the NovAtel log");
  std::vector<TrajectorySample> samples;
  double first_week = -1.0;
  // A record is a few hundred bytes: a longer line, or binary data, is not
  // a NovAtel ASCII log (a binary log, /dev/zero).
  constexpr size_t kMaxLineBytes = 1 << 16;
  BoundedLineReader reader(&in, path, "NovAtel ASCII log",
                           kMaxTrajectoryTextBytes, kMaxLineBytes);
  std::string line;
  while (reader.Next(&line)) {
    const int line_number = reader.line_number();
    const bool extended = line.rfind("#INSPVAXA,", 0) == 0;
    const bool plain = line.rfind("#INSPVAA,", 0) == 0;
    if (!extended && !plain) {
      // Other logs may share the file; a mangled INSPVA header may not.
      if (line.find("INSPVA") != std::string::npos) {
        throw InputError(path, line_number,
                         "an INSPVA record with a damaged header");
      }
      continue;
    }
    Record record = ParseRecord(line, extended, path, line_number);
    if (first_week < 0.0) first_week = record.week;
    record.sample.time += (record.week - first_week) * kSecondsPerGpsWeek;
    samples.push_back(record.sample);
  }
  if (samples.empty()) {
    throw InputError(path, 0,
                     "not a NovAtel ASCII log: no #INSPVAXA or #INSPVAA "
                     "record");
  }
  CheckImportedSamples(samples, path, "line");
  return samples;
}

}  // namespace zebrageo
