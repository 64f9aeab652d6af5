// INS trajectory imports against a simulated survey's trajectory: each
// format is written by the test from the simulation (its own conventions
// implemented here from the formats' documentation), read back by
// geodata/, and compared pose by pose.
#include "geodata/trajectory_import.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "geodata/gps_time.h"
#include "simulator/simulator.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

// The simulated survey's (measured) trajectory, at 100 Hz with real sd_*.
std::vector<TrajectorySample> SimulatedTrajectory(const TemporaryFolder& tmp) {
  SimulationOptions options;
  options.preset = "test";
  options.seed = 7;
  options.road_length_m = 120.0;
  options.num_crossings = 1;
  options.num_stale_crossings = 0;
  options.min_crossing_spacing_m = 20.0;
  options.render_images = false;
  options.threads = 1;
  SimulateSurvey(options, tmp.Path("survey"), nullptr);
  return ReadTrajectorySamples(tmp.Path("survey/trajectory.csv"),
                               "trajectory.csv");
}

// Largest position difference (m) and attitude difference (deg, the angle
// of R_a^T R_b) between two trajectories of the same times.
void ExpectSamePoses(const std::vector<TrajectorySample>& expected,
                     const std::vector<TrajectorySample>& actual,
                     double time_offset = 0.0) {
  ASSERT_EQ(expected.size(), actual.size());
  const LocalFrame frame(expected.front().position);
  double max_position_m = 0.0;
  double max_angle_deg = 0.0;
  double max_time_s = 0.0;
  for (size_t i = 0; i < expected.size(); ++i) {
    const TrajectorySample& e = expected[i];
    const TrajectorySample& a = actual[i];
    max_time_s = std::max(max_time_s, std::abs(e.time + time_offset - a.time));
    max_position_m = std::max(
        max_position_m,
        (frame.EnuFromGeodetic(e.position) - frame.EnuFromGeodetic(a.position))
            .norm());
    const Eigen::Matrix3d R = RotationNedFromBody(e.attitude).transpose() *
                              RotationNedFromBody(a.attitude);
    max_angle_deg =
        std::max(max_angle_deg, RadToDeg(Eigen::AngleAxisd(R).angle()));
  }
  EXPECT_LT(max_time_s, 1e-6);
  EXPECT_LT(max_position_m, 0.001);
  EXPECT_LT(max_angle_deg, 0.001);
}

void PutLittleEndian(double value, std::string* out) {
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 8; ++i)
    out->push_back(static_cast<char>(bits >> (8 * i)));
}

// SBET records (17 doubles); the wander angle and the velocities in the
// wander frame are filled in, as POSPac does, and must not disturb the
// attitude.
std::string SbetBytes(const std::vector<TrajectorySample>& samples,
                      double week_offset_s) {
  std::string bytes;
  for (size_t i = 0; i < samples.size(); ++i) {
    const TrajectorySample& s = samples[i];
    const double wander = 0.3 + 0.01 * i;
    double time = s.time + week_offset_s;
    if (time >= kSecondsPerGpsWeek) time -= kSecondsPerGpsWeek;
    const double record[17] = {time,
                               DegToRad(s.position.lat_deg),
                               DegToRad(s.position.lon_deg),
                               s.position.h_m,
                               8.0 * std::cos(wander),
                               -8.0 * std::sin(wander),
                               0.1,
                               s.attitude.roll,
                               s.attitude.pitch,
                               s.attitude.heading,
                               wander,
                               0.1,
                               0.2,
                               -9.8,
                               0.001,
                               0.002,
                               0.003};
    for (double v : record) PutLittleEndian(v, &bytes);
  }
  return bytes;
}

// smrmsg at 1 Hz: north, east, down position RMS, velocity RMS, attitude
// RMS in arc minutes, varying linearly in time so interpolation is exact.
std::string SmrmsgBytes(double start, double end) {
  std::string bytes;
  for (double t = std::floor(start); t <= end + 1.0; t += 1.0) {
    const double u = t - start;
    const double record[10] = {t,
                               0.02 + 0.001 * u,
                               0.03 + 0.002 * u,
                               0.05,
                               0.01,
                               0.01,
                               0.01,
                               0.6 + 0.01 * u,
                               0.7,
                               1.2 + 0.02 * u};
    for (double v : record) PutLittleEndian(v, &bytes);
  }
  return bytes;
}

