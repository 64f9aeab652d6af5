#include "registration/line_registration.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "registration/edge_registration.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// The database line's slope is fitted over +-10 m: the height of a control
// point follows it when the adjustment moves the point along the line.
constexpr double kGradeHalfWindowM = 10.0;

// Database lines whose matched points lie, by their median, further from
// where the zebra-corrected trajectory puts them than
// max(kMinLineGateM, kLineGateSigmas x the posterior sd there): rejected;
// the rest are kept in `kept`.
constexpr double kMinLineGateM = 0.2;
constexpr double kLineGateSigmas = 4.0;
std::vector<RejectedLine> RejectLinesAwayFromTrajectory(
    const std::vector<LinePointMatch>& matches,
    const std::vector<double>& sd_of_point, std::vector<LinePointMatch>* kept) {
  std::map<int, std::vector<double>> distance, gate;
  for (const LinePointMatch& m : matches) {
    distance[m.db_line].push_back(m.distance_m);
    gate[m.db_line].push_back(
        std::max(kMinLineGateM, kLineGateSigmas * sd_of_point[m.point]));
  }
  std::vector<RejectedLine> rejected;
  std::set<int> away;
  for (auto& [line, d] : distance) {
    const double median = Median(d);
    if (std::abs(median) > Median(gate[line])) {
      away.insert(line);
      rejected.push_back({line, static_cast<int>(d.size()), median});
    }
  }
  kept->clear();
  for (const LinePointMatch& m : matches) {
    if (!away.count(m.db_line)) kept->push_back(m);
  }
  return rejected;
}

// The reconstructed line points in ENU with the trajectory the zebra
// crossings corrected (those at an exposure it covers), with where each
// came from, the pose and its time.
struct LinePointsEnu {
  std::vector<LinePointEnu> enu;
  std::vector<int> source;  // index into the reconstructed points
  std::vector<Pose> pose_of;
  std::vector<double> time_of;
};
LinePointsEnu LinePointsInEnu(
    const std::vector<ReconstructedLinePoint>& points,
    const std::unordered_map<int64_t, double>& exposure_time,
    const CorrectedTrajectory& trajectory) {
  LinePointsEnu out;
  for (size_t i = 0; i < points.size(); ++i) {
    const auto t = exposure_time.find(points[i].exposure_id);
    Pose pose;
    if (t == exposure_time.end() ||
        !CorrectedPoseAt(trajectory, t->second, &pose)) {
      continue;
    }
    out.enu.push_back({points[i].line_id, RoadLineTypeName(points[i].type),
                       pose.T_enu_body() * points[i].p_body});
    out.source.push_back(static_cast<int>(i));
    out.pose_of.push_back(pose);
    out.time_of.push_back(t->second);
  }
  return out;
}

// Without a corrected trajectory: each window's points shifted across the
// track by the offset the lines agree on (line_offset.h); the points of
// windows without one removed.
void ShiftByLateralOffsets(const std::vector<DatabaseLineEnu>& database,
                           const LateralOffsetOptions& options,
                           LinePointsEnu* points) {
  std::vector<Eigen::Vector2d> left_of;
  for (const Pose& pose : points->pose_of) {
    // Body FRD: its y axis points right.
    const Eigen::Vector3d right = pose.q_enu_body * Eigen::Vector3d::UnitY();
    left_of.push_back(-right.head<2>().normalized());
  }
  const std::vector<LateralOffset> offsets = SearchLateralOffsets(
      points->enu, points->time_of, left_of, database, options);
  LinePointsEnu kept;
  int decided = 0;
  for (const LateralOffset& o : offsets) decided += o.decided;
  for (size_t i = 0; i < points->enu.size(); ++i) {
    const auto o = std::find_if(
        offsets.begin(), offsets.end(), [&](const LateralOffset& w) {
          return points->time_of[i] >= w.start_s &&
                 points->time_of[i] < w.start_s + options.window_s;
        });
    if (o == offsets.end() || !o->decided) continue;
    kept.enu.push_back(points->enu[i]);
    kept.enu.back().p_enu.head<2>() += o->offset_m * left_of[i];
    kept.source.push_back(points->source[i]);
    kept.pose_of.push_back(points->pose_of[i]);
    kept.time_of.push_back(points->time_of[i]);
  }
  LOG(INFO) << "road lines without zebra control: the cross-track offset "
               "decided in "
            << decided << " of " << offsets.size() << " windows of "
            << options.window_s << " s; " << kept.enu.size() << " of "
            << points->enu.size() << " line points kept";
  for (const LateralOffset& o : offsets) {
    VLOG(1) << "  window at " << o.start_s << " s: offset " << o.offset_m
            << " m, " << o.points << " points against " << o.runner_up_points
            << ", spread " << o.spread_m << " m"
            << (o.decided ? "" : " (undecided)")
            << (o.by_continuity > 0 ? " (by continuity)" : "");
  }
  *points = std::move(kept);
}

