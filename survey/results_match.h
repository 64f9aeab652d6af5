// What the match stage decides and writes beside matches.csv and
// crossing_decisions.csv (survey/results.h): the registration's result
// types (registration/band_matcher.h fills them) and their two files,
//   match_evidence.json  the evidence behind each decision, the database
//                        faults found, the options and the summary
//   matches.geojson      for QGIS: each matched vertex as a line from its
//                        measured placement to its database corner
//   matched_bands.geojson  the matched bands placed with the estimated
//                        correction, as polygons
//   database_faults.geojson  the database faults found, as points
// each written atomically. One geometry type per file (a GIS layer holds
// one: OGR's GeoJSON driver reads a mixed file as one "Unknown" layer that
// a shapefile or GeoPackage cannot take). With survey.yaml's output_crs,
// the three GeoJSON files are in that CRS with a top-level "crs" member,
// as bands.geojson (survey/output_crs.h): RFC 7946 allows WGS84 only, so
// they then leave the RFC for GeoJSON 2008, which GDAL and QGIS read.
#ifndef ZEBRAGEO_SURVEY_RESULTS_MATCH_H_
#define ZEBRAGEO_SURVEY_RESULTS_MATCH_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "survey/geodesy.h"
#include "survey/results.h"

namespace zebrageo {

inline constexpr char kMatchEvidenceFile[] = "match_evidence.json";
inline constexpr char kMatchesGeoJsonFile[] = "matches.geojson";
inline constexpr char kMatchedBandsGeoJsonFile[] = "matched_bands.geojson";
inline constexpr char kDatabaseFaultsGeoJsonFile[] = "database_faults.geojson";

class OutputCrs;

// A horizontal correction of the measured pose at one exposure
// (registration/band_matcher.h): p_true = Rz(heading_rad) (p - p_vehicle)
// + p_vehicle + shift_enu_m.
struct PoseCorrection {
  double heading_rad = 0.0;
  Eigen::Vector2d shift_enu_m = Eigen::Vector2d::Zero();
};

enum class FaultKind {
  kCrossingMissingFromDatabase,
  kCrossingGoneFromStreet,
  kBandMissingFromStreet,
  kBandMissingFromDatabase,
  kCrossingShifted,
};
const char* FaultKindName(FaultKind kind);  // e.g. "crossing_gone_from_street"

struct DatabaseFault {
  FaultKind kind = FaultKind::kCrossingGoneFromStreet;
  std::string crossing_id;  // empty for a crossing missing from the database
  int band = 0;             // band faults: the band (or the one beyond)
  Eigen::Vector2d location_enu = Eigen::Vector2d::Zero();
  double shift_m = 0.0;  // kCrossingShifted
  int views = 0;         // exposures behind the finding
  std::vector<int64_t> exposure_ids;
  std::string description;
  // What the finding rests on: for a crossing or band gone from the street,
  // the images' bare road where the paint should be (issue 52: never a
  // fault the images do not show).
  std::string evidence;
};

// A database crossing or band the images should have shown that was not
// recognised, without evidence that it is gone (paint seen at its place,
// or the images could not tell: occluded, shadowed, out of view, no
// images): not a database fault, listed apart.
struct UnrecognisedMark {
  std::string crossing_id;
  int band = 0;  // 0: the whole crossing
  Eigen::Vector2d location_enu = Eigen::Vector2d::Zero();
  // "paint seen" (painted, not reconstructed or not matched), "occluded"
  // (the stereo pair shows something standing above the road at its
  // place), "occluded or not told" (neither paint nor bare road in the
  // images), "no images".
  std::string why;
  int views = 0;
  std::vector<int64_t> exposure_ids;
  std::string description;
};

// Why one observation was decided as it was.
struct ObservationEvidence {
  int64_t exposure_id = 0;
  int64_t group_id = 0;
  double time_s = 0.0;
  Decision decision = Decision::kNoCandidate;
  std::string crossing_id;
  std::string reason;
  int bands = 0;         // observed bands
  int usable_bands = 0;  // with a zebra band's shape and 4 vertices
  int candidate_db_bands = 0;
  int hypotheses = 0;
  // Of the chosen (or best) hypothesis, in this observation alone:
  int hits = 0;
  int missing = 0;
  int contradictions = 0;
  int unexplained = 0;
  double own_score = 0.0;
  // Over the window:
  double aggregated_score = 0.0;
  bool has_runner_up = false;
  double runner_up_score = 0.0;
  double robust_margin = 0.0;     // the margin the decision used
  double both_ends_margin = 0.0;  // without the stronger end's evidence
  std::string runner_up;  // what the runner-up is ("band offset +1", ...)
  bool resolved_by_neighbours = false;
  PoseCorrection correction;
  double vertex_rms_m = 0.0;
  int vertex_matches = 0;
  std::vector<int> matched_bands;  // database band numbers
};

struct MatchSummary {
  int observations = 0;
  int matched = 0;
  int refused = 0;
  int no_candidate = 0;
  int ambiguous = 0;               // refused as ambiguous
  int inconsistent = 0;            // refused by the continuity check
  int resolved_by_neighbours = 0;  // matched thanks to continuity
  int vertex_matches = 0;
  int crossings_matched = 0;
  int faults = 0;
  double seconds = 0.0;
  // Empty when the matcher ran; otherwise why not (bad options, no index).
  std::string message;

  bool IsUsable() const { return message.empty(); }
  std::string BriefReport() const;
};

// What became of one database crossing in view (issue 51): "matched",
// "refused", "not matched", "gone from the street", "not recognised" or
// "not reconstructed", and why.
struct CrossingInView {
  std::string crossing_id;
  std::string status;
  std::string reason;
  int views = 0;  // exposures with at least one of its bands in full view
};

struct MatchResult {
  std::vector<VertexMatch> matches;
  std::vector<CrossingDecision> decisions;    // one per observation, in order
  std::vector<ObservationEvidence> evidence;  // one per observation, in order
  std::vector<DatabaseFault> faults;
  std::vector<UnrecognisedMark> unrecognised;
  std::vector<CrossingInView> crossings_in_view;
  MatchSummary summary;
};

// match_evidence.json. `options`: the match options it ran with (their
// JSON, survey/option_json.h); `frame`: the survey's ENU frame (the faults'
// latitude and longitude).
void WriteMatchEvidence(const MatchResult& result,
                        const nlohmann::json& options,
                        const std::vector<std::string>& warnings,
                        const LocalFrame& frame, const std::string& path);

// One feature of matches.geojson: a matched vertex from its measured
// placement to its database corner, followed, on the first vertex of its
// band, by the band placed with the estimated correction.
struct MatchedVertexFeature {
  VertexMatch match;
  Eigen::Vector3d measured_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d corrected_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d database_enu = Eigen::Vector3d::Zero();
  std::optional<std::array<Eigen::Vector3d, 4>> corrected_band_enu;
};
// matches.geojson (the vertices in order, as lines), matched_bands.geojson
// and database_faults.geojson into `folder`; in `crs` when not null, else
// WGS84 (RFC 7946). Throws InputError when PROJ cannot convert a position.
void WriteMatchesGeoJson(const std::vector<MatchedVertexFeature>& vertices,
                         const std::vector<DatabaseFault>& faults,
                         const LocalFrame& frame, const std::string& folder,
                         const OutputCrs* crs = nullptr);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RESULTS_MATCH_H_
