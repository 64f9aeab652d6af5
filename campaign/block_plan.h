// Where a long trajectory is cut into overlapping blocks (the geometry of
// `zebrageo plan`): blocks of about PlanOptions::block_length_m, boundaries
// moved to where crossings are densest, overlaps widened to hold
// min_overlap_crossings crossings, and no block starting or ending where a
// crossing is only partly seen.
#ifndef ZEBRAGEO_CAMPAIGN_BLOCK_PLAN_H_
#define ZEBRAGEO_CAMPAIGN_BLOCK_PLAN_H_

#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "survey/roadmarks.h"
#include "survey/trajectory.h"

namespace zebrageo {

// A crossing of the database along the trajectory: the arc-length span of
// its bands' corners projected on the trajectory.
struct CrossingSpan {
  std::string crossing_id;
  double start_m = 0.0;
  double end_m = 0.0;
  double centre_m() const { return 0.5 * (start_m + end_m); }
};

// Horizontal arc length at every trajectory sample (metres from the first).
std::vector<double> ArcLengths(const Trajectory& trajectory);

// The database crossings within max_offset_m of the trajectory, by start.
std::vector<CrossingSpan> CrossingSpansAlong(const Trajectory& trajectory,
                                             const std::vector<double>& arc,
                                             const RoadmarkDatabase& database,
                                             const LocalFrame& frame,
                                             double max_offset_m);

// [start_m, end_m] of each block over a trajectory of `length_m`, in order;
// consecutive blocks overlap, the first starts at 0, the last ends at
// length_m. One block when the trajectory is shorter than a block and a
// half.
struct BlockRange {
  double start_m = 0.0;
  double end_m = 0.0;
};
std::vector<BlockRange> PlanBlockRanges(double length_m,
                                        const std::vector<CrossingSpan>& spans,
                                        const PlanOptions& options);

// The crossings seen whole from both sides of [start_m, end_m] (the
// overlap's control): their view zone lies inside it.
std::vector<std::string> CrossingsInside(const std::vector<CrossingSpan>& spans,
                                         double start_m, double end_m,
                                         const PlanOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_BLOCK_PLAN_H_
