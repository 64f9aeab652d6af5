#include "registration/edge_registration.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace zebrageo {
namespace {

// A crossing lies this close (horizontally, centre to a reconstructed band
// vertex) to bands the zebra front-end reconstructed: it was seen whole.
constexpr double kSeenWholeRadiusM = 8.0;
// The gate across an edge once zebra crossings corrected the trajectory:
// max(kMinEdgeGateM, kEdgeGateSigmas x its posterior sd), at most
// CrossingEdgeMatchOptions::gate_m.
constexpr double kMinEdgeGateM = 0.3;
constexpr double kEdgeGateSigmas = 4.0;

// The database crossings of `edges` near bands the zebra front-end
// reconstructed (put in ENU with the corrected trajectory).
std::set<std::string> CrossingsSeenWhole(
    const LineRegistrationInput& input,
    const std::unordered_map<int64_t, double>& exposure_time,
    const std::vector<DatabaseCrossingEdge>& edges) {
  std::set<std::string> seen;
  for (const VertexMatch& m : *input.matches) seen.insert(m.crossing_id);
  std::map<std::string, Eigen::Vector2d> centre;
  std::map<std::string, int> count;
  for (const DatabaseCrossingEdge& e : edges) {
    for (const Eigen::Vector3d& p : e.points) {
      auto [it, inserted] = centre.emplace(e.crossing_id, p.head<2>());
      if (!inserted) it->second += p.head<2>();
      ++count[e.crossing_id];
    }
  }
  for (auto& [id, c] : centre) c /= count[id];
  for (const ReconstructedVertex& v : *input.vertices) {
    const auto t = exposure_time.find(v.exposure_id);
    Pose pose;
    if (t == exposure_time.end() ||
        !CorrectedPoseAt(input.trajectory, t->second, &pose)) {
      continue;
    }
    const Eigen::Vector2d p = (pose.T_enu_body() * v.p_body).head<2>();
    for (const auto& [id, c] : centre) {
      if ((p - c).norm() <= kSeenWholeRadiusM) seen.insert(id);
    }
  }
  return seen;
}

}  // namespace

int AddCrossingEdgeControl(
    const std::vector<ReconstructedLinePoint>& points,
    const std::unordered_map<int64_t, double>& exposure_time,
    const LineRegistrationInput& input,
    const CrossingEdgeMatchOptions& match_options,
    std::vector<LineControlPoint>* control, std::vector<LineMatch>* rows) {
  if (points.empty()) return 0;
  const std::vector<DatabaseCrossingEdge> database =
      DatabaseCrossingEdges(*input.roadmarks, *input.frame);
  if (database.empty()) return 0;
  // Each reconstructed edge's points (file order is point order), in ENU.
  std::map<int64_t, std::vector<int>> of_line;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    of_line[points[i].line_id].push_back(i);
  }
  std::vector<std::vector<int>> edge_points;
  std::vector<std::vector<Eigen::Vector3d>> edges_enu;
  std::vector<Pose> pose_of;
  std::vector<double> time_of;
  for (auto& [id, indices] : of_line) {
    std::sort(indices.begin(), indices.end(), [&points](int a, int b) {
      return points[a].point < points[b].point;
    });
    const auto t = exposure_time.find(points[indices.front()].exposure_id);
    Pose pose;
    if (t == exposure_time.end() ||
        !CorrectedPoseAt(input.trajectory, t->second, &pose)) {
      continue;
    }
    std::vector<Eigen::Vector3d> enu;
    for (int i : indices) enu.push_back(pose.T_enu_body() * points[i].p_body);
    edge_points.push_back(indices);
    edges_enu.push_back(std::move(enu));
    pose_of.push_back(pose);
    time_of.push_back(t->second);
  }
  std::vector<CrossingEdgeMatch> matches;
  // With zebra control the gate follows the corrected trajectory's sd.
  for (size_t e = 0; e < edges_enu.size(); ++e) {
    CrossingEdgeMatchOptions o = match_options;
    if (input.trajectory.corrected) {
      o.gate_m = std::min(
          o.gate_m, std::max(kMinEdgeGateM,
                             kEdgeGateSigmas *
                                 PosteriorSdAt(input.trajectory, time_of[e])));
    }
    for (CrossingEdgeMatch m :
         MatchCrossingEdges({edges_enu[e]}, database, o)) {
      m.edge = static_cast<int>(e);
      matches.push_back(m);
    }
  }
  const std::set<std::string> seen =
      CrossingsSeenWhole(input, exposure_time, database);
  const size_t first = control->size();
  std::vector<CrossingEdgeMatch> kept;
  std::map<int, int> points_on;  // database edge: control points
  for (const CrossingEdgeMatch& m : matches) {
    if (seen.count(database[m.db_edge].crossing_id)) continue;
    kept.push_back(m);
    points_on[m.db_edge] += static_cast<int>(edge_points[m.edge].size());
  }
  for (const CrossingEdgeMatch& m : kept) {
    const DatabaseCrossingEdge& db = database[m.db_edge];
    const Eigen::Vector3d normal(db.Normal().x(), db.Normal().y(), 0.0);
    const Eigen::Vector3d direction(db.direction.x(), db.direction.y(), 0.0);
    // The database's error is the crossing's, shared by every point on
    // the edge: counted once over them.
    const double db_sigma = std::max(db.sigma_xy_m, input.min_database_sigma_m);
    const double shared_variance = points_on[m.db_edge] * db_sigma * db_sigma;
    const Eigen::Matrix3d R = pose_of[m.edge].q_enu_body.toRotationMatrix();
    for (size_t k = 0; k < edge_points[m.edge].size(); ++k) {
      const ReconstructedLinePoint& p = points[edge_points[m.edge][k]];
      LineControlPoint c;
      c.time = time_of[m.edge];
      c.p_body = p.p_body;
      c.db_point_enu =
          Eigen::Vector3d(db.point.x(), db.point.y(), edges_enu[m.edge][k].z());
      c.across_enu = normal;
      c.along_enu = direction;
      c.along_track = true;
      const double variance =
          normal.dot(R * p.covariance_body * R.transpose() * normal) +
          shared_variance;
      c.sqrt_information.setZero();
      c.sqrt_information(0, 0) = 1.0 / std::sqrt(variance);
      control->push_back(c);
      LineMatch row;
      row.exposure_id = p.exposure_id;
      row.line_id = p.line_id;
      row.point = p.point;
      row.type = p.type;
      row.db_line = db.id;
      row.across_enu = db.Normal();
      row.distance_m = (edges_enu[m.edge][k] - c.db_point_enu).dot(normal);
      row.constrains_across = false;
      row.along = true;
      rows->push_back(row);
    }
  }
  LOG(INFO) << "crossing edges: " << kept.size() << " of " << edges_enu.size()
            << " reconstructed edges matched to a database crossing's edge ("
            << matches.size() - kept.size()
            << " left out: the crossing's bands were seen whole)";
  return static_cast<int>(control->size() - first);
}

}  // namespace zebrageo
