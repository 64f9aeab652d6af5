// Checks shared by the trajectory imports, and the delimited-text reader
// with a column map (geodata/trajectory_import.h).
#include "geodata/trajectory_import.h"

#include <glog/logging.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "geodata/gps_time.h"
#include "geodata/text_input.h"
#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

const std::vector<std::string>& RequiredNames() {
  static const std::vector<std::string> kNames = {
      "time", "lat", "lon", "h", "roll", "pitch", "heading"};
  return kNames;
}
const std::vector<std::string>& AccuracyNames() {
  static const std::vector<std::string> kNames = {
      "sd_e", "sd_n", "sd_u", "sd_roll", "sd_pitch", "sd_heading"};
  return kNames;
}

std::string FileColumn(const CsvTrajectoryFormat& format,
                       const std::string& name) {
  const auto it = format.columns.find(name);
  return it == format.columns.end() ? name : it->second;
}

// The text with its delimiter turned into commas, line for line (so CsvTable
// reports the file's own line numbers). A comma inside a whitespace- or
// semicolon-delimited field would split it: refused.
std::string AsCommaSeparated(const std::string& text, Delimiter delimiter,
                             const std::string& path) {
  if (delimiter == Delimiter::kComma) return text;
  std::ostringstream out;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r");
    const bool comment = first != std::string::npos && line[first] == '#';
    if (!comment && line.find(',') != std::string::npos) {
      throw InputError(
          path, line_number,
          "a ',' in a file read as " +
              std::string(delimiter == Delimiter::kWhitespace ? "whitespace"
                                                              : "semicolon") +
              "-delimited (decimal comma? use '.')");
    }
    if (comment) {
      out << line << '\n';
      continue;
    }
    if (delimiter == Delimiter::kSemicolon) {
      for (char& c : line) c = c == ';' ? ',' : c;
      out << line << '\n';
      continue;
    }
    std::istringstream fields(line);
    std::string field;
    bool first_field = true;
    while (fields >> field) {
      out << (first_field ? "" : ",") << field;
      first_field = false;
    }
    out << '\n';
  }
  return out.str();
}

double ReadTime(const CsvTable& table, int row, const std::string& column,
                const CsvTrajectoryFormat& format,
                const LeapSeconds* leap_seconds) {
  if (format.time_kind != TimeKind::kUtc) {
    return table.GetDouble(row, column);
  }
  const std::string& text = table.GetString(row, column);
  double unix_seconds = 0.0;
  if (!ParseUtcTimestamp(text, &unix_seconds)) {
    table.Fail(row, "column '" + column + "': \"" + text +
                        "\" is not an ISO 8601 UTC time "
                        "(2024-05-03T10:15:30.25Z)");
  }
  return GpsSecondsFromUnix(unix_seconds, *leap_seconds);
}

}  // namespace

Attitude NormalizedAttitude(const Attitude& attitude) {
  return AttitudeFromRotationNedBody(RotationNedFromBody(attitude));
}

void CheckImportedSamples(const std::vector<TrajectorySample>& samples,
                          const std::string& path, const std::string& unit) {
  if (samples.size() < 2) {
    throw InputError(path, 0,
                     "fewer than 2 trajectory " + unit + "s (" +
                         std::to_string(samples.size()) + ")");
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    const TrajectorySample& s = samples[i];
    // A text file's line goes where messages put lines; a binary record's
    // number is spelled out.
    const bool by_line = unit == "line";
    const std::string where =
        by_line ? "" : unit + " " + std::to_string(s.line) + ": ";
    const int line = by_line ? s.line : 0;
    const double values[] = {s.time,
                             s.position.lat_deg,
                             s.position.lon_deg,
                             s.position.h_m,
                             s.attitude.roll,
                             s.attitude.pitch,
                             s.attitude.heading,
                             s.sd_enu_m.x(),
                             s.sd_enu_m.y(),
                             s.sd_enu_m.z(),
                             s.sd_attitude_rad.x(),
                             s.sd_attitude_rad.y(),
                             s.sd_attitude_rad.z()};
    for (double v : values) {
      if (!std::isfinite(v)) throw InputError(path, line, where + "not finite");
    }
    if (std::abs(s.position.lat_deg) > 90.0 ||
        std::abs(s.position.lon_deg) > 180.0) {
      throw InputError(path, line,
                       where + "latitude or longitude out of range");
    }
    if (s.sd_enu_m.minCoeff() < 0.0 || s.sd_attitude_rad.minCoeff() < 0.0) {
      throw InputError(path, line, where + "negative standard deviation");
    }
    if (i > 0 && !(s.time > samples[i - 1].time)) {
      std::ostringstream problem;
      problem << where << "time " << FormatDouble(s.time)
              << " does not increase (previous "
              << FormatDouble(samples[i - 1].time) << ")";
      throw InputError(path, line, problem.str());
    }
  }
}