// Warns of each rejected database line (the report's wording, so the
// warning is listed once in report.json) and lists it in `summary`.
void WarnRejectedLines(const std::vector<RejectedLine>& rejected,
                       const std::vector<DatabaseLineEnu>& database,
                       bool log_warnings, LineControlRecord* summary,
                       std::vector<std::string>* warnings) {
  for (const RejectedLine& r : rejected) {
    const DatabaseLineEnu& line = database[r.db_line];
    std::ostringstream w;
    w << "database: road line " << line.id << " (" << line.type << ") lies "
      << std::fixed << std::setprecision(2) << std::abs(r.offset_m)
      << " m across from where the other lines put it: repainted or stale, "
         "not used as control";
    if (log_warnings) {
      LOG(WARNING) << w.str();
    } else {
      VLOG(1) << w.str();
    }
    warnings->push_back(w.str());
    summary->rejected_lines.push_back(
        {line.id, line.type, r.points, r.offset_m});
  }
}

// The control point of a line point matched to a database line; `shared`:
// how many points share its database segment's error, square-rooted.
// *cross_track: whether the line runs with the vehicle (then it controls
// the cross-track position, else the height only).
LineControlPoint ControlPointOf(const ReconstructedLinePoint& p, double time,
                                const Pose& pose, const LinePointMatch& m,
                                const DatabaseLineEnu& line, double shared,
                                double min_database_sigma_m,
                                bool* cross_track) {
  LineControlPoint c;
  c.time = time;
  c.p_body = p.p_body;
  c.db_point_enu = m.db_point_enu;
  c.across_enu = m.across_enu;
  c.along_enu = m.along_enu;
  c.grade =
      DatabaseLineGrade(line, m.db_segment, m.db_segment_t, kGradeHalfWindowM);
  c.sqrt_information = LineSqrtInformation(
      p.covariance_body, pose.q_enu_body.toRotationMatrix(), m.across_enu,
      shared * std::max(line.sigma_xy_m, min_database_sigma_m),
      shared * std::max(line.sigma_z_m, min_database_sigma_m));
  // Across the line is cross-track when the line runs with the vehicle.
  const Eigen::Vector3d forward = pose.q_enu_body * Eigen::Vector3d::UnitX();
  *cross_track = std::abs(m.along_enu.dot(forward)) > 0.7;
  if (!*cross_track) {
    // A line across the road (a stop line) would control the along-track
    // position, which the zebra crossings it lies beside already hold; a
    // database's stop lines are drawn loosely (an aerial image shows a
    // thick bar, a give-way line beside it), so it controls the height
    // only.
    c.sqrt_information.row(0).setZero();
  }
  return c;
}

// A dash's two ends each lie this far from where the database's ends would
// put them, beyond the reconstruction's covariance (the paint's blur and
// wear; dash_matcher.h): the centre's sd from the ends alone is this over
// sqrt(2). Measured on rendered surveys with the true trajectory: whole
// dashes' centres lie 2 cm (sd) from the database's.
constexpr double kDashEndSigmaM = 0.03;
// The along-track gate of a dash: max(this, kLineGateSigmas x the posterior
// sd of the zebra-corrected trajectory there).
constexpr double kMinDashGateM = 0.3;

