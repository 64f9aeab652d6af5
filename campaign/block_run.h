// `zebrageo run-block CAMPAIGN --index i`: one block of a campaign as a
// survey of its own, then `zebrageo run` on it.
//
// The block's survey (CAMPAIGN/blocks/block-NNNN/survey) holds the
// survey's trajectory and exposures within the block, its rig and road-mark
// database, and its images by hard link: the path confinement of the
// survey format holds without --allow-outside-paths. It is written into
// survey.partial and renamed when whole. The results (…/results) are
// written by the pipeline, which resumes every finished stage; block.json,
// written last, marks the block done. A rerun (a requeued or retried task)
// therefore finishes what was left, or does nothing, and the result is the
// same.
#ifndef ZEBRAGEO_CAMPAIGN_BLOCK_RUN_H_
#define ZEBRAGEO_CAMPAIGN_BLOCK_RUN_H_

#include <nlohmann/json.hpp>
#include <string>

#include "campaign/campaign.h"
#include "pipeline/pipeline.h"

namespace zebrageo {

struct BlockRunResult {
  bool already_done = false;  // block.json was there: nothing was run
  nlohmann::json block;       // block.json
};

// Runs block `index` with `options` (the campaign's, CampaignRunOptions,
// threads aside). Throws UsageError for an index out of range or a
// campaign that cannot be read, InputError/StageFailedError as `run`.
BlockRunResult RunCampaignBlock(const std::string& campaign_folder, int index,
                                const RunOptions& options,
                                const RunContext& context = {});

// Writes the block's survey folder (`folder`, which must not exist) from
// the loaded campaign survey: exposed for the tests.
void WriteBlockSurvey(const Campaign& campaign, const CampaignBlock& block,
                      const std::string& folder);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_BLOCK_RUN_H_
