// `zebrageo plan`: surveys cut into blocks (campaign/block_plan.h), the
// campaign folder written with its manifest, the blocks' run options and
// the cluster jobs (campaign/job_scripts.h).
#ifndef ZEBRAGEO_CAMPAIGN_PLAN_H_
#define ZEBRAGEO_CAMPAIGN_PLAN_H_

#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "pipeline/run_options.h"
#include "survey/survey.h"

namespace zebrageo {

// Loads and checks every survey (as `zebrageo run` would), plans the
// blocks and writes `campaign_folder`, which must not hold a campaign yet.
// Throws UsageError for bad options or an existing campaign, InputError
// for a survey that cannot be processed (nothing is written then).
Campaign PlanCampaign(const std::vector<std::string>& survey_folders,
                      const std::string& campaign_folder,
                      const PlanOptions& options,
                      const RunOptions& run_options);

// Appends to `campaign` the blocks and overlaps of `survey`, its
// campaign->surveys[survey_index] (length and crossings set there): the
// geometry of PlanCampaign, in memory (bench/campaign_bench plans a
// geometry-level campaign with it).
void PlanSurveyBlocks(const Survey& survey, int survey_index,
                      const PlanOptions& options, Campaign* campaign);

// The options every block runs with (CAMPAIGN/options.json).
RunOptions CampaignRunOptions(const std::string& campaign_folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_PLAN_H_
