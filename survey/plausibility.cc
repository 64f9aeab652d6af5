#include "survey/plausibility.h"

#include <glog/logging.h>

#include <GeographicLib/Geodesic.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Gaps listed one by one in the warnings before "and N more".
constexpr int kMaxListedGaps = 3;

// A sample interval for messages: 3 significant digits ("0.01", "0.2").
std::string Interval(double seconds) {
  std::ostringstream text;
  text.precision(3);
  text << seconds;
  return text.str();
}

// "850 m" or "6012 km" (message text).
std::string Distance(double metres) {
  if (metres < 10e3) return FormatFixed(metres, 0) + " m";
  return FormatFixed(metres / 1e3, 0) + " km";
}

std::string LatLon(const Geodetic& g) {
  return "(" + FormatFixed(g.lat_deg, 6) + ", " + FormatFixed(g.lon_deg, 6) +
         ")";
}

double GeodesicDistance(const Geodetic& a, const Geodetic& b) {
  double distance = 0.0;
  GeographicLib::Geodesic::WGS84().Inverse(a.lat_deg, a.lon_deg, b.lat_deg,
                                           b.lon_deg, distance);
  return distance;
}

// `g` with latitude and longitude exchanged, when that is still a position
// (|lon| <= 90), else nullopt.
std::optional<Geodetic> Swapped(const Geodetic& g) {
  if (std::abs(g.lon_deg) > 90.0) return std::nullopt;
  return Geodetic{g.lon_deg, g.lat_deg, g.h_m};
}

// Angle in (-pi, pi].
double WrapPi(double angle) {
  double wrapped = std::remainder(angle, 2.0 * kPi);
  if (wrapped <= -kPi) wrapped += 2.0 * kPi;
  return wrapped;
}

// Up to `count` samples spread evenly over the trajectory (distance
// searches over many road marks need not visit every 100 Hz sample).
std::vector<int> SpreadSamples(int size, int count) {
  std::vector<int> indices;
  const int step = std::max(1, size / std::max(1, count));
  for (int i = 0; i < size; i += step) indices.push_back(i);
  if (indices.back() != size - 1) indices.push_back(size - 1);
  return indices;
}

// ------------------------------------------------------------ heading

// Yaw of the body's forward axis in the ENU frame (counter-clockwise from
// east), radians.
double ForwardYaw(const Eigen::Matrix3d& R_enu_body) {
  const Eigen::Vector3d forward = R_enu_body.col(0);
  return std::atan2(forward.y(), forward.x());
}

struct HeadingDisagreement {
  int chords = 0;
  double median_as_degrees_rad = 0.0;  // the file's angles read as degrees
  double median_as_radians_rad = 0.0;  // the same numbers read as radians
  int first_line = 0;
  int last_line = 0;
};

// Direction of travel against the heading over chords of the positions.
HeadingDisagreement MeasureHeadingDisagreement(
    const Trajectory& trajectory, const LocalFrame& frame,
    const PlausibilityOptions& options) {
  HeadingDisagreement result;
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  const int n = trajectory.size();
  std::vector<double> as_degrees, as_radians;
  double next_time = samples.front().time;
  for (int i = 0, j = 0; i < n; ++i) {
    if (samples[i].time < next_time) continue;
    j = std::max(j, i + 1);
    while (j < n && samples[j].time < samples[i].time + options.heading_chord_s)
      ++j;
    if (j >= n) break;
    const double dt = samples[j].time - samples[i].time;
    next_time = samples[i].time + 0.5 * options.heading_chord_s;
    if (dt > 2.0 * options.heading_chord_s) continue;  // across a gap
    const Eigen::Vector3d chord =
        trajectory.poses()[j].p_enu - trajectory.poses()[i].p_enu;
    if (chord.head<2>().norm() < options.min_speed_mps * dt) continue;
    const double course = std::atan2(chord.y(), chord.x());
    Pose mid;
    trajectory.InterpolatePose(0.5 * (samples[i].time + samples[j].time), &mid);
    as_degrees.push_back(std::abs(
        WrapPi(course - ForwardYaw(mid.q_enu_body.toRotationMatrix()))));
    // The numbers of the file taken as radians: the attitude was divided by
    // 180 / pi when read.
    const TrajectorySample& s = samples[(i + j) / 2];
    const Attitude radians{RadToDeg(s.attitude.roll),
                           RadToDeg(s.attitude.pitch),
                           RadToDeg(s.attitude.heading)};
    as_radians.push_back(std::abs(WrapPi(
        course - ForwardYaw(frame.RotationEnuFromBody(s.position, radians)))));
    if (result.first_line == 0) result.first_line = samples[i].line;
    result.last_line = samples[j].line;
  }
  result.chords = static_cast<int>(as_degrees.size());
  result.median_as_degrees_rad = Median(as_degrees);
  result.median_as_radians_rad = Median(as_radians);
  return result;
}

