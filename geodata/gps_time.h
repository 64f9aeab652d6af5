// GPS time and UTC.
//
// GPS time counts SI seconds from 1980-01-06 00:00:00 UTC without leap
// seconds; UTC has inserted leap seconds since, so GPS - UTC grows (18 s
// since 2017). Trajectory imports write the survey's clock as GPS seconds of
// week (the clock of SBET files, NovAtel logs and most camera trigger logs),
// counted from the week of the first record, so a survey crossing Saturday
// midnight keeps increasing past 604800 instead of wrapping.
//
// Leap seconds come from the IERS list that Debian's tzdata ships
// (/usr/share/zoneinfo/leap-seconds.list), never from a table in our code: a
// new leap second only needs a tzdata update.
#ifndef ZEBRAGEO_GEODATA_GPS_TIME_H_
#define ZEBRAGEO_GEODATA_GPS_TIME_H_

#include <string>
#include <utility>
#include <vector>

namespace zebrageo {

inline constexpr double kSecondsPerGpsWeek = 604800.0;
inline constexpr char kDefaultLeapSecondsFile[] =
    "/usr/share/zoneinfo/leap-seconds.list";

class LeapSeconds {
 public:
  // Reads an IERS/NTP leap-seconds.list ("NTP_SECONDS TAI-UTC" lines, "#@"
  // expiry). Throws InputError naming the file (and line) when it is
  // missing or malformed.
  static LeapSeconds Load(const std::string& path = kDefaultLeapSecondsFile);

  // GPS - UTC in seconds at the UTC instant `unix_seconds` (POSIX seconds
  // since 1970, leap seconds not counted). 0 before 1980.
  double GpsMinusUtc(double unix_seconds) const;
  // POSIX seconds after which the list is no longer guaranteed.
  double expires_unix_seconds() const { return expires_unix_seconds_; }

 private:
  // (POSIX seconds from which it applies, TAI - UTC), increasing.
  std::vector<std::pair<double, double>> tai_minus_utc_;
  double expires_unix_seconds_ = 0.0;
};

// Seconds since the GPS epoch of a UTC instant.
double GpsSecondsFromUnix(double unix_seconds, const LeapSeconds& leap_seconds);
// POSIX seconds of an ISO 8601 UTC timestamp, "2024-05-03T10:15:30.25Z"
// ('T' or ' ' between date and time, 'Z' optional, no other offset).
// False when `text` is not one.
bool ParseUtcTimestamp(const std::string& text, double* unix_seconds);

// Turns times that wrap at the end of a GPS week (seconds of week,
// 604799.9 -> 0.1) into increasing ones by adding a week after each wrap:
// a jump back of more than half a week is a new week, not disorder.
void UnwrapGpsWeekSeconds(std::vector<double>* times);

}  // namespace zebrageo

#endif  // ZEBRAGEO_GEODATA_GPS_TIME_H_
