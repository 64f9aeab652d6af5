#include "survey/geodesy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "survey/math_util.h"
#include "survey/trajectory.h"
#include "tests/survey/test_util.h"

namespace zebrageo {
namespace {

constexpr double kDeg = kPi / 180.0;

// Independent WGS84 geodesy, written from the textbook formulas and sharing
// nothing with GeographicLib: geodetic -> ECEF and the ENU axes in ECEF.
Eigen::Vector3d EcefFromGeodetic(const Geodetic& g) {
  const double a = 6378137.0, f = 1.0 / 298.257223563, e2 = f * (2.0 - f);
  const double lat = g.lat_deg * kDeg, lon = g.lon_deg * kDeg;
  const double n = a / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat));
  return {(n + g.h_m) * std::cos(lat) * std::cos(lon),
          (n + g.h_m) * std::cos(lat) * std::sin(lon),
          (n * (1.0 - e2) + g.h_m) * std::sin(lat)};
}

// Columns: east, north, up unit vectors at (lat, lon), in ECEF.
Eigen::Matrix3d RotationEcefFromEnu(const Geodetic& g) {
  const double lat = g.lat_deg * kDeg, lon = g.lon_deg * kDeg;
  Eigen::Matrix3d R;
  R.col(0) << -std::sin(lon), std::cos(lon), 0.0;
  R.col(1) << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon),
      std::cos(lat);
  R.col(2) << std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon),
      std::sin(lat);
  return R;
}

const Geodetic kAmiens{49.8941, 2.2958, 60.0};

TEST(LocalFrame, EnuRoundTripsBelowOneMillimetreOver20Km) {
  const LocalFrame frame(kAmiens);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  std::uniform_real_distribution<double> range(0.0, 20000.0);
  std::uniform_real_distribution<double> height(-100.0, 300.0);
  double worst_m = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double a = angle(rng), r = range(rng);
    const Eigen::Vector3d p(r * std::cos(a), r * std::sin(a), height(rng));
    const Geodetic g = frame.GeodeticFromEnu(p);
    worst_m = std::max(worst_m, (frame.EnuFromGeodetic(g) - p).norm());
  }
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_m, 1e-6);  // GeographicLib is exact to nanometres
}

TEST(LocalFrame, EnuAgreesWithIndependentEcefComputationOver20Km) {
  const LocalFrame frame(kAmiens);
  const Eigen::Vector3d origin_ecef = EcefFromGeodetic(kAmiens);
  const Eigen::Matrix3d R_ecef_enu0 = RotationEcefFromEnu(kAmiens);
  for (const Geodetic& g :
       {Geodetic{49.8941 + 0.18, 2.2958, 75.0},  // 20 km north
        Geodetic{49.8941, 2.2958 + 0.28, 20.0},  // 20 km east
        Geodetic{49.8941 - 0.12, 2.2958 - 0.2, 160.0}}) {
    const Eigen::Vector3d expected =
        R_ecef_enu0.transpose() * (EcefFromGeodetic(g) - origin_ecef);
    EXPECT_GT(expected.head<2>().norm(), 13000.0);
    EXPECT_LT((frame.EnuFromGeodetic(g) - expected).norm(), 1e-3);
  }
}