// Whether the trajectory's latitude and longitude look swapped, judged by
// its heading: swapping them mirrors the direction of travel (east and
// north exchanged), so only one reading follows the heading. nullopt when
// both or neither do (a heading near 45 degrees, a vehicle standing still):
// a swap that brings two files together could then be in either.
std::optional<bool> TrajectoryLooksSwapped(const Trajectory& trajectory,
                                           const PlausibilityOptions& options) {
  const double limit_rad = DegToRad(options.max_heading_disagreement_deg);
  auto follows_heading =
      [&](const std::vector<TrajectorySample>& samples) -> std::optional<bool> {
    const LocalFrame frame(samples.front().position);
    const HeadingDisagreement d =
        MeasureHeadingDisagreement(Trajectory(samples, frame), frame, options);
    if (d.chords < options.min_heading_chords) return std::nullopt;
    return d.median_as_degrees_rad <= limit_rad;
  };
  std::vector<TrajectorySample> swapped = trajectory.samples();
  for (TrajectorySample& sample : swapped) {
    const std::optional<Geodetic> position = Swapped(sample.position);
    if (!position.has_value()) return std::nullopt;
    sample.position = *position;
  }
  const std::optional<bool> as_is = follows_heading(trajectory.samples());
  const std::optional<bool> other = follows_heading(swapped);
  if (!as_is.has_value() || !other.has_value() || *as_is == *other) {
    return std::nullopt;
  }
  return *other;
}

void CheckHeading(const PlausibilityInput& input,
                  const PlausibilityOptions& options) {
  const HeadingDisagreement d =
      MeasureHeadingDisagreement(*input.trajectory, *input.frame, options);
  const std::string& file = input.trajectory_file;
  if (d.chords < options.min_heading_chords) {
    // A vehicle standing still has no direction of travel: nothing to say.
    VLOG(1) << file << ": " << d.chords
            << " moving stretches: heading not checked against the direction "
               "of travel";
    return;
  }
  const double limit_rad = DegToRad(options.max_heading_disagreement_deg);
  if (d.median_as_degrees_rad <= limit_rad) return;
  const std::string where =
      " (median over " + std::to_string(d.chords) + " stretches of " +
      FormatDouble(options.heading_chord_s) + " s, lines " +
      std::to_string(d.first_line) + "-" + std::to_string(d.last_line) + ")";
  if (d.median_as_radians_rad <= limit_rad) {
    throw InputError(
        file, 0,
        "columns 'roll', 'pitch', 'heading' look like radians, not degrees: "
        "read as degrees, the heading differs from the direction of travel "
        "by " +
            FormatFixed(RadToDeg(d.median_as_degrees_rad), 1) +
            " deg, read as radians by " +
            FormatFixed(RadToDeg(d.median_as_radians_rad), 1) + " deg" + where);
  }
  throw InputError(
      file, 0,
      "column 'heading' differs from the direction of travel by " +
          FormatFixed(RadToDeg(d.median_as_degrees_rad), 1) + " deg" + where +
          ", more than max_heading_disagreement_deg = " +
          FormatDouble(options.max_heading_disagreement_deg) +
          ": the heading must be degrees clockwise from true north of the "
          "body's x axis, which points forward");
}

// ------------------------------------------------------------ origin

