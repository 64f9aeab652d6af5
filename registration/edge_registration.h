// Crossing edges as along-track control (issue 17; edge_matcher.h), beside
// the road lines of line_registration.h.
#ifndef ZEBRAGEO_REGISTRATION_EDGE_REGISTRATION_H_
#define ZEBRAGEO_REGISTRATION_EDGE_REGISTRATION_H_

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "registration/edge_matcher.h"
#include "registration/line_registration.h"

namespace zebrageo {

// The reconstructed crossing edges among `points` (type crossing_edge)
// matched to the database crossings' edges on input.trajectory: one
// along-track control point per edge point, appended to `control` and
// `rows`. Crossings whose bands the zebra front-end reconstructed are left
// out: their bands are control already, or were refused (a repainted
// crossing must not return through its edges). Returns how many control
// points were added.
int AddCrossingEdgeControl(
    const std::vector<ReconstructedLinePoint>& points,
    const std::unordered_map<int64_t, double>& exposure_time,
    const LineRegistrationInput& input,
    const CrossingEdgeMatchOptions& match_options,
    std::vector<LineControlPoint>* control, std::vector<LineMatch>* rows);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_EDGE_REGISTRATION_H_
