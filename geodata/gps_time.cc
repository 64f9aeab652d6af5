#include "geodata/gps_time.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

// NTP counts from 1900-01-01, POSIX from 1970-01-01.
constexpr double kNtpToUnixSeconds = 2208988800.0;
// 1980-01-06 00:00:00 UTC, the GPS epoch, in POSIX seconds.
constexpr double kGpsEpochUnixSeconds = 315964800.0;
// TAI - GPS: GPS was set to UTC in 1980, when TAI - UTC was 19 s.
constexpr double kTaiMinusGps = 19.0;

// Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's
// days_from_civil: exact for every date, no time zone involved).
long long DaysFromCivil(long long year, int month, int day) {
  year -= month <= 2 ? 1 : 0;
  const long long era = (year >= 0 ? year : year - 399) / 400;
  const long long year_of_era = year - era * 400;
  const int shifted_month = month > 2 ? month - 3 : month + 9;
  const long long day_of_year = (153 * shifted_month + 2) / 5 + day - 1;
  const long long day_of_era =
      year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + day_of_era - 719468;
}

int DaysInMonth(int year, int month) {
  static const int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  return month == 2 && leap ? 29 : kDays[month - 1];
}

}  // namespace

LeapSeconds LeapSeconds::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw InputError(path, 0,
                     "cannot read the leap-second list (Debian package "
                     "tzdata); name another with --leap-seconds");
  }
  LeapSeconds table;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.rfind("#@", 0) == 0) {
      std::istringstream fields(line.substr(2));
      double ntp = 0.0;
      if (!(fields >> ntp)) {
        throw InputError(path, line_number, "malformed expiry line");
      }
      table.expires_unix_seconds_ = ntp - kNtpToUnixSeconds;
      continue;
    }
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream fields(line);
    double ntp = 0.0;
    double tai_minus_utc = 0.0;
    if (!(fields >> ntp >> tai_minus_utc) || !std::isfinite(ntp) ||
        !std::isfinite(tai_minus_utc)) {
      throw InputError(path, line_number,
                       "expected 'NTP_SECONDS TAI-UTC', got \"" + line + "\"");
    }
    const double unix_seconds = ntp - kNtpToUnixSeconds;
    if (!table.tai_minus_utc_.empty() &&
        unix_seconds <= table.tai_minus_utc_.back().first) {
      throw InputError(path, line_number, "dates do not increase");
    }
    table.tai_minus_utc_.emplace_back(unix_seconds, tai_minus_utc);
  }
  if (table.tai_minus_utc_.empty()) {
    throw InputError(path, 0, "no leap second in the list");
  }
  return table;
}

double LeapSeconds::GpsMinusUtc(double unix_seconds) const {
  if (unix_seconds < kGpsEpochUnixSeconds) return 0.0;
  // The last entry that applies at `unix_seconds`.
  auto after = std::upper_bound(
      tai_minus_utc_.begin(), tai_minus_utc_.end(), unix_seconds,
      [](double t, const std::pair<double, double>& e) { return t < e.first; });
  if (after == tai_minus_utc_.begin()) return 0.0;
  return std::prev(after)->second - kTaiMinusGps;
}

double GpsSecondsFromUnix(double unix_seconds,
                          const LeapSeconds& leap_seconds) {
  return unix_seconds - kGpsEpochUnixSeconds +
         leap_seconds.GpsMinusUtc(unix_seconds);
}

bool ParseUtcTimestamp(const std::string& text, double* unix_seconds) {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, consumed = 0;
  char separator = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2d%c%2d:%2d:%n", &year, &month, &day,
                  &separator, &hour, &minute, &consumed) != 6 ||
      (separator != 'T' && separator != ' ')) {
    return false;
  }
  std::string rest = text.substr(consumed);
  if (!rest.empty() && rest.back() == 'Z') rest.pop_back();
  if (rest.empty() || !(std::isdigit(static_cast<unsigned char>(rest[0])))) {
    return false;
  }
  size_t used = 0;
  double second = 0.0;
  try {
    second = std::stod(rest, &used);
  } catch (const std::exception&) {
    return false;
  }
  if (used != rest.size() || month < 1 || month > 12 || day < 1 ||
      day > DaysInMonth(year, month) || hour > 23 || minute > 59 ||
      !(second >= 0.0 && second < 61.0)) {
    return false;
  }
  *unix_seconds =
      static_cast<double>(DaysFromCivil(year, month, day)) * 86400.0 +
      hour * 3600.0 + minute * 60.0 + second;
  return true;
}

void UnwrapGpsWeekSeconds(std::vector<double>* times) {
  double offset = 0.0;
  double previous = 0.0;
  for (size_t i = 0; i < times->size(); ++i) {
    const double raw = (*times)[i];
    if (i > 0 && raw < previous - kSecondsPerGpsWeek / 2) {
      offset += kSecondsPerGpsWeek;
    }
    previous = raw;
    (*times)[i] = raw + offset;
  }
}

}  // namespace zebrageo