TEST(SbetImport, SimulatedTrajectoryReadsBackToTheSamePosesAndAccuracies) {
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  ASSERT_GT(truth.size(), 100u);
  const std::string sbet = tmp.Write("sbet_test.out", SbetBytes(truth, 0.0));
  const std::string smrmsg = tmp.Write(
      "smrmsg_test.out", SmrmsgBytes(truth.front().time, truth.back().time));
  const std::vector<TrajectorySample> read = ReadSbet(sbet, smrmsg);
  ExpectSamePoses(truth, read);
  for (const TrajectorySample& s : read) {
    const double u = s.time - truth.front().time;
    ASSERT_NEAR(s.sd_enu_m.x(), 0.03 + 0.002 * u, 1e-9);  // east
    ASSERT_NEAR(s.sd_enu_m.y(), 0.02 + 0.001 * u, 1e-9);  // north
    ASSERT_NEAR(s.sd_enu_m.z(), 0.05, 1e-9);
    ASSERT_NEAR(RadToDeg(s.sd_attitude_rad.z()) * 60.0, 1.2 + 0.02 * u, 1e-9);
  }
}

TEST(SbetImport, TimesCrossingTheEndOfAGpsWeekKeepIncreasing) {
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  // Shift the survey so that it crosses Saturday midnight half way.
  const double mid = 0.5 * (truth.front().time + truth.back().time);
  const double offset = kSecondsPerGpsWeek - mid;
  const std::string sbet = tmp.Write("sbet.out", SbetBytes(truth, offset));
  ExpectSamePoses(truth, ReadSbet(sbet, ""), offset);
}

TEST(SbetImport, TruncatedFileNamesTheTruncatedRecord) {
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  std::string bytes = SbetBytes(truth, 0.0);
  bytes.resize(bytes.size() - 50);
  const std::string sbet = tmp.Write("sbet_cut.out", bytes);
  try {
    ReadSbet(sbet, "");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sbet_cut.out"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(
                  "record " + std::to_string(truth.size()) + " is truncated"),
              std::string::npos)
        << e.what();
  }
}

TEST(SbetImport, DegreesInsteadOfRadiansAreRefusedWithTheRecord) {
  TemporaryFolder tmp;
  std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  std::string bytes = SbetBytes(truth, 0.0);
  // Record 3's latitude written in degrees (49.9 > pi/2).
  std::string degrees;
  PutLittleEndian(truth[2].position.lat_deg, &degrees);
  bytes.replace(2 * kSbetRecordBytes + 8, 8, degrees);
  const std::string sbet = tmp.Write("sbet.out", bytes);
  EXPECT_THROW(
      {
        try {
          ReadSbet(sbet, "");
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("record 3 "), std::string::npos)
              << e.what();
          throw;
        }
      },
      InputError);
}

// NovAtel's CRC-32 through zlib (see geodata/novatel.cc), checked here on
// the example record of NovAtel's INSPVAX documentation (OEM7 manual; the
// web page drops the minus signs of the longitude, undulation and
// velocities, which the CRC restores: Calgary is at 114 W).
uint32_t NovatelCrc(const std::string& content) {
  return static_cast<uint32_t>(
      crc32(0xFFFFFFFFUL, reinterpret_cast<const Bytef*>(content.data()),
            static_cast<uInt>(content.size())) ^
      0xFFFFFFFFUL);
}

constexpr char kNovatelDocumentationRecord[] =
    "#INSPVAXA,COM3,0,53.0,FINESTEERING,2175,235409.000,02004820,46eb,32768;"
    "INS_ALIGNMENT_COMPLETE,INS_PSRSP,51.15039052936,-114.03070375311,"
    "1098.5442,-17.0000,-0.0025,-0.0012,-0.0002,0.688984419,0.654219583,"
    "348.427063661,1.2792,1.2780,1.2934,0.0228,0.0228,0.0140,0.0516,0.0516,"
    "9.3595,07000005,0*ca760b9b";

TEST(NovatelImport, CrcMatchesNovatelsDocumentedRecord) {
  const std::string record = kNovatelDocumentationRecord;
  const size_t star = record.find('*');
  EXPECT_EQ(NovatelCrc(record.substr(1, star - 1)), 0xca760b9bu);
}