void CheckOriginDistance(const PlausibilityInput& input,
                         const PlausibilityOptions& options) {
  if (!input.origin.has_value()) return;  // the first sample: distance 0
  const Geodetic& origin = *input.origin;
  const std::vector<TrajectorySample>& samples = input.trajectory->samples();
  double nearest = std::numeric_limits<double>::infinity();
  int nearest_index = 0;
  for (int i : SpreadSamples(static_cast<int>(samples.size()), 2000)) {
    const double d = GeodesicDistance(origin, samples[i].position);
    if (d < nearest) {
      nearest = d;
      nearest_index = i;
    }
  }
  if (nearest <= options.max_origin_distance_m) return;
  const TrajectorySample& sample = samples[nearest_index];
  const std::string where =
      "'origin' " + LatLon(origin) + " is " + Distance(nearest) +
      " from the nearest sample of " + input.trajectory_file + " (line " +
      std::to_string(sample.line) + ", " + LatLon(sample.position) + ")";
  // Swapping either side brings them together or neither does.
  const std::optional<Geodetic> swapped_sample = Swapped(sample.position);
  if (!swapped_sample.has_value() || GeodesicDistance(origin, *swapped_sample) >
                                         options.max_origin_distance_m) {
    throw InputError(input.manifest_file, input.origin_line,
                     where + ", more than max_origin_distance_m = " +
                         Distance(options.max_origin_distance_m) +
                         ": the origin must be near the survey");
  }
  const std::optional<bool> trajectory_swapped =
      TrajectoryLooksSwapped(*input.trajectory, options);
  if (trajectory_swapped.value_or(false)) {
    throw InputError(
        input.trajectory_file, sample.line,
        "latitude and longitude look swapped: (lat, lon) " +
            LatLon(sample.position) + " is " + Distance(nearest) + " from " +
            input.manifest_file + "'s origin " + LatLon(origin) +
            ", swapped back " +
            Distance(GeodesicDistance(origin, *swapped_sample)) +
            ", and its direction of travel then follows its heading (the "
            "columns are lat, then lon, in degrees)");
  }
  throw InputError(input.manifest_file, input.origin_line,
                   where + (trajectory_swapped.has_value()
                                ? ": 'origin' looks like [lon, lat, h]; it is "
                                  "[lat, lon, h]"
                                : ": latitude and longitude look swapped, in "
                                  "'origin' ([lat, lon, h]) or in " +
                                      input.trajectory_file));
}

// ------------------------------------------------------------ database

// Every vertex of the database: band corners and line points.
std::vector<Geodetic> RoadmarkPositions(const RoadmarkDatabase& database) {
  std::vector<Geodetic> positions;
  for (const RoadmarkBand& band : database.bands) {
    positions.insert(positions.end(), band.corners.begin(), band.corners.end());
  }
  for (const RoadmarkLine& line : database.lines) {
    positions.insert(positions.end(), line.points.begin(), line.points.end());
  }
  return positions;
}

// Nearest distance (m) between a mark and the trajectory (its samples
// spread every few metres), in the ENU frame: a straight line through the
// Earth beyond a few km, which only says "far" there. `nearest_mark` and
// `nearest_sample` receive the pair.
double NearestMarkDistance(const Trajectory& trajectory,
                           const std::vector<Eigen::Vector3d>& marks_enu,
                           int* nearest_mark, int* nearest_sample) {
  double nearest = std::numeric_limits<double>::infinity();
  const std::vector<int> samples = SpreadSamples(trajectory.size(), 300);
  for (size_t m = 0; m < marks_enu.size(); ++m) {
    for (int i : samples) {
      const double d = (marks_enu[m] - trajectory.poses()[i].p_enu).norm();
      if (d < nearest) {
        nearest = d;
        *nearest_mark = static_cast<int>(m);
        *nearest_sample = i;
      }
    }
  }
  return nearest;
}

// True when any mark lies within `radius` of a trajectory sample. A grid of
// cells of side `radius` over the samples keeps this linear in the marks.
bool AnyMarkNear(const Trajectory& trajectory,
                 const std::vector<Eigen::Vector3d>& marks_enu, double radius) {
  auto cell_of = [radius](const Eigen::Vector3d& p) {
    return std::make_pair(static_cast<long long>(std::floor(p.x() / radius)),
                          static_cast<long long>(std::floor(p.y() / radius)));
  };
  std::map<std::pair<long long, long long>, std::vector<int>> cells;
  for (int i : SpreadSamples(trajectory.size(), 20000)) {
    cells[cell_of(trajectory.poses()[i].p_enu)].push_back(i);
  }
  for (const Eigen::Vector3d& mark : marks_enu) {
    const auto [cx, cy] = cell_of(mark);
    for (long long dx = -1; dx <= 1; ++dx) {
      for (long long dy = -1; dy <= 1; ++dy) {
        const auto cell = cells.find({cx + dx, cy + dy});
        if (cell == cells.end()) continue;
        for (int i : cell->second) {
          if ((mark - trajectory.poses()[i].p_enu).norm() <= radius) {
            return true;
          }
        }
      }
    }
  }
  return false;
}

