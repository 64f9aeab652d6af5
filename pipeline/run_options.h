// The options of `zebrageo run` as data: every stage's options in one
// struct, written and read as JSON (`zebrageo run --print-options`,
// `--options FILE`; a server's job). The JSON has one object per group,
// nested as the structs are, each key a field's name (snake_case), e.g.
//   {"lines": true, ..., "adjustment": {"vehicle_motion":
//       {"sideslip_sigma_rad": 0.0017453292519943296, ...}, ...}, ...}
// Angles are in radians as the fields say (_rad); a file may hold any
// subset: the rest keep their defaults.
#ifndef ZEBRAGEO_PIPELINE_RUN_OPTIONS_H_
#define ZEBRAGEO_PIPELINE_RUN_OPTIONS_H_

#include <nlohmann/json.hpp>
#include <string>

#include "adjustment/adjustment_options.h"
#include "pipeline/boresight_check.h"
#include "pipeline/report_stage.h"
#include "reconstruction/reconstruction.h"
#include "reconstruction/road_lines.h"
#include "registration/band_matcher.h"
#include "registration/line_registration.h"
#include "registration/paint_probe.h"
#include "registration/rematch.h"
#include "tiepoints/tie_points.h"

namespace zebrageo {

struct RunOptions {
  // Image tie points between exposures in the adjustment.
  bool tie_points = true;
  // Road lines as control beside the zebras (issue 9).
  bool lines = true;
  // The second registration pass, with the adjusted trajectory.
  bool rematch = true;
  // Worker threads of the road-line extraction (0: one per hardware
  // thread); the other stages take theirs from their options
  // (reconstruction.threads, adjustment.solver.num_threads). No result
  // depends on them.
  int threads = 0;

  // Before reconstruct: the rig's mount against what the images observe.
  BoresightCheckOptions boresight;
  // reconstruct: zebra bands, then road lines.
  ReconstructionOptions reconstruction;
  RoadLineOptions road_lines;
  // match: the bands to the road-mark database, the images probed for
  // paint where a database band was not seen.
  MatchOptions matching;
  PaintProbeOptions paint_probe;
  // adjust: tie points, road lines registered to the database, the
  // adjustment, the second registration pass's gates.
  TiePointOptions tie_point_matching;
  LineRegistrationOptions line_registration;
  AdjustmentOptions adjustment;
  RematchOptions second_pass;
  ReportOptions report;

  // "" or the first problem, named by its JSON path
  // ("adjustment.model.knot_spacing_s = -1: must be > 0").
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("tie_points", tie_points);
    v("lines", lines);
    v("rematch", rematch);
    v("threads", threads);
    v("boresight", boresight);
    v("reconstruction", reconstruction);
    v("road_lines", road_lines);
    v("matching", matching);
    v("paint_probe", paint_probe);
    v("tie_point_matching", tie_point_matching);
    v("line_registration", line_registration);
    v("adjustment", adjustment);
    v("second_pass", second_pass);
    v("report", report);
  }
};

// Every field, as nested objects.
nlohmann::json RunOptionsToJson(const RunOptions& options);
// `defaults` with the members of `json` applied, then checked. Throws
// UsageError naming the member (its path) for an unknown one, one of the
// wrong type, or a value Check() refuses.
RunOptions RunOptionsFromJson(const nlohmann::json& json,
                              const RunOptions& defaults = RunOptions());
// The same from a JSON file; the message names the file too.
RunOptions ReadRunOptions(const std::string& path,
                          const RunOptions& defaults = RunOptions());

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_RUN_OPTIONS_H_
