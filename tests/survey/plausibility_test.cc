#include "survey/plausibility.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "survey/input_error.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

constexpr double kDegToRad = kPi / 180.0;
const Geodetic kStart{49.8941, 2.2958, 60.0};

struct DriveOptions {
  double rate_hz = 100.0;
  double duration_s = 20.0;
  double speed_mps = 10.0;
  double heading_deg = 65.0;  // clockwise from north, the direction driven
  double start_time = 302400.0;
  Geodetic start = kStart;
};

// A straight drive; sample k is on line k + 2 of its file.
std::vector<TrajectorySample> Drive(const DriveOptions& options) {
  const LocalFrame frame(options.start);
  const double heading = options.heading_deg * kDegToRad;
  const Eigen::Vector3d direction(std::sin(heading), std::cos(heading), 0.0);
  std::vector<TrajectorySample> samples;
  const int n = static_cast<int>(options.duration_s * options.rate_hz) + 1;
  for (int k = 0; k < n; ++k) {
    TrajectorySample s;
    const double t = k / options.rate_hz;
    s.time = options.start_time + t;
    s.position = frame.GeodeticFromEnu(options.speed_mps * t * direction);
    s.attitude = {1.0 * kDegToRad, 0.3 * kDegToRad, heading};
    s.line = k + 2;
    samples.push_back(s);
  }
  return samples;
}

// `samples` without those whose time is in (from, to).
std::vector<TrajectorySample> WithHole(std::vector<TrajectorySample> samples,
                                       double from, double to) {
  std::vector<TrajectorySample> kept;
  for (const TrajectorySample& s : samples) {
    if (!(s.time > from && s.time < to)) kept.push_back(s);
  }
  return kept;
}

// One image per exposure, every `spacing_s` from `first` to `last`; image
// i is on line i + 2.
ExposureTable Exposures(double first, double last, double spacing_s) {
  ExposureTable table;
  for (double t = first; t <= last + 1e-9; t += spacing_s) {
    const int i = static_cast<int>(table.images.size());
    ExposureImage image;
    image.exposure_id = 1000 + i;
    image.time = t;
    image.camera = 0;
    image.image = "images/" + std::to_string(i) + ".png";
    image.line = i + 2;
    table.images.push_back(image);
    table.exposures.push_back({image.exposure_id, t, {i}});
  }
  return table;
}

// One zebra band, 40 m east and 20 m north of `at`.
RoadmarkDatabase BandNear(const Geodetic& at) {
  const LocalFrame frame(at);
  RoadmarkBand band;
  band.crossing_id = "C1";
  band.band = 1;
  const Eigen::Vector3d corners[4] = {
      {40, 20, 0}, {40.5, 20, 0}, {40.5, 23, 0}, {40, 23, 0}};
  for (int i = 0; i < 4; ++i)
    band.corners[i] = frame.GeodeticFromEnu(corners[i]);
  band.sigma_xy_m = 0.05;
  band.sigma_z_m = 0.1;
  RoadmarkDatabase database;
  database.bands.push_back(band);
  return database;
}

// A survey for CheckPlausibility, its parts owned here.
struct Case {
  std::vector<TrajectorySample> samples = Drive(DriveOptions());
  std::optional<Geodetic> origin;
  ExposureTable exposures = Exposures(302400.1, 302419.9, 0.4);
  RoadmarkDatabase roadmarks = BandNear(kStart);
  bool with_roadmarks = true;

  std::vector<std::string> Check(
      const PlausibilityOptions& options = PlausibilityOptions()) const {
    const LocalFrame frame(origin.value_or(samples.front().position));
    const Trajectory trajectory(samples, frame);
    PlausibilityInput input;
    input.trajectory = &trajectory;
    input.exposures = &exposures;
    input.roadmarks = with_roadmarks ? &roadmarks : nullptr;
    input.origin = origin;
    input.origin_line = 6;
    input.frame = &frame;
    return CheckPlausibility(input, options);
  }
  std::string Error() const {
    try {
      Check();
    } catch (const InputError& error) {
      return error.what();
    }
    return "(no InputError)";
  }
};