void CheckDatabaseDistance(const PlausibilityInput& input,
                           const PlausibilityOptions& options) {
  if (input.roadmarks == nullptr) return;
  const std::vector<Geodetic> marks = RoadmarkPositions(*input.roadmarks);
  if (marks.empty()) return;  // an empty database is warned about later
  std::vector<Eigen::Vector3d> marks_enu;
  marks_enu.reserve(marks.size());
  for (const Geodetic& mark : marks) {
    marks_enu.push_back(input.frame->EnuFromGeodetic(mark));
  }
  const Trajectory& trajectory = *input.trajectory;
  if (AnyMarkNear(trajectory, marks_enu, options.max_database_distance_m)) {
    return;
  }
  int mark = 0, sample = 0;
  NearestMarkDistance(trajectory, marks_enu, &mark, &sample);
  const TrajectorySample& nearest_sample = trajectory.samples()[sample];
  const double distance =
      GeodesicDistance(marks[mark], nearest_sample.position);
  std::string hint = ": a database of another place?";
  // The same pair, one side swapped back (a rough test that only tells
  // which way to look); which side, the trajectory's heading tells.
  const std::optional<Geodetic> sample_swapped =
      Swapped(nearest_sample.position);
  const double hint_radius =
      options.max_database_distance_m +
      GeodesicDistance(trajectory.samples().front().position,
                       trajectory.samples().back().position);
  if (sample_swapped.has_value() &&
      GeodesicDistance(marks[mark], *sample_swapped) <= hint_radius) {
    const std::optional<bool> trajectory_swapped =
        TrajectoryLooksSwapped(trajectory, options);
    if (trajectory_swapped.value_or(false)) {
      hint = ": latitude and longitude of " + input.trajectory_file +
             " look swapped (swapped back, its line " +
             std::to_string(nearest_sample.line) + " is " +
             Distance(GeodesicDistance(marks[mark], *sample_swapped)) +
             " from the database, and its direction of travel follows its "
             "heading)";
    } else if (trajectory_swapped.has_value()) {
      hint =
          ": its coordinates look like [lat, lon]; GeoJSON (RFC 7946) "
          "writes [lon, lat, h]";
    } else {
      hint =
          ": latitude and longitude look swapped, in the database (GeoJSON "
          "writes [lon, lat, h]) or in " +
          input.trajectory_file;
    }
  }
  throw InputError(input.roadmarks_file, 0,
                   "the nearest of its " + std::to_string(marks.size()) +
                       " road-mark vertices " + LatLon(marks[mark]) + " is " +
                       Distance(distance) + " from the trajectory (" +
                       input.trajectory_file + " line " +
                       std::to_string(nearest_sample.line) + ", " +
                       LatLon(nearest_sample.position) +
                       "), more than max_database_distance_m = " +
                       Distance(options.max_database_distance_m) +
                       "; nothing in it can control the trajectory" + hint);
}

// ------------------------------------------------------------ rate, gaps

void CheckRate(const PlausibilityInput& input,
               const PlausibilityOptions& options,
               std::vector<std::string>* warnings) {
  const double interval =
      MedianSampleInterval(SampleTimes(input.trajectory->samples()));
  // 5% slack: time stamps rounded to the millisecond.
  if (!(interval > 1.05 / options.min_rate_hz)) return;
  warnings->push_back(
      input.trajectory_file + ": " + FormatFixed(1.0 / interval, 1) +
      " Hz (median sample interval " + Interval(interval) +
      " s) is below the " + FormatDouble(options.min_rate_hz) +
      " Hz the survey format asks for: poses are interpolated over " +
      Interval(interval) +
      " s, and turns and the body's motion between samples are lost");
}

std::string GapText(const TrajectoryGap& gap,
                    const std::vector<TrajectorySample>& samples) {
  return FormatFixed(gap.duration(), 2) +
         " s with no sample (t = " + FormatDouble(gap.start_time) +
         " on line " + std::to_string(samples[gap.before].line) + " to " +
         FormatDouble(gap.end_time) + " on line " +
         std::to_string(samples[gap.before + 1].line) + ")";
}