TEST(Attitude, RotationMatchesTheFormatsEulerSequence) {
  // Heading 90 deg (east), level: body x (forward) points east in NED = (0, 1,
  // 0).
  const Eigen::Matrix3d R = RotationNedFromBody({0.0, 0.0, 90.0 * kDeg});
  EXPECT_TRUE(R.col(0).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
  // Pitch up 10 deg: forward gets a negative down component.
  const Eigen::Matrix3d P = RotationNedFromBody({0.0, 10.0 * kDeg, 0.0});
  EXPECT_NEAR(P(2, 0), -std::sin(10.0 * kDeg), 1e-15);
  // Roll right 5 deg: body y (right) gets a positive down component.
  const Eigen::Matrix3d Q = RotationNedFromBody({5.0 * kDeg, 0.0, 0.0});
  EXPECT_NEAR(Q(2, 1), std::sin(5.0 * kDeg), 1e-15);
}

TEST(Attitude, RoundTripsAndNormalisesRanges) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> roll(-kPi + 1e-6, kPi);
  std::uniform_real_distribution<double> pitch(-kPi / 2 + 1e-3, kPi / 2 - 1e-3);
  std::uniform_real_distribution<double> heading(0.0, 2.0 * kPi);
  for (int i = 0; i < 1000; ++i) {
    const Attitude in{roll(rng), pitch(rng), heading(rng)};
    const Attitude out = AttitudeFromRotationNedBody(RotationNedFromBody(in));
    EXPECT_NEAR(out.roll, in.roll, 1e-9);
    EXPECT_NEAR(out.pitch, in.pitch, 1e-9);
    EXPECT_NEAR(std::remainder(out.heading - in.heading, 2 * kPi), 0.0, 1e-9);
    EXPECT_GE(out.heading, 0.0);
    EXPECT_LT(out.heading, 2.0 * kPi);
  }
  // A heading of -1 deg comes back as 359 deg.
  const Attitude wrapped =
      AttitudeFromRotationNedBody(RotationNedFromBody({0.0, 0.0, -kDeg}));
  EXPECT_NEAR(wrapped.heading, 359.0 * kDeg, 1e-12);
}

TEST(LocalFrame, AttitudeChainMatchesEcefRotationsFiveKmFromOrigin) {
  const LocalFrame frame(kAmiens);
  // A vehicle 5 km north-east of the origin: its NED frame is tilted by
  // about 5 km / 6378 km = 0.78 mrad relative to the origin's.
  const Geodetic vehicle{49.8941 + 0.032, 2.2958 + 0.049, 85.0};
  const Attitude attitude{1.5 * kDeg, -3.0 * kDeg, 237.0 * kDeg};
  Eigen::Matrix3d R_ned_enu_vehicle;
  R_ned_enu_vehicle << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d expected =
      RotationEcefFromEnu(kAmiens).transpose() * RotationEcefFromEnu(vehicle) *
      R_ned_enu_vehicle.transpose() * RotationNedFromBody(attitude);
  const Eigen::Matrix3d actual = frame.RotationEnuFromBody(vehicle, attitude);
  EXPECT_LT((actual - expected).norm(), 1e-12);
  // The test discriminates: using NED at the origin instead would be off by
  // the meridian convergence and the tilt.
  const Eigen::Matrix3d wrong =
      RotationEnuFromNed() * RotationNedFromBody(attitude);
  EXPECT_GT(Eigen::AngleAxisd(wrong.transpose() * expected).angle(), 5e-4);
  // And the inverse recovers the INS attitude.
  const Attitude back = frame.AttitudeFromRotationEnuBody(vehicle, actual);
  EXPECT_NEAR(back.roll, attitude.roll, 1e-12);
  EXPECT_NEAR(back.pitch, attitude.pitch, 1e-12);
  EXPECT_NEAR(back.heading, attitude.heading, 1e-12);
}

