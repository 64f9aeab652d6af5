// `zebrageo merge CAMPAIGN -o RESULTS`: the blocks joined into one result
// per survey.
//
// Boundary adjustment: over an overlap both blocks are adjusted with the
// same crossings (the plan puts at least two there where the road has
// them), so each block's correction there is consistent with both blocks'
// control; the merge weights block `before` from 1 down to 0 across the
// overlap and `after` from 0 up to 1 (a smoothstep in time), lerps the
// positions and slerps the attitudes. Position and attitude are therefore
// continuous, and each block dominates where its own control is. The
// blocks' disagreement over each overlap (the seam a hard cut would make)
// is measured and reported.
//
// RESULTS/<survey>/ holds the contract's outputs of each survey
// (trajectory_corrected.csv, poses.csv, bands.geojson, gcp_residuals.csv,
// report.json, report.html), RESULTS/campaign_report.json the campaign's
// (per-block figures, seams, uncontrolled stretches, database faults).
// RESULTS is written in a sibling folder and renamed when whole.
#ifndef ZEBRAGEO_CAMPAIGN_MERGE_H_
#define ZEBRAGEO_CAMPAIGN_MERGE_H_

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "survey/trajectory.h"

namespace zebrageo {

inline constexpr char kCampaignReportFile[] = "campaign_report.json";

// The merge weight of a block at `t`, given the overlaps before and after
// it (null when none): 0 outside [start, end], 1 between the overlaps.
double BlockWeight(double t, double start_time, double end_time,
                   const double* before_overlap_end,
                   const double* after_overlap_start);

// One block's corrected body poses at the survey's trajectory samples
// block->first_sample .. block->last_sample, and its overlaps (null when
// none): what the merge blends.
struct BlockPoses {
  const CampaignBlock* block = nullptr;
  const double* before_overlap_end = nullptr;
  const double* after_overlap_start = nullptr;
  const std::vector<Pose>* poses = nullptr;
};

// The survey's trajectory from its blocks (in campaign order): at each
// sample (`times`, the survey's sample times) the blocks holding it
// blended with their BlockWeight, positions lerped and attitudes slerped.
// dominant[i] is the index into `blocks` of the block weighing most at
// sample i. Linear in the blocks' samples (a long survey's many blocks do
// not multiply). Throws UsageError for a sample no block holds.
std::vector<Pose> BlendBlockPoses(const std::vector<double>& times,
                                  const std::vector<BlockPoses>& blocks,
                                  std::vector<int>* dominant);

// Merges every block (all must be done: block.json) into `results_folder`.
// Returns the campaign report. Throws UsageError for a block not done or a
// block result that does not match its survey.
nlohmann::json MergeCampaign(const std::string& campaign_folder,
                             const std::string& results_folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_MERGE_H_