TEST(Plausibility, APlausibleSurveyPassesWithoutWarnings) {
  Case c;
  c.origin = Geodetic{49.8941, 2.2958, 60.0};
  EXPECT_THAT(c.Check(), IsEmpty());
  // Not moving (a vehicle waiting at lights): nothing to check the heading
  // against, nothing to say.
  DriveOptions parked;
  parked.speed_mps = 0.0;
  c.samples = Drive(parked);
  EXPECT_THAT(c.Check(), IsEmpty());
}

TEST(Plausibility, WarnsAboutAGapNamingItsLinesAndTimes) {
  Case c;
  c.samples = WithHole(c.samples, 302406.0, 302409.0);
  c.exposures = Exposures(302400.1, 302405.9, 0.4);  // none in the gap
  const std::vector<std::string> warnings = c.Check();
  ASSERT_EQ(warnings.size(), 1u);
  // Samples 600 (line 602) and 900 (line 902) border the hole.
  EXPECT_THAT(warnings[0],
              AllOf(HasSubstr("trajectory.csv: 1 gap in the GNSS/INS solution "
                              "(median sample interval 0.01"),
                    HasSubstr("3.00 s with no sample (t = 302406 on line 602 "
                              "to 302409 on line 902)")));
}

TEST(Plausibility, AnExposureInALongGapIsAnErrorNamingItsLine) {
  Case c;
  c.samples = WithHole(c.samples, 302406.0, 302409.0);
  // Exposures every 0.4 s from 302400.1: the first in the hole is at
  // 302406.1, image 15 on line 17.
  EXPECT_THAT(
      c.Error(),
      AllOf(HasSubstr("exposures.csv:17: exposure 1015 at t = 302406.1"),
            HasSubstr("falls in a gap of trajectory.csv: 3.00 s with no "
                      "sample (t = 302406 on line 602 to 302409 on line 902)"),
            HasSubstr("(8 exposures are in gaps longer than "
                      "max_exposure_gap_s = 1 s)")));
}

TEST(Plausibility, AnExposureInAShortGapIsAWarning) {
  Case c;
  c.samples = WithHole(c.samples, 302406.0, 302406.6);
  const std::vector<std::string> warnings = c.Check();
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_THAT(warnings[1],
              AllOf(HasSubstr("exposures.csv:17: exposure 1015 at t = "
                              "302406.1"),
                    HasSubstr("falls in a gap of trajectory.csv: 0.60 s"),
                    HasSubstr("interpolated across the gap")));
}

TEST(Plausibility, AGapWithoutExposuresIsNeverAnError) {
  Case c;
  // Ten minutes without a sample, the exposures on either side.
  std::vector<TrajectorySample> samples = Drive(DriveOptions());
  for (TrajectorySample& s : samples) {
    if (s.time > 302409.0) s.time += 600.0;
  }
  c.samples = samples;
  c.exposures = Exposures(302400.1, 302408.9, 0.4);
  const std::vector<std::string> warnings = c.Check();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_THAT(warnings[0], HasSubstr("600.01 s with no sample"));
}

TEST(Plausibility, WarnsBelowTheContractsTenHertz) {
  for (const double rate_hz : {1.0, 5.0}) {
    Case c;
    DriveOptions slow;
    slow.rate_hz = rate_hz;
    c.samples = Drive(slow);
    const std::vector<std::string> warnings = c.Check();
    ASSERT_EQ(warnings.size(), 1u) << rate_hz;
    EXPECT_THAT(
        warnings[0],
        AllOf(HasSubstr("trajectory.csv: " +
                        std::to_string(static_cast<int>(rate_hz)) + ".0 Hz"),
              HasSubstr("below the 10 Hz the survey format asks for")));
  }
  Case ten_hertz;
  DriveOptions floor;
  floor.rate_hz = 10.0;
  ten_hertz.samples = Drive(floor);
  EXPECT_THAT(ten_hertz.Check(), IsEmpty());
}