void CheckGaps(const PlausibilityInput& input,
               const PlausibilityOptions& options,
               std::vector<std::string>* warnings) {
  const Trajectory& trajectory = *input.trajectory;
  const std::vector<TrajectorySample>& samples = trajectory.samples();
  const std::vector<TrajectoryGap> gaps =
      FindTrajectoryGaps(SampleTimes(samples), options.gaps);
  if (gaps.empty()) return;
  const double interval = MedianSampleInterval(SampleTimes(samples));
  std::ostringstream text;
  text << input.trajectory_file << ": " << gaps.size() << " gap"
       << (gaps.size() > 1 ? "s" : "")
       << " in the GNSS/INS solution (median sample interval "
       << Interval(interval) << " s): ";
  for (int g = 0; g < std::min<int>(gaps.size(), kMaxListedGaps); ++g) {
    text << (g > 0 ? "; " : "") << GapText(gaps[g], samples);
  }
  if (static_cast<int>(gaps.size()) > kMaxListedGaps) {
    text << "; and " << gaps.size() - kMaxListedGaps << " more";
  }
  text << ". Poses inside a gap are interpolated across it";
  warnings->push_back(text.str());

  // Exposures in gaps: the first image of each exposure names its line.
  const ExposureTable& table = *input.exposures;
  std::map<int64_t, int> line_of_exposure;
  for (const ExposureImage& image : table.images) {
    line_of_exposure.emplace(image.exposure_id, image.line);
  }
  int in_long_gaps = 0, in_short_gaps = 0;
  int first_long_line = 0;
  std::string first_long, first_short;
  for (const Exposure& exposure : table.exposures) {
    const int segment = trajectory.FindSegment(exposure.time);
    if (segment < 0) continue;  // outside the span: refused by LoadSurvey
    const auto gap = std::find_if(
        gaps.begin(), gaps.end(),
        [segment](const TrajectoryGap& g) { return g.before == segment; });
    if (gap == gaps.end() || exposure.time <= gap->start_time ||
        exposure.time >= gap->end_time) {
      continue;
    }
    const int line = line_of_exposure[exposure.exposure_id];
    const std::string what =
        "exposure " + std::to_string(exposure.exposure_id) +
        " at t = " + FormatDouble(exposure.time) + " falls in a gap of " +
        input.trajectory_file + ": " + GapText(*gap, samples);
    if (gap->duration() > options.max_exposure_gap_s) {
      if (in_long_gaps++ == 0) {
        first_long = what;
        first_long_line = line;
      }
    } else if (in_short_gaps++ == 0) {
      first_short =
          input.exposures_file + ":" + std::to_string(line) + ": " + what;
    }
  }
  if (in_long_gaps > 0) {
    throw InputError(input.exposures_file, first_long_line,
                     first_long +
                         "; its pose would be interpolated across the gap (" +
                         std::to_string(in_long_gaps) + " exposure" +
                         (in_long_gaps > 1 ? "s are" : " is") +
                         " in gaps longer than max_exposure_gap_s = " +
                         FormatDouble(options.max_exposure_gap_s) + " s)");
  }
  if (in_short_gaps > 0) {
    warnings->push_back(first_short + " (" + std::to_string(in_short_gaps) +
                        " exposure" + (in_short_gaps > 1 ? "s" : "") +
                        " in gaps up to max_exposure_gap_s = " +
                        FormatDouble(options.max_exposure_gap_s) +
                        " s): interpolated across the gap");
  }
}

}  // namespace

std::string PlausibilityOptions::Check() const {
  OptionCheck check;
  OPTION_NESTED(check, gaps);
  OPTION_GT(check, max_exposure_gap_s, 0.0);
  OPTION_GT(check, min_rate_hz, 0.0);
  OPTION_GT(check, heading_chord_s, 0.0);
  OPTION_GT(check, max_heading_disagreement_deg, 0.0);
  OPTION_GT(check, max_origin_distance_m, 0.0);
  OPTION_GT(check, max_database_distance_m, 0.0);
  OPTION_GE(check, min_speed_mps, 0.0);
  OPTION_GE(check, min_heading_chords, 1);
  OPTION_NESTED(check, database_height);
  return check.problem();
}

std::vector<std::string> CheckPlausibility(const PlausibilityInput& input,
                                           const PlausibilityOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("PlausibilityOptions: " + problem);
  }
  if (input.trajectory == nullptr || input.exposures == nullptr ||
      input.frame == nullptr) {
    throw std::invalid_argument(
        "CheckPlausibility: trajectory, exposures and frame are required");
  }
  std::vector<std::string> warnings;
  // Where the survey is comes first: with the trajectory in the wrong
  // place, every later figure is meaningless.
  CheckOriginDistance(input, options);
  CheckDatabaseDistance(input, options);
  if (input.roadmarks != nullptr) {
    const std::string height = DatabaseHeightProblem(
        *input.trajectory, input.trajectory_file, *input.roadmarks,
        *input.frame, options.database_height);
    if (!height.empty()) throw InputError(input.roadmarks_file, 0, height);
  }
  CheckHeading(input, options);
  CheckGaps(input, options, &warnings);
  CheckRate(input, options, &warnings);
  return warnings;
}

}  // namespace zebrageo