TEST(NovatelImport, DocumentedRecordReadsItsFields) {
  TemporaryFolder tmp;
  // Two records one second apart (the second with its CRC recomputed).
  std::string second = kNovatelDocumentationRecord;
  second.replace(second.find("235409.000"), 10, "235410.000");
  second = second.substr(0, second.find('*'));
  std::ostringstream crc;
  crc << std::hex << std::setw(8) << std::setfill('0')
      << NovatelCrc(second.substr(1));
  const std::string path =
      tmp.Write("span.log", std::string(kNovatelDocumentationRecord) +
                                "\r\n#BESTPOSA,COM1,0;other log*00000000\r\n" +
                                second + "*" + crc.str() + "\r\n");
  const std::vector<TrajectorySample> read = ReadNovatelAscii(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_DOUBLE_EQ(read[0].time, 235409.0);
  EXPECT_DOUBLE_EQ(read[1].time, 235410.0);
  EXPECT_DOUBLE_EQ(read[0].position.lat_deg, 51.15039052936);
  EXPECT_NEAR(read[0].position.h_m, 1098.5442 - 17.0, 1e-9);  // MSL + N
  EXPECT_NEAR(read[0].sd_enu_m.x(), 1.2780, 1e-9);  // longitude sd: east
  EXPECT_NEAR(read[0].sd_enu_m.y(), 1.2792, 1e-9);
  EXPECT_NEAR(RadToDeg(read[0].sd_attitude_rad.z()), 9.3595, 1e-9);
  // Small roll and pitch: the heading is the azimuth to a few 1e-3 deg.
  EXPECT_NEAR(RadToDeg(read[0].attitude.heading), 348.427063661, 0.01);
}

// SPAN angles of R_ned_body: R_enu_rfu = Rz(-azimuth) Rx(pitch) Ry(roll)
// (NovAtel APN-037: roll about y, pitch about x, azimuth clockwise about z),
// so pitch = asin(R(2,1)), roll = atan2(-R(2,0), R(2,2)), azimuth =
// atan2(R(0,1), R(1,1)).
void SpanAngles(const Attitude& attitude, double* roll, double* pitch,
                double* azimuth) {
  Eigen::Matrix3d R_enu_ned;
  R_enu_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  Eigen::Matrix3d R_frd_rfu;
  R_frd_rfu << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d R =
      R_enu_ned * RotationNedFromBody(attitude) * R_frd_rfu;
  *pitch = RadToDeg(std::asin(R(2, 1)));
  *roll = RadToDeg(std::atan2(-R(2, 0), R(2, 2)));
  *azimuth = RadToDeg(std::atan2(R(0, 1), R(1, 1)));
  if (*azimuth < 0) *azimuth += 360.0;
}

std::string NovatelLog(const std::vector<TrajectorySample>& samples,
                       double roll_offset_deg) {
  constexpr double kUndulation = 47.25;
  std::ostringstream log;
  for (const TrajectorySample& s : samples) {
    Attitude attitude = s.attitude;
    attitude.roll += DegToRad(roll_offset_deg);
    double roll, pitch, azimuth;
    SpanAngles(attitude, &roll, &pitch, &azimuth);
    std::ostringstream content;
    content << std::setprecision(17) << "INSPVAXA,USB1,0,50.0,FINESTEERING,"
            << 2300 << "," << s.time << ",00000000,0000,16809;"
            << "INS_SOLUTION_GOOD,INS_RTKFIXED," << s.position.lat_deg << ","
            << s.position.lon_deg << "," << s.position.h_m - kUndulation << ","
            << kUndulation << ",1.0,2.0,0.0," << roll << "," << pitch << ","
            << azimuth << ",0.011,0.012,0.02,0.01,0.01,0.01,0.004,0.005,0.03,"
            << "00000000,0";
    log << "#" << content.str() << "*" << std::hex << std::setw(8)
        << std::setfill('0') << NovatelCrc(content.str()) << std::dec << "\r\n";
  }
  return log.str();
}

TEST(NovatelImport, SimulatedTrajectoryReadsBackToTheSamePoses) {
  TemporaryFolder tmp;
  std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  // A 4-degree roll, so that SPAN's Z-X-Y angle order differs measurably
  // from the contract's Z-Y-X (by about roll x pitch: read angle by angle
  // they would be a few 1e-2 deg off).
  const std::string path = tmp.Write("span.log", NovatelLog(truth, 4.0));
  for (TrajectorySample& s : truth) s.attitude.roll += DegToRad(4.0);
  const std::vector<TrajectorySample> read = ReadNovatelAscii(path);
  ExpectSamePoses(truth, read);
  EXPECT_NEAR(read[5].sd_enu_m.x(), 0.012, 1e-12);
  EXPECT_NEAR(RadToDeg(read[5].sd_attitude_rad.y()), 0.005, 1e-12);
}

TEST(NovatelImport, GarbledRecordIsACrcErrorNamingTheLine) {
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  std::string log = NovatelLog(truth, 0.0);
  // Flip one digit of the 10th record's latitude.
  size_t line_start = 0;
  for (int i = 0; i < 9; ++i) line_start = log.find('\n', line_start) + 1;
  const size_t digit = log.find("RTKFIXED,", line_start) + 12;
  log[digit] = log[digit] == '7' ? '8' : '7';
  const std::string path = tmp.Write("span.log", log);
  try {
    ReadNovatelAscii(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 10);
    EXPECT_NE(e.problem().find("CRC mismatch"), std::string::npos) << e.what();
  }
  // Cut in the middle of a record.
  const std::string cut = tmp.Write("cut.log", log.substr(0, line_start + 80));
  try {
    ReadNovatelAscii(cut);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 10);
    EXPECT_NE(e.problem().find("truncated"), std::string::npos) << e.what();
  }
}