TEST(Plausibility, AnglesInRadiansAreAnErrorNamingTheColumns) {
  Case c;
  // The file's numbers multiplied by pi / 180: read as degrees, each is the
  // true angle in radians.
  for (TrajectorySample& s : c.samples) {
    s.attitude.roll *= kDegToRad;
    s.attitude.pitch *= kDegToRad;
    s.attitude.heading *= kDegToRad;
  }
  EXPECT_THAT(c.Error(),
              AllOf(HasSubstr("trajectory.csv: columns 'roll', 'pitch', "
                              "'heading' look like radians, not degrees: "
                              "read as degrees, the heading differs from the "
                              "direction of travel by 63.9 deg, read as "
                              "radians by 0.0 deg"),
                    HasSubstr("lines 2-")));
}

TEST(Plausibility, AHeadingAcrossTheDirectionOfTravelIsAnError) {
  Case c;
  for (TrajectorySample& s : c.samples) s.attitude.heading += 90 * kDegToRad;
  EXPECT_THAT(c.Error(),
              HasSubstr("trajectory.csv: column 'heading' differs from the "
                        "direction of travel by 90.0 deg"));
}

TEST(Plausibility, AcceptsAHeadingThroughNorthAndACrabAngle) {
  for (const double heading_deg : {359.9, 0.1, 180.0, 270.0}) {
    Case c;
    DriveOptions north;
    north.heading_deg = heading_deg;
    c.samples = Drive(north);
    // A crab of 5 degrees (a vehicle on a slope, an INS misaligned): fine.
    for (TrajectorySample& s : c.samples) s.attitude.heading += 5 * kDegToRad;
    EXPECT_THAT(c.Check(), IsEmpty()) << heading_deg;
  }
}

TEST(Plausibility, SwappedLatitudeAndLongitudeAreNamedAgainstTheOrigin) {
  Case c;
  c.origin = kStart;
  for (TrajectorySample& s : c.samples) {
    std::swap(s.position.lat_deg, s.position.lon_deg);
  }
  // Swapping the origin would bring them together as well: the heading
  // tells which is wrong.
  EXPECT_THAT(c.Error(),
              AllOf(HasSubstr("trajectory.csv:"),
                    HasSubstr(": latitude and longitude look swapped: (lat, "
                              "lon) (2.29"),
                    HasSubstr("km from survey.yaml's origin (49.894100, "
                              "2.295800), swapped back"),
                    HasSubstr("its direction of travel then follows its "
                              "heading")));
  // Driving north-east, both readings follow the heading: either is named.
  DriveOptions diagonal;
  diagonal.heading_deg = 45.0;
  c.samples = Drive(diagonal);
  for (TrajectorySample& s : c.samples) {
    std::swap(s.position.lat_deg, s.position.lon_deg);
  }
  EXPECT_THAT(c.Error(), HasSubstr("survey.yaml:6: 'origin' (49.894100, "
                                   "2.295800) is 6920 km from the nearest "
                                   "sample of trajectory.csv"));
  EXPECT_THAT(c.Error(), HasSubstr(": latitude and longitude look swapped, "
                                   "in 'origin' ([lat, lon, h]) or in "
                                   "trajectory.csv"));
}

TEST(Plausibility, AnOriginFarFromTheTrajectoryIsAnErrorOnItsLine) {
  Case c;
  c.origin = Geodetic{50.9, 2.2958, 60.0};  // 112 km north
  EXPECT_THAT(c.Error(),
              AllOf(HasSubstr("survey.yaml:6: 'origin' (50.900000, 2.295800) "
                              "is 112 km from the nearest sample of "
                              "trajectory.csv (line 2"),
                    HasSubstr("more than max_origin_distance_m = 100 km")));
  c.origin = Geodetic{2.2958, 49.8941, 60.0};
  EXPECT_THAT(c.Error(), HasSubstr("'origin' looks like [lon, lat, h]"));
}

