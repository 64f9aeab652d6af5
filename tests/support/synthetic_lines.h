// What the road-line stage (reconstruction/road_lines.h) would give for a
// simulated survey, synthesised from its truth without rendering (the
// geometry sweep, issue 17): reconstructed_lines.csv rows of the lane lines
// painted in the street.
//
// Frames and units: the survey's ENU frame, body FRD; metres. A point is
// the TRUE paint (World::lines, on the road surface) in the body frame of
// the TRUE pose plus noise; the adjustment then places it with the
// measured pose, as it does with the real stage's output.
//
// Like the band synthesis (synthetic_reconstruction.h), it must not flatter:
//  - a point is reported only where it projects inside both images of a
//    stereo pair (with the model's margin), within max_range_m of the left
//    camera and max_lateral_m of the vehicle, and no parked vehicle hides
//    it from either camera;
//  - a line seen by a pair is reported with the band recall of its range
//    (ReconstructionModel::Recall), at least min_points points;
//  - noise grows with range as the bands' does, mostly along the viewing
//    ray, with a part shared by the whole line (the road plane's error);
//  - the database's own faults (gaps, moved stretches) are the world's:
//    the synthesis sees the street as painted.
#ifndef ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_LINES_H_
#define ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_LINES_H_

#include <cstdint>
#include <vector>

#include "simulator/simulated_survey.h"
#include "survey/results_lines.h"
#include "tests/support/synthetic_reconstruction.h"

namespace zebrageo::support {

struct LineSynthesisOptions {
  double spacing_m = 1.0;     // between the points of a line
  double max_range_m = 16.0;  // RoadLineOptions::max_range_m
  double max_lateral_m = 8.0;
  int min_points = 3;
};

// Deterministic in `seed`; the band model's recall, noise and margin.
std::vector<ReconstructedLinePoint> SynthesiseLinePoints(
    const sim::SimulatedSurvey& survey, const ReconstructionModel& model,
    uint64_t seed, const LineSynthesisOptions& options = {});

}  // namespace zebrageo::support

#endif  // ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_LINES_H_