// GPS seconds of week 2300 to ISO 8601 UTC: UTC = GPS - 18 s (the leap
// seconds since 2017), formatted with the C library.
std::string UtcText(double seconds_of_week) {
  constexpr double kGpsEpochUnix = 315964800.0;
  const double unix_seconds =
      kGpsEpochUnix + 2300 * kSecondsPerGpsWeek + seconds_of_week - 18.0;
  const std::time_t whole = static_cast<std::time_t>(std::floor(unix_seconds));
  std::tm utc{};
  gmtime_r(&whole, &utc);
  char text[64];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%S", &utc);
  std::ostringstream out;
  out << text << "." << std::setw(6) << std::setfill('0')
      << std::llround((unix_seconds - whole) * 1e6) << "Z";
  return out.str();
}

TEST(CsvTrajectoryImport, InertialExplorerStyleExportInUtcAndRadians) {
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  std::ostringstream text;
  text << "# Inertial Explorer export, custom profile\n"
       << "UTCTime  Latitude  Longitude  H-Ell  Roll  Pitch  Heading  SDEast  "
          "SDNorth  SDHeight  RollSD  PitchSD  HdngSD\n"
       << std::setprecision(17);
  for (const TrajectorySample& s : truth) {
    text << UtcText(s.time) << "  " << DegToRad(s.position.lat_deg) << " "
         << DegToRad(s.position.lon_deg) << " " << s.position.h_m << " "
         << s.attitude.roll << " " << s.attitude.pitch << " "
         << s.attitude.heading << " " << s.sd_enu_m.x() << " " << s.sd_enu_m.y()
         << " " << s.sd_enu_m.z() << " " << s.sd_attitude_rad.x() << " "
         << s.sd_attitude_rad.y() << " " << s.sd_attitude_rad.z() << "\n";
  }
  const std::string path = tmp.Write("ie_export.txt", text.str());
  CsvTrajectoryFormat format;
  ASSERT_EQ(ParseColumnMap("time=UTCTime,lat=Latitude,lon=Longitude,h=H-Ell,"
                           "roll=Roll,pitch=Pitch,heading=Heading,sd_e=SDEast,"
                           "sd_n=SDNorth,sd_u=SDHeight,sd_roll=RollSD,"
                           "sd_pitch=PitchSD,sd_heading=HdngSD",
                           &format),
            "");
  format.angle_unit = AngleUnit::kRadians;
  format.time_kind = TimeKind::kUtc;
  format.delimiter = Delimiter::kWhitespace;
  const std::vector<TrajectorySample> read = ReadTrajectoryCsv(path, format);
  ExpectSamePoses(truth, read);
  EXPECT_NEAR(read[3].sd_attitude_rad.z(), truth[3].sd_attitude_rad.z(), 1e-15);
}