TEST(LocalFrame, RejectsInvalidOrigin) {
  EXPECT_THROW(LocalFrame(Geodetic{91.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(LocalFrame(Geodetic{NAN, 0.0, 0.0}), std::invalid_argument);
}

// --- Real data: comma2k19 (MIT), a real drive with ECEF poses. ---

// Reads a little-endian float64 .npy array (the dataset's raw files).
std::vector<double> ReadNpyDoubles(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8];
  in.read(magic, 8);
  uint16_t header_length = 0;
  in.read(reinterpret_cast<char*>(&header_length), 2);
  in.seekg(10 + header_length);
  std::vector<double> values;
  double value;
  while (in.read(reinterpret_cast<char*>(&value), sizeof(value))) {
    values.push_back(value);
  }
  return values;
}

// comma2k19's CSV has no sd_* columns: add zero ones for the reader.
std::string CommaCsvWithSdColumns(const std::string& path) {
  std::ifstream in(path);
  std::string line, text;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    text += line + (header ? ",sd_e,sd_n,sd_u,sd_roll,sd_pitch,sd_heading"
                           : ",0,0,0,0,0,0");
    text += "\n";
    header = false;
  }
  return text;
}

TEST(LocalFrame, AttitudeChainReproducesRealEcefOrientations) {
  const std::string datasets = SharedDatasetsFolder();
  if (datasets.empty()) GTEST_SKIP() << "../shared/datasets is absent";
  const std::string comma = datasets + "/trajectories/comma2k19/";
  const std::vector<TrajectorySample> samples = ParseTrajectorySamples(
      CommaCsvWithSdColumns(comma + "comma2k19_example1.csv"), "comma.csv");
  const std::vector<double> q =
      ReadNpyDoubles(comma + "raw/global_pose/frame_orientations");
  const std::vector<double> x =
      ReadNpyDoubles(comma + "raw/global_pose/frame_positions");
  ASSERT_EQ(samples.size(), 1200u);
  ASSERT_EQ(q.size(), 4 * samples.size());
  ASSERT_EQ(x.size(), 3 * samples.size());

  const LocalFrame frame(samples.front().position);
  const Eigen::Matrix3d R_ecef_enu0 =
      RotationEcefFromEnu(samples.front().position);
  const Eigen::Vector3d origin_ecef(x[0], x[1], x[2]);
  double worst_angle = 0.0, worst_position = 0.0, max_range = 0.0;
  for (size_t i = 0; i < samples.size(); ++i) {
    // comma's quaternion is Hamilton [w, x, y, z] of R_ecef_device.
    const Eigen::Quaterniond q_ecef_body(q[4 * i], q[4 * i + 1], q[4 * i + 2],
                                         q[4 * i + 3]);
    const Eigen::Matrix3d expected =
        R_ecef_enu0.transpose() * q_ecef_body.normalized().toRotationMatrix();
    const Eigen::Matrix3d actual =
        frame.RotationEnuFromBody(samples[i].position, samples[i].attitude);
    worst_angle = std::max(
        worst_angle, Eigen::AngleAxisd(actual.transpose() * expected).angle());
    const Eigen::Vector3d expected_enu =
        R_ecef_enu0.transpose() *
        (Eigen::Vector3d(x[3 * i], x[3 * i + 1], x[3 * i + 2]) - origin_ecef);
    const Eigen::Vector3d p = frame.EnuFromGeodetic(samples[i].position);
    worst_position = std::max(worst_position, (p - expected_enu).norm());
    max_range = std::max(max_range, p.norm());
  }
  EXPECT_GT(max_range, 1000.0);
  // The CSV rounds angles to 1e-6 deg and positions to ~0.1 mm.
  EXPECT_LT(worst_angle, 1e-6);
  EXPECT_LT(worst_position, 2e-3);
}

TEST(Trajectory, RealDriveMovesAlongBodyForwardAxis) {
  const std::string datasets = SharedDatasetsFolder();
  if (datasets.empty()) GTEST_SKIP() << "../shared/datasets is absent";
  const std::vector<TrajectorySample> samples = ParseTrajectorySamples(
      CommaCsvWithSdColumns(datasets + "/trajectories/comma2k19/"
                                       "comma2k19_example1.csv"),
      "comma.csv");
  const Trajectory trajectory(samples, LocalFrame(samples.front().position));
  Eigen::Vector3d mean_direction = Eigen::Vector3d::Zero();
  for (int i = 0; i + 1 < trajectory.size(); ++i) {
    const Pose& a = trajectory.poses()[i];
    const Pose& b = trajectory.poses()[i + 1];
    const Eigen::Vector3d v_body =
        a.q_enu_body.conjugate() * (b.p_enu - a.p_enu);
    mean_direction += v_body.normalized();
  }
  mean_direction /= trajectory.size() - 1;
  // The device looks forward, pitched down ~3.7 deg (datasets/README.md).
  EXPECT_GT(mean_direction.x(), 0.99);
  EXPECT_LT(std::abs(mean_direction.y()), 0.05);
  EXPECT_LT(std::abs(mean_direction.z()), 0.1);
}

}  // namespace
}  // namespace zebrageo