std::string CsvTrajectoryFormat::Check() const {
  std::set<std::string> known(RequiredNames().begin(), RequiredNames().end());
  known.insert(AccuracyNames().begin(), AccuracyNames().end());
  known.insert({"x", "y"});  // with a CRS
  for (const auto& [name, column] : columns) {
    if (!known.count(name)) {
      return "columns: unknown name '" + name +
             "' (time, lat, lon, h, roll, pitch, heading, sd_e, sd_n, sd_u, "
             "sd_roll, sd_pitch, sd_heading; x, y with a CRS)";
    }
    if (column.empty()) return "columns: '" + name + "' maps to nothing";
  }
  if (time_kind == TimeKind::kUtc && leap_seconds_file.empty()) {
    return "leap_seconds_file is empty: UTC times need the leap seconds";
  }
  return "";
}

std::string ParseColumnMap(const std::string& text,
                           CsvTrajectoryFormat* format) {
  std::istringstream in(text);
  std::string pair;
  while (std::getline(in, pair, ',')) {
    const size_t equals = pair.find('=');
    if (equals == std::string::npos || equals == 0) {
      return "column map: \"" + pair + "\" is not NAME=COLUMN";
    }
    format->columns[pair.substr(0, equals)] = pair.substr(equals + 1);
  }
  return format->Check();
}

std::vector<TrajectorySample> ReadTrajectoryCsv(
    const std::string& path, const CsvTrajectoryFormat& format) {
  const std::string error = format.Check();
  if (!error.empty()) {
    throw std::invalid_argument("CsvTrajectoryFormat: " + error);
  }
  // Capped, and binary data refused as it is read (/dev/zero never ends).
  const std::string text =
      ReadTextInput(path, "delimited trajectory file", kMaxTrajectoryTextBytes);
  std::vector<std::string> required;
  for (const std::string& name : RequiredNames()) {
    if (!format.crs.empty() && (name == "lat" || name == "lon")) continue;
    required.push_back(FileColumn(format, name));
  }
  std::unique_ptr<CrsTransformer> transformer;
  if (!format.crs.empty()) {
    required.push_back(FileColumn(format, "x"));
    required.push_back(FileColumn(format, "y"));
    CrsOptions crs_options;
    crs_options.grid_dirs = format.grid_dirs;
    transformer =
        std::make_unique<CrsTransformer>(Crs(format.crs), crs_options);
  }
  const CsvTable table = CsvTable::Parse(
      AsCommaSeparated(text, format.delimiter, path), path, required);
  bool has_accuracy = true;
  for (const std::string& name : AccuracyNames()) {
    has_accuracy = has_accuracy && table.HasColumn(FileColumn(format, name));
  }
  if (!has_accuracy) {
    LOG(WARNING) << path
                 << ": no standard deviation columns (sd_e ... sd_heading "
                    "all mapped): sd_* written as 0";
  }
  std::unique_ptr<LeapSeconds> leap_seconds;
  if (format.time_kind == TimeKind::kUtc) {
    leap_seconds = std::make_unique<LeapSeconds>(
        LeapSeconds::Load(format.leap_seconds_file));
  }
  const double angle =
      format.angle_unit == AngleUnit::kDegrees ? kPi / 180.0 : 1.0;
  std::vector<double> times;
  std::vector<TrajectorySample> samples;
  for (int row = 0; row < table.NumRows(); ++row) {
    auto get = [&](const std::string& name) {
      return table.GetDouble(row, FileColumn(format, name));
    };
    TrajectorySample s;
    times.push_back(ReadTime(table, row, FileColumn(format, "time"), format,
                             leap_seconds.get()));
    if (transformer) {
      try {
        s.position =
            transformer->ToWgs84(Eigen::Vector3d(get("x"), get("y"), get("h")));
      } catch (const CrsError& crs_error) {
        table.Fail(row, crs_error.what());
      }
    } else {
      s.position.lat_deg = RadToDeg(get("lat") * angle);
      s.position.lon_deg = RadToDeg(get("lon") * angle);
      s.position.h_m = get("h");
    }
    s.attitude = NormalizedAttitude(
        {get("roll") * angle, get("pitch") * angle, get("heading") * angle});
    if (has_accuracy) {
      s.sd_enu_m = Eigen::Vector3d(get("sd_e"), get("sd_n"), get("sd_u"));
      s.sd_attitude_rad =
          Eigen::Vector3d(get("sd_roll"), get("sd_pitch"), get("sd_heading")) *
          angle;
    }
    s.line = table.LineOf(row);
    samples.push_back(s);
  }
  // One clock for every format: GPS seconds of the first record's week.
  if (format.time_kind == TimeKind::kGpsWeekSeconds) {
    UnwrapGpsWeekSeconds(&times);
  } else if (!times.empty()) {
    const double week_start =
        std::floor(times.front() / kSecondsPerGpsWeek) * kSecondsPerGpsWeek;
    for (double& t : times) t -= week_start;
  }
  for (size_t i = 0; i < samples.size(); ++i) samples[i].time = times[i];
  CheckImportedSamples(samples, path, "line");
  return samples;
}

std::string GuessTrajectoryFormat(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot read the trajectory file");
  std::string head(64 * 1024, '\0');
  in.read(head.data(), head.size());
  head.resize(static_cast<size_t>(in.gcount()));
  if (head.find('\0') != std::string::npos) return "sbet";
  if (head.find("#INSPVA") != std::string::npos) return "novatel";
  return "csv";
}

}  // namespace zebrageo
