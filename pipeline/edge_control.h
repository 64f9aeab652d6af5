// Crossing edges as along-track control in the adjustment with road lines
// (issue 17; registration/edge_matcher.h), beside the lines of
// line_control.cc.
#ifndef ZEBRAGEO_PIPELINE_EDGE_CONTROL_H_
#define ZEBRAGEO_PIPELINE_EDGE_CONTROL_H_

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "adjustment/adjustment_io.h"
#include "adjustment/line_control.h"
#include "registration/edge_matcher.h"
#include "survey/results_lines.h"

namespace zebrageo {

// The corrected body pose at `time` (linear in position, slerp in attitude
// between the corrected samples, as Trajectory does); false outside them.
// (line_control.cc)
bool CorrectedPoseAt(const AdjustmentResult& result, double time, Pose* pose);
// The posterior horizontal sd (radial) of the corrected trajectory at
// `time`, from the nearest corrected sample (line_control.cc).
double PosteriorSdAt(const AdjustmentResult& result, double time);

// The reconstructed crossing edges among `points` (type crossing_edge)
// matched to the database crossings' edges on the trajectory of
// `zebra_result`: one along-track control point per edge point, appended
// to `control` and `rows`. Crossings whose bands the zebra front-end
// reconstructed are left out: their bands are control already, or were
// refused (a repainted crossing must not return through its edges).
// Returns how many control points were added.
int AddCrossingEdgeControl(
    const AdjustmentData& data, const AdjustmentOptions& options,
    const CrossingEdgeMatchOptions& match_options,
    const AdjustmentResult& zebra_result,
    const std::vector<ReconstructedLinePoint>& points,
    const std::unordered_map<int64_t, double>& exposure_time,
    std::vector<LineControlPoint>* control, std::vector<LineMatch>* rows);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_EDGE_CONTROL_H_
