// `zebrageo plan`: surveys cut into blocks (campaign/block_plan.h), the
// campaign folder written with its manifest, the blocks' run options and
// the cluster jobs (campaign/job_scripts.h).
#ifndef ZEBRAGEO_CAMPAIGN_PLAN_H_
#define ZEBRAGEO_CAMPAIGN_PLAN_H_

#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "pipeline/run_options.h"

namespace zebrageo {

// Loads and checks every survey (as `zebrageo run` would), plans the
// blocks and writes `campaign_folder`, which must not hold a campaign yet.
// Throws UsageError for bad options or an existing campaign, InputError
// for a survey that cannot be processed (nothing is written then).
Campaign PlanCampaign(const std::vector<std::string>& survey_folders,
                      const std::string& campaign_folder,
                      const PlanOptions& options,
                      const RunOptions& run_options);

// The options every block runs with (CAMPAIGN/options.json).
RunOptions CampaignRunOptions(const std::string& campaign_folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_PLAN_H_
