// A campaign (issue 46): long surveys split into overlapping blocks along
// the trajectory, each block run as its own survey by a cluster's job array
// (Slurm or a Kubernetes Indexed Job), then merged into one corrected
// trajectory per survey. COLMAP's hierarchical mapper and ODM's split-merge
// are the models; here the blocks share the survey's ENU origin and its
// road-mark database, and the merge blends the blocks' corrections over the
// overlaps so position and attitude stay continuous.
//
// The campaign folder (written by `zebrageo plan`, docs in campaign/README):
//   campaign.json          the manifest (ReadCampaign / WriteCampaign)
//   options.json           the run options of every block
//   slurm/blocks.sbatch    the job array, one task per block
//   slurm/merge.sbatch     the merge, after the array (afterok)
//   slurm/submit.sh        submits both
//   kubernetes/job.yaml    an Indexed Job doing the same, and the merge Job
//   blocks/block-NNNN/     survey/ (images by hard link), results/,
//                          block.json (written last: the block is done)
#ifndef ZEBRAGEO_CAMPAIGN_CAMPAIGN_H_
#define ZEBRAGEO_CAMPAIGN_CAMPAIGN_H_

#include <string>
#include <vector>

#include "survey/geodesy.h"

namespace zebrageo {

inline constexpr char kCampaignFile[] = "campaign.json";
inline constexpr char kCampaignOptionsFile[] = "options.json";
inline constexpr char kBlockDoneFile[] = "block.json";

// A block's cost from its size: linear in stereo pairs, measured with
// `zebrageo run` on simulated surveys (docs/results.md, issue 46). The
// scheduler gets the estimate times `safety`.
struct BlockCostModel {
  double cpu_s_per_pair = 0.25;
  double cpu_s_base = 20.0;
  double memory_mb_per_pair = 0.6;
  double memory_mb_base = 400.0;
  double safety = 3.0;
  std::string Check() const;
};

struct PlanOptions {
  // Target block length and overlap along the trajectory, metres.
  double block_length_m = 500.0;
  double overlap_m = 120.0;
  // An overlap is widened (up to max_overlap_m) until it holds this many
  // crossings, where the road has them.
  int min_overlap_crossings = 2;
  double max_overlap_m = 400.0;
  // A boundary may move this share of a block's length to where the
  // crossings are densest.
  double boundary_search_share = 0.25;
  // Cameras see a crossing from this far before it: a block's first
  // exposure is never inside [crossing - view, crossing end], nor its last.
  double crossing_view_m = 35.0;
  double crossing_margin_m = 5.0;
  // A crossing farther than this from the trajectory is not on the road.
  double crossing_max_offset_m = 30.0;
  BlockCostModel cost;
  // Job scripts.
  std::string zebrageo_path;  // absolute path of the program in the scripts
  int cpus_per_task = 2;
  std::string results_folder;  // of the merge; "": CAMPAIGN/results
  std::string kubernetes_image = "zebrageo:latest";
  std::string kubernetes_claim = "zebrageo-data";
  int kubernetes_parallelism = 4;
  std::string Check() const;
};

struct CampaignSurvey {
  std::string name;    // unique in the campaign: the merge's subfolder
  std::string folder;  // absolute
  Geodetic origin;     // the ENU origin every block uses
  int samples = 0;     // trajectory samples
  int images = 0;
  double length_m = 0.0;
  int crossings = 0;  // database crossings on the trajectory
};

struct CampaignBlock {
  int index = 0;
  int survey = 0;  // into Campaign::surveys
  // Inclusive trajectory sample range of the survey, and its span.
  int first_sample = 0;
  int last_sample = 0;
  double start_time = 0.0;
  double end_time = 0.0;
  double start_m = 0.0;
  double end_m = 0.0;
  int exposures = 0;
  int images = 0;
  int crossings = 0;
  // BlockCostModel's estimate (without the safety factor).
  double estimated_cpu_s = 0.0;
  double estimated_memory_mb = 0.0;
};

// Where block `before` and block `after` (consecutive, same survey) both
// run: [after.start, before.end].
struct CampaignOverlap {
  int survey = 0;
  int before = 0;
  int after = 0;
  double start_time = 0.0;
  double end_time = 0.0;
  double start_m = 0.0;
  double end_m = 0.0;
  std::vector<std::string> crossings;
};

struct Campaign {
  std::string name;
  std::string folder;  // absolute, not written
  PlanOptions options;
  std::vector<CampaignSurvey> surveys;
  std::vector<CampaignBlock> blocks;
  std::vector<CampaignOverlap> overlaps;
};

// CAMPAIGN/campaign.json. ReadCampaign throws InputError naming the file
// and the member that is missing or wrong.
void WriteCampaign(const Campaign& campaign);
Campaign ReadCampaign(const std::string& campaign_folder);

// CAMPAIGN/blocks/block-NNNN.
std::string BlockFolder(const std::string& campaign_folder, int index);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_CAMPAIGN_H_
