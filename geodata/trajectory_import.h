// GNSS/INS trajectories from other tools into the contract's trajectory.csv
// (SURVEY_FORMAT.md): WGS84 latitude/longitude/ellipsoidal height of the
// IMU origin, attitude of the body frame (x forward, y right, z down)
// relative to NED at the vehicle, R_ned_body = Rz(heading) Ry(pitch)
// Rx(roll), heading from true north; standard deviations east/north/up in
// metres and roll/pitch/heading. Angles are radians in the returned samples.
//
// Time: every reader returns GPS seconds of week of the first record's week,
// increasing across a week boundary (geodata/gps_time.h). The survey's
// exposures.csv must use the same clock.
//
// Formats:
//  - Applanix SBET (POSPac "sbet_*.out"): headerless little-endian records
//    of 17 doubles: time (GPS s of week), latitude, longitude (rad),
//    altitude (m, ellipsoidal), x/y/z velocity (wander frame), roll, pitch,
//    platform heading, wander angle (rad), x/y/z acceleration, x/y/z angular
//    rate. The platform heading is the true heading of the body's x axis;
//    the wander angle only orients the velocity axes (which we do not use),
//    so it is not added to the heading. Roll/pitch/heading are already the
//    contract's FRD Euler angles.
//  - Applanix smrmsg ("smrmsg_*.out"): 10 doubles per record: time, north,
//    east, down position RMS (m), north/east/down velocity RMS (m/s),
//    roll, pitch, heading RMS (arc minutes). Usually at 1 Hz: interpolated
//    linearly to the SBET's times, held at its ends.
//  - NovAtel SPAN ASCII logs INSPVAXA (with standard deviations; height is
//    above mean sea level, plus the undulation field for the ellipsoidal
//    height) and INSPVAA (ellipsoidal height, no standard deviations). The
//    CRC-32 of every record is checked. SPAN's attitude is of its vehicle
//    frame (x right, y forward, z up) in the local level (ENU) frame,
//    rotated Z (azimuth, clockwise), then X (pitch), then Y (roll):
//    R_enu_rfu = Rz(-azimuth) Rx(pitch) Ry(roll). It is converted through the
//    rotation matrix, not angle by angle (the orders differ: ZXY vs ZYX).
//    Other logs in the file are ignored.
//  - A delimited text file with a column map (Inertial Explorer and most
//    other exports): the contract's names mapped to the file's columns,
//    degrees or radians, time as GPS seconds of week, GPS seconds since
//    1980-01-06, or ISO 8601 UTC converted with the IERS leap seconds.
#ifndef ZEBRAGEO_GEODATA_TRAJECTORY_IMPORT_H_
#define ZEBRAGEO_GEODATA_TRAJECTORY_IMPORT_H_

#include <map>
#include <string>
#include <vector>

#include "survey/trajectory.h"

namespace zebrageo {

inline constexpr int kSbetRecordBytes = 17 * 8;
inline constexpr int kSmrmsgRecordBytes = 10 * 8;

// Reads an SBET and, when `smrmsg_path` is not empty, its accuracy file.
// Throws InputError naming the file, the record (1-based) and the problem:
// a size that is not whole records (the truncated record), non-finite or
// out-of-range values, times that do not increase.
std::vector<TrajectorySample> ReadSbet(const std::string& sbet_path,
                                       const std::string& smrmsg_path);

// Reads INSPVAXA/INSPVAA records of a NovAtel ASCII log. Throws InputError
// naming the file, the line and the problem (CRC mismatch, a missing field,
// a non-number, an unknown or unsolved INS status is kept: the contract has
// no status; times that do not increase).
std::vector<TrajectorySample> ReadNovatelAscii(const std::string& path);

enum class AngleUnit { kDegrees, kRadians };
enum class TimeKind {
  kGpsWeekSeconds,  // seconds of the GPS week
  kGpsSeconds,      // seconds since the GPS epoch (1980-01-06)
  kUtc,             // ISO 8601 UTC text, "2024-05-03T10:15:30.25Z"
};
enum class Delimiter { kComma, kWhitespace, kSemicolon };

struct CsvTrajectoryFormat {
  // The contract's column names (time, lat, lon, h, roll, pitch, heading,
  // sd_e, sd_n, sd_u, sd_roll, sd_pitch, sd_heading) to the file's. A name
  // not mapped is looked up as itself; the sd_* may be absent (written 0).
  std::map<std::string, std::string> columns;
  // Unit of lat, lon, roll, pitch, heading and sd_roll/pitch/heading.
  AngleUnit angle_unit = AngleUnit::kDegrees;
  TimeKind time_kind = TimeKind::kGpsWeekSeconds;
  Delimiter delimiter = Delimiter::kComma;
  // IERS leap-second list, for TimeKind::kUtc.
  std::string leap_seconds_file = "/usr/share/zoneinfo/leap-seconds.list";
  // CRS of the positions (survey/crs.h: EPSG code, compound code with a
  // geoid, PROJ string, WKT), "" for WGS84 latitude, longitude and
  // ellipsoidal height. Given one, the columns are x, y (its easting and
  // northing, or longitude and latitude in degrees) and h (its height:
  // orthometric for a compound CRS), transformed to WGS84 by PROJ; a
  // missing geoid grid is an error naming it. The heading stays from true
  // north: INS exports give true heading, never grid bearings.
  std::string crs;
  // Folders searched for its grids before PROJ's own (CrsOptions).
  std::vector<std::string> grid_dirs;

  // "" or what is wrong ("columns: unknown name 'yaw'").
  std::string Check() const;
};

// Parses "time=GPSTime,lat=Latitude,..." into `format->columns`; "" or the
// error.
std::string ParseColumnMap(const std::string& text,
                           CsvTrajectoryFormat* format);

// Reads a delimited trajectory. Throws InputError naming the file, the line
// and the column.
std::vector<TrajectorySample> ReadTrajectoryCsv(
    const std::string& path, const CsvTrajectoryFormat& format);

// Checks imported samples as trajectory.csv's reader would (finite values,
// latitude/longitude in range, non-negative sd, at least 2 samples, strictly
// increasing times). `unit` names a sample in messages ("record", "line");
// samples carry it in `line`. Throws InputError naming `path`.
void CheckImportedSamples(const std::vector<TrajectorySample>& samples,
                          const std::string& path, const std::string& unit);

// "sbet", "novatel" or "csv" from the first 64 KiB of `path`: binary data
// (a NUL byte) is an SBET, "#INSPVA" a NovAtel log, other text a delimited
// export. Throws InputError when it cannot be read.
std::string GuessTrajectoryFormat(const std::string& path);

// Normalises angles as the contract writes them: heading [0, 2pi), roll
// (-pi, pi], pitch [-pi/2, pi/2].
Attitude NormalizedAttitude(const Attitude& attitude);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_TRAJECTORY_IMPORT_H_