// An export in UTM 31N with EGM96 heights (the geoid grid proj-data ships):
// its coordinates made by PROJ's own cs2cs from the simulated trajectory,
// read back through the CRS wrapper to the same poses.
TEST(CsvTrajectoryImport, ProjectedCrsWithGeoidHeightsReadsBack) {
  if (std::system("command -v cs2cs >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "cs2cs (proj-bin) is not installed";
  }
  TemporaryFolder tmp;
  const std::vector<TrajectorySample> truth = SimulatedTrajectory(tmp);
  {
    std::ofstream out(tmp.Path("wgs84.txt"));
    out << std::setprecision(17);
    for (const TrajectorySample& s : truth) {
      out << s.position.lat_deg << " " << s.position.lon_deg << " "
          << s.position.h_m << "\n";
    }
  }
  ASSERT_EQ(
      std::system(("cs2cs -f %.6f EPSG:4979 EPSG:32631+5773 < '" +
                   tmp.Path("wgs84.txt") + "' > '" + tmp.Path("utm.txt") + "'")
                      .c_str()),
      0);
  std::ifstream utm(tmp.Path("utm.txt"));
  std::ostringstream text;
  text << "GPSTime,Easting,Northing,H-MSL,Roll,Pitch,Heading\n"
       << std::setprecision(17);
  double first_height = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    double x = 0.0, y = 0.0, h = 0.0;
    ASSERT_TRUE(utm >> x >> y >> h);
    if (i == 0) first_height = h;
    const TrajectorySample& s = truth[i];
    text << s.time << "," << x << "," << y << "," << h << ","
         << RadToDeg(s.attitude.roll) << "," << RadToDeg(s.attitude.pitch)
         << "," << RadToDeg(s.attitude.heading) << "\n";
  }
  // The geoid is applied (EGM96 is 40-50 m above the ellipsoid in France):
  // a silently ellipsoidal height would not be 40 m off.
  EXPECT_GT(truth.front().position.h_m - first_height, 40.0);
  const std::string path = tmp.Write("utm_export.csv", text.str());
  CsvTrajectoryFormat format;
  ASSERT_EQ(ParseColumnMap("time=GPSTime,x=Easting,y=Northing,h=H-MSL,"
                           "roll=Roll,pitch=Pitch,heading=Heading",
                           &format),
            "");
  format.crs = "EPSG:32631+5773";
  ExpectSamePoses(truth, ReadTrajectoryCsv(path, format));
}

TEST(CsvTrajectoryImport, BadRowNamesTheLineAndColumn) {
  TemporaryFolder tmp;
  const std::string path = tmp.Write("t.csv",
                                     "t,lat,lon,h,roll,pitch,heading\n"
                                     "100.0,49.0,2.0,60,0,0,10\n"
                                     "100.1,49.0,2.0,60,0,zero,10\n");
  CsvTrajectoryFormat format;
  ASSERT_EQ(ParseColumnMap("time=t", &format), "");
  try {
    ReadTrajectoryCsv(path, format);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(e.problem().find("'pitch'"), std::string::npos) << e.what();
  }
  EXPECT_NE(ParseColumnMap("yaw=Heading", &format), "");
}

TEST(GpsTime, LeapSecondsFromTheIersListOfTzdata) {
  const LeapSeconds leap = LeapSeconds::Load();
  double unix_seconds = 0.0;
  ASSERT_TRUE(ParseUtcTimestamp("2016-12-31T23:59:59Z", &unix_seconds));
  EXPECT_EQ(leap.GpsMinusUtc(unix_seconds), 17.0);
  ASSERT_TRUE(ParseUtcTimestamp("2017-01-01 00:00:00", &unix_seconds));
  EXPECT_EQ(leap.GpsMinusUtc(unix_seconds), 18.0);
  ASSERT_TRUE(ParseUtcTimestamp("1980-01-06T00:00:00Z", &unix_seconds));
  EXPECT_EQ(GpsSecondsFromUnix(unix_seconds, leap), 0.0);
  EXPECT_FALSE(ParseUtcTimestamp("2017-02-30T00:00:00Z", &unix_seconds));
  EXPECT_FALSE(ParseUtcTimestamp("2017-01-01T00:00:00+02:00", &unix_seconds));
  EXPECT_THROW(LeapSeconds::Load("/nonexistent/leap-seconds.list"), InputError);
}

}  // namespace
}  // namespace zebrageo