// The whole dashes among the line points (a lane_dashed line whose kept
// point matches all lie on one database dash), matched to the database's
// dashes along the track (registration/dash_matcher.h): one along-track
// control point at each dash's centre, appended to `control` and `rows`;
// returns how many.
int AddDashControl(const std::vector<ReconstructedLinePoint>& points,
                   const LinePointsEnu& line_points,
                   const std::vector<LinePointMatch>& matches,
                   const std::vector<DatabaseLineEnu>& database,
                   const CorrectedTrajectory& trajectory,
                   double min_database_sigma_m,
                   const DashMatchOptions& dash_options,
                   std::vector<LineControlPoint>* control,
                   std::vector<LineMatch>* rows) {
  const std::vector<int> db_dashes = DatabaseDashes(database, dash_options);
  if (db_dashes.empty()) return 0;
  // The database line each reconstructed line's kept points agree on, or
  // -1 when they split.
  std::map<int64_t, int> db_line_of;
  for (const LinePointMatch& m : matches) {
    const int64_t id = line_points.enu[m.point].line_id;
    const auto [it, inserted] = db_line_of.emplace(id, m.db_line);
    if (!inserted && it->second != m.db_line) it->second = -1;
  }
  // First and last point (indices into line_points) of each dashed line.
  std::map<int64_t, std::pair<int, int>> ends;
  for (size_t i = 0; i < line_points.enu.size(); ++i) {
    const ReconstructedLinePoint& p = points[line_points.source[i]];
    if (p.type != RoadLineType::kLaneDashed) continue;
    const auto [it, inserted] = ends.emplace(
        p.line_id, std::make_pair(static_cast<int>(i), static_cast<int>(i)));
    if (inserted) continue;
    auto& [first, last] = it->second;
    if (p.point < points[line_points.source[first]].point) {
      first = static_cast<int>(i);
    }
    if (p.point > points[line_points.source[last]].point) {
      last = static_cast<int>(i);
    }
  }
  std::vector<ReconstructedDashEnu> dashes;
  std::vector<std::pair<int, int>> dash_ends;
  std::vector<int> dash_db_line;
  for (const auto& [id, e] : ends) {
    const auto db = db_line_of.find(id);
    if (db == db_line_of.end() || db->second < 0 || e.first == e.second) {
      continue;
    }
    const double sd = PosteriorSdAt(trajectory, line_points.time_of[e.first]);
    dashes.push_back({line_points.enu[e.first].p_enu,
                      line_points.enu[e.second].p_enu,
                      std::max(kMinDashGateM, kLineGateSigmas * sd)});
    dash_ends.push_back(e);
    dash_db_line.push_back(db->second);
  }
  std::vector<DashMatch> dash_matches;
  std::map<int, int> seen_of_db_dash;
  for (const DashMatch& m :
       MatchDashes(dashes, database, db_dashes, dash_options)) {
    // The nearest database dash must be the one the points lie on.
    if (m.db_line != dash_db_line[m.dash]) continue;
    dash_matches.push_back(m);
    ++seen_of_db_dash[m.db_line];
  }
  for (const DashMatch& m : dash_matches) {
    const auto [first, last] = dash_ends[m.dash];
    const ReconstructedLinePoint& a = points[line_points.source[first]];
    const ReconstructedLinePoint& b = points[line_points.source[last]];
    const Pose& pose = line_points.pose_of[first];
    const DatabaseLineEnu& line = database[m.db_line];
    LineControlPoint c;
    c.time = line_points.time_of[first];
    c.p_body = 0.5 * (a.p_body + b.p_body);
    c.db_point_enu = m.db_centre_enu;
    c.across_enu = m.along_enu;
    c.along_enu = Eigen::Vector3d(-m.along_enu.y(), m.along_enu.x(), 0.0);
    c.along_track = true;
    // The database dash's error is shared by every exposure that saw it.
    const double db_sigma =
        std::sqrt(static_cast<double>(seen_of_db_dash[m.db_line])) *
        std::max(line.sigma_xy_m, min_database_sigma_m);
    const Eigen::Matrix3d R = pose.q_enu_body.toRotationMatrix();
    const Eigen::Matrix3d covariance_enu =
        R * (0.25 * (a.covariance_body + b.covariance_body)) * R.transpose();
    const double variance = m.along_enu.dot(covariance_enu * m.along_enu) +
                            0.5 * kDashEndSigmaM * kDashEndSigmaM +
                            db_sigma * db_sigma;
    c.sqrt_information.setZero();
    c.sqrt_information(0, 0) = 1.0 / std::sqrt(variance);
    control->push_back(c);
    LineMatch row;
    row.exposure_id = a.exposure_id;
    row.line_id = a.line_id;
    row.point = -1;
    row.type = a.type;
    row.db_line = line.id;
    row.across_enu = m.along_enu.head<2>();
    row.distance_m = m.offset_m;
    row.constrains_across = false;
    row.along = true;
    rows->push_back(row);
  }
  LOG(INFO) << "road lines: " << dash_matches.size() << " of " << dashes.size()
            << " dashes on a database dash matched along the track ("
            << db_dashes.size() << " dashes in the database)";
  return static_cast<int>(dash_matches.size());
}

