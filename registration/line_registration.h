// Road lines, whole dashes and crossing edges registered to the road-mark
// database as control for the adjustment (issue 9, issue 17), on the
// trajectory an adjustment with the zebra crossings corrected:
//   - each reconstructed line point matched to a database line
//     (line_matcher.h); database lines that disagree with the others, or
//     (with a corrected trajectory) lie beyond its posterior sd, rejected;
//     without zebra control, each window's points shifted across the track
//     by the offset the lines agree on (line_offset.h), and only lines
//     another line vouched for kept;
//   - whole dashes matched to the database's dashes along the track
//     (dash_matcher.h), once the crossings corrected the trajectory;
//   - the edges of crossings never seen whole (edge_registration.h).
// In memory: the pipeline writes line_matches.csv and line_control.json.
#ifndef ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_
#define ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_

#include <optional>
#include <string>
#include <vector>

#include "registration/dash_matcher.h"
#include "registration/edge_matcher.h"
#include "registration/line_matcher.h"
#include "registration/line_offset.h"
#include "survey/exposures.h"
#include "survey/geodesy.h"
#include "survey/line_control_points.h"
#include "survey/results.h"
#include "survey/results_lines.h"
#include "survey/roadmarks.h"

namespace zebrageo {

struct LineRegistrationOptions {
  // Line points to database lines (line_matcher.h).
  LineMatchOptions lines;
  // Database lines that disagree with the others.
  LineConsistencyOptions consistency;
  // Without zebra control: the cross-track offset the lines agree on.
  LateralOffsetOptions lateral_offsets;
  // Whole dashes along the track (dash_matcher.h).
  DashMatchOptions dashes;
  // Crossing edges along the track (edge_matcher.h).
  CrossingEdgeMatchOptions crossing_edges;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("lines", lines);
    v("consistency", consistency);
    v("lateral_offsets", lateral_offsets);
    v("dashes", dashes);
    v("crossing_edges", crossing_edges);
  }
};

// What the registration reads besides the line points. Pointers, not
// owned.
struct LineRegistrationInput {
  const RoadmarkDatabase* roadmarks = nullptr;
  const LocalFrame* frame = nullptr;
  const ExposureTable* exposures = nullptr;
  // The zebra bands and their matches: the edges of a crossing seen whole
  // are not control (its bands are, or were refused).
  const std::vector<ReconstructedVertex>* vertices = nullptr;
  const std::vector<VertexMatch>* matches = nullptr;
  // The trajectory the zebra crossings corrected (or the input, kept).
  CorrectedTrajectory trajectory;
  // Floor on the database's own sigma (AdjustmentOptions control.
  // min_database_sigma_m).
  double min_database_sigma_m = 0.01;
  // The rejected database lines as warnings in the log (else VLOG(1)): off
  // for a trial registration whose result the user never gets.
  bool log_warnings = true;
};

struct LineRegistration {
  // The adjustment's control (adjustment/line_costs.h).
  std::vector<LineControlPoint> control;
  // line_matches.csv and line_control.json; no record when nothing was
  // registered (a database without lines, and no crossing edge).
  std::vector<LineMatch> rows;
  std::optional<LineControlRecord> record;
  // Database lines rejected, or none to match.
  std::vector<std::string> warnings;
};

LineRegistration RegisterRoadLines(
    const std::vector<ReconstructedLinePoint>& points,
    const LineRegistrationInput& input, const LineRegistrationOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_