TEST(Plausibility, ADatabaseOfAnotherPlaceIsAnError) {
  Case c;
  // 54 degrees south: about 6,000 km.
  c.roadmarks = BandNear(Geodetic{kStart.lat_deg - 54.0, kStart.lon_deg, 60});
  EXPECT_THAT(
      c.Error(),
      AllOf(HasSubstr("roadmarks.geojson: the nearest of its 4 road-mark "
                      "vertices (-4.1"),
            HasSubstr("is 5983 km from the trajectory (trajectory.csv line 2"),
            HasSubstr("nothing in it can control the trajectory: a database "
                      "of another place?")));
  // Not loaded (reconstruct): not checked.
  c.with_roadmarks = false;
  EXPECT_THAT(c.Check(), IsEmpty());
  // Empty: warned about elsewhere (the contract allows an uncontrolled run).
  c.with_roadmarks = true;
  c.roadmarks = RoadmarkDatabase();
  EXPECT_THAT(c.Check(), IsEmpty());
}

TEST(Plausibility, SwapsAgainstTheDatabaseAreNamed) {
  Case c;  // no origin: the ENU origin is the (swapped) first sample
  for (TrajectorySample& s : c.samples) {
    std::swap(s.position.lat_deg, s.position.lon_deg);
  }
  EXPECT_THAT(c.Error(), HasSubstr("latitude and longitude of trajectory.csv "
                                   "look swapped (swapped back, its line"));
  // The database in [lat, lon] order: the trajectory follows its heading,
  // so the database is the one to fix.
  Case lat_lon_database;
  for (RoadmarkBand& band : lat_lon_database.roadmarks.bands) {
    for (Geodetic& corner : band.corners) {
      std::swap(corner.lat_deg, corner.lon_deg);
    }
  }
  EXPECT_THAT(lat_lon_database.Error(),
              HasSubstr("its coordinates look like [lat, lon]; GeoJSON (RFC "
                        "7946) writes [lon, lat, h]"));
}

TEST(Plausibility, ADatabaseWithinReachPassesEvenIfOnlyOneMarkIsNear) {
  Case c;
  RoadmarkDatabase database = BandNear(kStart);
  const RoadmarkDatabase far =
      BandNear(Geodetic{kStart.lat_deg - 54.0, kStart.lon_deg, 60});
  database.bands.insert(database.bands.end(), far.bands.begin(),
                        far.bands.end());
  c.roadmarks = database;
  EXPECT_THAT(c.Check(), IsEmpty());
}

TEST(PlausibilityOptions, CheckNamesTheFieldAndItsValue) {
  PlausibilityOptions options;
  EXPECT_EQ(options.Check(), "");
  options.max_exposure_gap_s = -1.0;
  EXPECT_EQ(options.Check(), "max_exposure_gap_s = -1: must be > 0");
  options = PlausibilityOptions();
  options.gaps.factor = 0.5;
  EXPECT_EQ(options.Check(), "gaps.factor = 0.5: must be > 1");
  options = PlausibilityOptions();
  options.min_heading_chords = 0;
  EXPECT_EQ(options.Check(), "min_heading_chords = 0: must be >= 1");
  Case c;
  EXPECT_THROW(c.Check(options), std::invalid_argument);
}

TEST(TrajectoryGaps, AreIntervalsFarAboveTheMedian) {
  // 10 Hz with one dropped sample (0.2 s: not a gap) and a 0.6 s hole.
  const std::vector<double> times = {0.0, 0.1, 0.2, 0.4, 0.5, 1.1, 1.2, 1.3};
  EXPECT_DOUBLE_EQ(MedianSampleInterval(times), 0.1);
  const std::vector<TrajectoryGap> gaps = FindTrajectoryGaps(times);
  ASSERT_EQ(gaps.size(), 1u);
  EXPECT_EQ(gaps[0].before, 4);
  EXPECT_DOUBLE_EQ(gaps[0].duration(), 0.6);
  // A 1 Hz trajectory's second between samples is its rate, not a gap.
  EXPECT_THAT(FindTrajectoryGaps({0, 1, 2, 3, 4}), IsEmpty());
  EXPECT_THAT(FindTrajectoryGaps({0.0}), IsEmpty());
}

}  // namespace
}  // namespace zebrageo