// Logs the line control per stretch of stretch_s seconds.
void LogLineControl(size_t used, size_t reconstructed, double stretch_s,
                    const std::map<int, std::array<int, 3>>& stretches) {
  std::ostringstream report;
  report << "road lines: " << used << " of " << reconstructed
         << " line points matched to database lines; per " << stretch_s
         << " s stretch (cross-track/height/along-track points):";
  for (const auto& [k, s] : stretches) {
    report << " [+" << k * stretch_s << " s: " << s[0] << "/" << s[1] << "/"
           << s[2] << "]";
  }
  LOG(INFO) << report.str();
  int along = 0;
  for (const auto& [k, s] : stretches) along += s[2];
  LOG(INFO) << "road lines control cross-track and height between crossings"
            << (along > 0 ? "; whole dashes the along-track position" : "");
}

// The reconstructed line points matched to database lines and kept: those
// of the lines that agree with each other and, with a corrected trajectory,
// with it (*rejected: the others); *all_matches: every point matched.
std::vector<LinePointMatch> AcceptedLineMatches(
    const LinePointsEnu& line_points,
    const std::vector<DatabaseLineEnu>& database,
    const CorrectedTrajectory& trajectory,
    const LineRegistrationOptions& options, std::vector<RejectedLine>* rejected,
    size_t* all_matches) {
  const std::vector<LinePointMatch> matched =
      MatchLinePoints(line_points.enu, database, options.lines);
  *all_matches = matched.size();
  std::vector<LinePointMatch> consistent;
  std::set<int> checked;
  *rejected = RejectInconsistentLines(
      matched, line_points.time_of, options.consistency, &consistent, &checked);
  // A database line must also agree with the trajectory the zebra crossings
  // corrected, to what that trajectory's posterior sd allows: a line the
  // zebras place decimetres away is stale or mismatched, and would pull
  // the trajectory off the crossings.
  std::vector<double> sd_of_point(line_points.enu.size(), 0.0);
  for (size_t i = 0; i < line_points.enu.size(); ++i) {
    sd_of_point[i] = PosteriorSdAt(trajectory, line_points.time_of[i]);
  }
  // Without a corrected trajectory (no zebra crossing was control) there is
  // nothing to check the lines against but each other (the input's stated
  // sd is no measure of its error), and a line matched alone may be its
  // neighbour, a lane away less the drift: only lines another painted line
  // vouched for are control.
  std::vector<LinePointMatch> matches;
  if (trajectory.corrected) {
    for (const RejectedLine& r :
         RejectLinesAwayFromTrajectory(consistent, sd_of_point, &matches)) {
      rejected->push_back(r);
    }
  } else {
    for (const LinePointMatch& m : consistent) {
      if (checked.count(m.db_line)) matches.push_back(m);
    }
  }
  return matches;
}

// Control points per stretch of line_control.json: cross-track, height,
// along-track, by stretch index.
using Stretches = std::map<int, std::array<int, 3>>;

// A control point per accepted line point, and its row of
// line_matches.csv; counts them in *stretches.
void AddLineControl(const std::vector<ReconstructedLinePoint>& points,
                    const LinePointsEnu& line_points,
                    const std::vector<LinePointMatch>& matches,
                    const std::vector<DatabaseLineEnu>& database,
                    const std::unordered_map<int64_t, double>& exposure_time,
                    const LineRegistrationInput& input, double start_time,
                    double stretch_s, Stretches* stretches,
                    LineRegistration* out) {
  // The database's error is one per segment, shared by every point matched
  // to it (from several exposures): counted once, or the adjustment would
  // fit the database's noise (the heading follows the digitised line's
  // wiggles between crossings).
  std::map<std::pair<int, int>, int> points_on_segment;
  for (const LinePointMatch& m : matches) {
    ++points_on_segment[{m.db_line, m.db_segment}];
  }
  for (const LinePointMatch& m : matches) {
    const ReconstructedLinePoint& p = points[line_points.source[m.point]];
    const double shared = std::sqrt(
        static_cast<double>(points_on_segment[{m.db_line, m.db_segment}]));
    const DatabaseLineEnu& line = database[m.db_line];
    bool cross_track = false;
    out->control.push_back(ControlPointOf(
        p, exposure_time.at(p.exposure_id), line_points.pose_of[m.point], m,
        line, shared, input.min_database_sigma_m, &cross_track));
    auto& s = (*stretches)[static_cast<int>(
        std::floor((out->control.back().time - start_time) / stretch_s))];
    if (cross_track) s[0] += 1;
    s[1] += 1;
    out->rows.push_back({p.exposure_id, p.line_id, p.point, p.type, line.id,
                         m.across_enu.head<2>(), m.distance_m, m.height_m,
                         cross_track});
  }
}

}  // namespace

