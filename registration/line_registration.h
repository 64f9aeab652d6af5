// Road lines, dashes and crossing edges registered to the road-mark
// database as control for the adjustment (issue 9, issue 17): the options
// of every step.
#ifndef ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_
#define ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_

#include <string>

#include "registration/dash_matcher.h"
#include "registration/edge_matcher.h"
#include "registration/line_matcher.h"
#include "registration/line_offset.h"

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

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_LINE_REGISTRATION_H_
