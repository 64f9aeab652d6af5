#include "survey/results_match.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>
#include <utility>

#include "survey/atomic_file.h"
#include "survey/math_util.h"
#include "survey/output_crs.h"

namespace zebrageo {
namespace {

using nlohmann::json;

// Rounded for a person; positions keep full precision.
double Round(double value, double unit) {
  return std::round(value / unit) * unit;
}

json Position(const LocalFrame& frame, const Eigen::Vector3d& p_enu) {
  const Geodetic g = frame.GeodeticFromEnu(p_enu);
  return json::array({g.lon_deg, g.lat_deg, Round(g.h_m, 1e-4)});
}

json FeatureOf(json geometry, json properties) {
  return json{{"type", "Feature"},
              {"geometry", std::move(geometry)},
              {"properties", std::move(properties)}};
}

}  // namespace

const char* FaultKindName(FaultKind kind) {
  switch (kind) {
    case FaultKind::kCrossingMissingFromDatabase:
      return "crossing_missing_from_database";
    case FaultKind::kCrossingGoneFromStreet:
      return "crossing_gone_from_street";
    case FaultKind::kBandMissingFromStreet:
      return "band_missing_from_street";
    case FaultKind::kBandMissingFromDatabase:
      return "band_missing_from_database";
    case FaultKind::kCrossingShifted:
      return "crossing_shifted";
  }
  return "unknown";
}

std::string MatchSummary::BriefReport() const {
  std::ostringstream out;
  if (!IsUsable()) return "match: not run: " + message;
  out << "match: " << observations << " observations: " << matched
      << " matched (" << resolved_by_neighbours << " by continuity), "
      << refused << " refused (" << ambiguous << " ambiguous, " << inconsistent
      << " inconsistent), " << no_candidate << " without candidate; "
      << vertex_matches << " vertex matches on " << crossings_matched
      << " crossings; " << faults << " database faults; " << std::fixed
      << std::setprecision(2) << seconds << " s";
  return out.str();
}

void WriteMatchEvidence(const MatchResult& result,
                        const nlohmann::json& options,
                        const std::vector<std::string>& warnings,
                        const LocalFrame& frame, const std::string& path) {
  const MatchSummary& s = result.summary;
  json root;
  root["summary"] = {{"observations", s.observations},
                     {"matched", s.matched},
                     {"refused", s.refused},
                     {"no_candidate", s.no_candidate},
                     {"ambiguous", s.ambiguous},
                     {"inconsistent", s.inconsistent},
                     {"resolved_by_neighbours", s.resolved_by_neighbours},
                     {"vertex_matches", s.vertex_matches},
                     {"crossings_matched", s.crossings_matched},
                     {"faults", s.faults},
                     {"seconds", Round(s.seconds, 1e-3)},
                     {"report", s.BriefReport()}};
  root["warnings"] = warnings;
  root["options"] = options;
  json observations = json::array();
  for (const ObservationEvidence& e : result.evidence) {
    json o = {{"exposure_id", e.exposure_id},
              {"group_id", e.group_id},
              {"time", e.time_s},
              {"decision", DecisionName(e.decision)},
              {"crossing_id",
               e.crossing_id.empty() ? json(nullptr) : json(e.crossing_id)},
              {"reason", e.reason},
              {"bands", e.bands},
              {"usable_bands", e.usable_bands},
              {"candidate_db_bands", e.candidate_db_bands},
              {"hypotheses", e.hypotheses},
              {"hits", e.hits},
              {"missing", e.missing},
              {"contradictions", e.contradictions},
              {"unexplained", e.unexplained},
              {"own_score", Round(e.own_score, 1e-3)},
              {"aggregated_score", Round(e.aggregated_score, 1e-3)},
              {"resolved_by_neighbours", e.resolved_by_neighbours}};
    if (e.has_runner_up) {
      o["runner_up"] = {{"what", e.runner_up},
                        {"score", Round(e.runner_up_score, 1e-3)},
                        {"margin", Round(e.robust_margin, 1e-3)},
                        {"both_ends_margin", Round(e.both_ends_margin, 1e-3)}};
    }
    if (e.hypotheses > 0) {
      o["correction"] = {
          {"de_m", Round(e.correction.shift_enu_m.x(), 1e-4)},
          {"dn_m", Round(e.correction.shift_enu_m.y(), 1e-4)},
          {"dheading_deg", Round(RadToDeg(e.correction.heading_rad), 1e-4)}};
    }
    if (e.decision == Decision::kMatched) {
      o["matched_bands"] = e.matched_bands;
      o["vertex_matches"] = e.vertex_matches;
      o["vertex_rms_m"] = Round(e.vertex_rms_m, 1e-4);
    }
    observations.push_back(std::move(o));
  }
  root["observations"] = std::move(observations);
  json faults = json::array();
  for (const DatabaseFault& f : result.faults) {
    const Geodetic g = frame.GeodeticFromEnu(
        Eigen::Vector3d(f.location_enu.x(), f.location_enu.y(), 0.0));
    json fault = {{"kind", FaultKindName(f.kind)},
                  {"crossing_id",
                   f.crossing_id.empty() ? json(nullptr) : json(f.crossing_id)},
                  {"views", f.views},
                  {"exposure_ids", f.exposure_ids},
                  {"east", Round(f.location_enu.x(), 1e-3)},
                  {"north", Round(f.location_enu.y(), 1e-3)},
                  {"lat", g.lat_deg},
                  {"lon", g.lon_deg},
                  {"description", f.description}};
    if (f.band != 0) fault["band"] = f.band;
    if (!f.evidence.empty()) fault["evidence"] = f.evidence;
    if (f.kind == FaultKind::kCrossingShifted) {
      fault["shift_m"] = Round(f.shift_m, 1e-3);
    }
    faults.push_back(std::move(fault));
  }
  root["faults"] = std::move(faults);
  json unrecognised = json::array();
  for (const UnrecognisedMark& m : result.unrecognised) {
    const Geodetic g = frame.GeodeticFromEnu(
        Eigen::Vector3d(m.location_enu.x(), m.location_enu.y(), 0.0));
    json mark = {{"crossing_id", m.crossing_id},
                 {"why", m.why},
                 {"views", m.views},
                 {"exposure_ids", m.exposure_ids},
                 {"east", Round(m.location_enu.x(), 1e-3)},
                 {"north", Round(m.location_enu.y(), 1e-3)},
                 {"lat", g.lat_deg},
                 {"lon", g.lon_deg},
                 {"description", m.description}};
    if (m.band != 0) mark["band"] = m.band;
    unrecognised.push_back(std::move(mark));
  }
  root["not_recognised"] = std::move(unrecognised);
  json in_view = json::array();
  for (const CrossingInView& c : result.crossings_in_view) {
    in_view.push_back({{"crossing_id", c.crossing_id},
                       {"status", c.status},
                       {"reason", c.reason},
                       {"views", c.views}});
  }
  root["crossings_in_view"] = std::move(in_view);
  WriteFileAtomically(path,
                      [&](std::ostream& out) { out << root.dump(1) << "\n"; });
}

void WriteMatchesGeoJson(const std::vector<MatchedVertexFeature>& vertices,
                         const std::vector<DatabaseFault>& faults,
                         const LocalFrame& frame, const std::string& folder,
                         const OutputCrs* crs) {
  const auto position = [&](const Eigen::Vector3d& p_enu) {
    if (crs == nullptr) return Position(frame, p_enu);
    const Eigen::Vector3d xyz = crs->FromWgs84(frame.GeodeticFromEnu(p_enu));
    return json::array({xyz.x(), xyz.y(), Round(xyz.z(), 1e-4)});
  };
  json lines = json::array(), bands = json::array(), points = json::array();
  for (const MatchedVertexFeature& f : vertices) {
    const VertexMatch& m = f.match;
    lines.push_back(FeatureOf(
        {{"type", "LineString"},
         {"coordinates",
          json::array({position(f.measured_enu), position(f.database_enu)})}},
        {{"kind", "vertex_match"},
         {"exposure_id", m.exposure_id},
         {"band_id", m.band_id},
         {"vertex", m.vertex},
         {"crossing_id", m.crossing_id},
         {"band", m.band},
         {"db_vertex", m.db_vertex},
         {"drift_m",
          Round((f.measured_enu - f.database_enu).head<2>().norm(), 1e-3)},
         {"residual_m",
          Round((f.corrected_enu - f.database_enu).head<2>().norm(), 1e-4)}}));
    if (f.corrected_band_enu) {
      json ring = json::array();
      for (int v = 0; v <= 4; ++v) {
        ring.push_back(position((*f.corrected_band_enu)[v % 4]));
      }
      bands.push_back(
          FeatureOf({{"type", "Polygon"}, {"coordinates", json::array({ring})}},
                    {{"kind", "matched_band_corrected"},
                     {"exposure_id", m.exposure_id},
                     {"band_id", m.band_id},
                     {"crossing_id", m.crossing_id},
                     {"band", m.band}}));
    }
  }
  for (const DatabaseFault& f : faults) {
    points.push_back(FeatureOf(
        {{"type", "Point"},
         {"coordinates", position(Eigen::Vector3d(f.location_enu.x(),
                                                  f.location_enu.y(), 0.0))}},
        {{"kind", "database_fault"},
         {"fault", FaultKindName(f.kind)},
         {"crossing_id",
          f.crossing_id.empty() ? json(nullptr) : json(f.crossing_id)},
         {"band", f.band == 0 ? json(nullptr) : json(f.band)},
         {"views", f.views},
         {"description", f.description}}));
  }
  const std::string crs_member =
      crs == nullptr ? "" : "\"crs\": " + crs->GeoJsonMember().dump() + ", ";
  const auto write = [&](const json& features, const char* name) {
    WriteFileAtomically((std::filesystem::path(folder) / name).string(),
                        [&](std::ostream& out) {
                          // One feature per line: diffable, and QGIS reads it
                          // as it is.
                          out << "{\"type\": \"FeatureCollection\", "
                              << crs_member << "\"features\": [\n";
                          for (size_t i = 0; i < features.size(); ++i) {
                            out << (i > 0 ? ",\n" : "") << features[i].dump();
                          }
                          out << "\n]}\n";
                        });
  };
  write(lines, kMatchesGeoJsonFile);
  write(bands, kMatchedBandsGeoJsonFile);
  write(points, kDatabaseFaultsGeoJsonFile);
}

}  // namespace zebrageo