std::string LineRegistrationOptions::Check() const {
  OptionCheck check;
  OPTION_NESTED(check, lines);
  OPTION_NESTED(check, consistency);
  OPTION_NESTED(check, lateral_offsets);
  OPTION_NESTED(check, dashes);
  OPTION_NESTED(check, crossing_edges);
  return check.problem();
}

LineRegistration RegisterRoadLines(
    const std::vector<ReconstructedLinePoint>& reconstructed,
    const LineRegistrationInput& input,
    const LineRegistrationOptions& options) {
  LineRegistration out;
  // Crossing edges are matched to the database's crossings, apart.
  std::vector<ReconstructedLinePoint> points, edge_points;
  for (const ReconstructedLinePoint& p : reconstructed) {
    (p.type == RoadLineType::kCrossingEdge ? edge_points : points).push_back(p);
  }
  if (input.roadmarks->lines.empty()) {
    out.warnings.push_back(
        "the road-mark database has no lines: road lines not used");
    if (edge_points.empty()) return out;
    points.clear();
  }
  std::unordered_map<int64_t, double> exposure_time;
  for (const Exposure& e : input.exposures->exposures) {
    exposure_time[e.exposure_id] = e.time;
  }
  const std::vector<DatabaseLineEnu> database =
      DatabaseLinesEnu(*input.roadmarks, *input.frame);
  LinePointsEnu line_points =
      LinePointsInEnu(points, exposure_time, input.trajectory);
  if (!input.trajectory.corrected) {
    ShiftByLateralOffsets(database, options.lateral_offsets, &line_points);
  }
  std::vector<RejectedLine> rejected;
  size_t all_matches = 0;
  const std::vector<LinePointMatch> matches =
      AcceptedLineMatches(line_points, database, input.trajectory, options,
                          &rejected, &all_matches);
  LineControlRecord record;
  WarnRejectedLines(rejected, database, input.log_warnings, &record,
                    &out.warnings);

  // Per 30 s stretch: matches, and the directions controlled.
  const double stretch_s = 30.0;
  const double start_time = input.exposures->exposures.empty()
                                ? 0.0
                                : input.exposures->exposures.front().time;
  Stretches stretches;
  AddLineControl(points, line_points, matches, database, exposure_time, input,
                 start_time, stretch_s, &stretches, &out);
  // Along the track: whole dashes, once the crossings corrected the
  // trajectory (without them its along-track error is unbounded, and a
  // dash period off would match the next dash).
  const size_t first_along = out.control.size();
  if (input.trajectory.corrected) {
    AddDashControl(points, line_points, matches, database, input.trajectory,
                   input.min_database_sigma_m, options.dashes, &out.control,
                   &out.rows);
  }
  // Along the track too: the edges of crossings never seen whole.
  AddCrossingEdgeControl(edge_points, exposure_time, input,
                         options.crossing_edges, &out.control, &out.rows);
  for (size_t i = first_along; i < out.control.size(); ++i) {
    stretches[static_cast<int>(
        std::floor((out.control[i].time - start_time) / stretch_s))][2] += 1;
  }
  LogLineControl(matches.size(), points.size(), stretch_s, stretches);
  record.stretch_s = stretch_s;
  record.reconstructed_points = static_cast<int64_t>(points.size());
  record.matched_points = static_cast<int64_t>(all_matches);
  record.used_points = static_cast<int64_t>(matches.size());
  for (const auto& [k, s] : stretches) {
    record.stretches.push_back({k * stretch_s, (k + 1) * stretch_s,
                                start_time + k * stretch_s, s[0], s[1], s[2]});
  }
  out.record = std::move(record);
  return out;
}

}  // namespace zebrageo
