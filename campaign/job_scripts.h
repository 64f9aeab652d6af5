// The cluster jobs of a campaign: a Slurm job array (one task per block,
// resources from the blocks' estimated cost) and a merge job that runs
// after it (--dependency=afterok), and a Kubernetes Indexed Job doing the
// same with its merge Job. Neither scheduler is reimplemented here: these
// are their own job descriptions.
#ifndef ZEBRAGEO_CAMPAIGN_JOB_SCRIPTS_H_
#define ZEBRAGEO_CAMPAIGN_JOB_SCRIPTS_H_

#include <string>

#include "campaign/campaign.h"

namespace zebrageo {

// What every array task asks the scheduler for: the largest block's
// estimate times the cost model's safety.
struct BlockResources {
  int cpus = 1;
  int memory_mb = 0;
  int time_minutes = 0;
};
BlockResources BlockResourcesOf(const Campaign& campaign);

// CAMPAIGN/slurm/blocks.sbatch, merge.sbatch, submit.sh.
std::string SlurmArrayScript(const Campaign& campaign);
std::string SlurmMergeScript(const Campaign& campaign);
std::string SlurmSubmitScript(const Campaign& campaign);
// CAMPAIGN/kubernetes/job.yaml: two YAML documents, the Indexed Job of the
// blocks and the merge Job.
std::string KubernetesManifest(const Campaign& campaign);

// Writes the four files above (scripts executable).
void WriteJobFiles(const Campaign& campaign);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_JOB_SCRIPTS_H_
