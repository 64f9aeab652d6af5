// `zebrageo plan`, `zebrageo run-block` and `zebrageo merge`: a campaign
// on a cluster (campaign/). Argument parsing only.
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "campaign/block_run.h"
#include "campaign/merge.h"
#include "campaign/plan.h"
#include "pipeline/exit_codes.h"
#include "pipeline/run_options.h"
#include "tools/commands.h"
#include "tools/progress_bars.h"

namespace zebrageo {
namespace {

struct PlanArguments {
  std::vector<std::string> surveys;
  std::string campaign;
  std::string options_file;
  PlanOptions plan;
};

struct RunBlockArguments {
  std::string campaign;
  int index = -1;
  int threads = 0;
  CLI::App* command = nullptr;
};

// The running program, for the job scripts.
std::string ThisProgram() {
  std::error_code error;
  const auto path = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? "zebrageo" : path.string();
}

// --index, else the scheduler's: Slurm's array task or Kubernetes' Indexed
// Job completion index.
int BlockIndex(const RunBlockArguments& args) {
  if (args.command->get_option("--index")->count() > 0) return args.index;
  for (const char* name : {"SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"}) {
    const char* value = std::getenv(name);
    if (value == nullptr || *value == '\0') continue;
    char* end = nullptr;
    const long index = std::strtol(value, &end, 10);
    if (*end != '\0' || index < 0 || index > INT_MAX) {
      throw UsageError(std::string("run-block: ") + name + "=" + value +
                       " is not a block index");
    }
    return static_cast<int>(index);
  }
  throw UsageError(
      "run-block: no --index, SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX");
}

}  // namespace

void AddCampaignCommands(CLI::App* app, std::vector<Command>* commands) {
  auto plan = std::make_shared<PlanArguments>();
  CLI::App* p = app->add_subcommand(
      "plan",
      "Split surveys into overlapping blocks and write a campaign: its "
      "manifest, a Slurm job array with its merge job, a Kubernetes "
      "Indexed Job.");
  p->add_option("surveys", plan->surveys, "survey folders")->required();
  p->add_option("-o,--output", plan->campaign, "campaign folder to write")
      ->required();
  p->add_option("--block-length-m", plan->plan.block_length_m,
                "target block length along the trajectory, metres")
      ->capture_default_str();
  p->add_option("--overlap-m", plan->plan.overlap_m,
                "overlap of consecutive blocks, metres (widened to hold "
                "--min-overlap-crossings)")
      ->capture_default_str();
  p->add_option("--min-overlap-crossings", plan->plan.min_overlap_crossings,
                "crossings an overlap holds where the road has them")
      ->capture_default_str();
  p->add_option("--options", plan->options_file,
                "JSON file of run options for every block (`zebrageo run "
                "--print-options`)")
      ->check(CLI::ExistingFile);
  p->add_option("--cpus-per-task", plan->plan.cpus_per_task,
                "CPUs each block asks for")
      ->capture_default_str();
  p->add_option("--results", plan->plan.results_folder,
                "the merge's results folder (default CAMPAIGN/results)");
  p->add_option("--zebrageo", plan->plan.zebrageo_path,
                "the program the Slurm scripts run (default: this one)");
  p->add_option("--kubernetes-image", plan->plan.kubernetes_image,
                "container image of the Kubernetes jobs")
      ->capture_default_str();
  p->add_option("--kubernetes-claim", plan->plan.kubernetes_claim,
                "PersistentVolumeClaim holding the surveys and the campaign")
      ->capture_default_str();
  p->add_option("--kubernetes-parallelism", plan->plan.kubernetes_parallelism,
                "pods running at once")
      ->capture_default_str();
  commands->push_back({p, [plan] {
                         PlanOptions options = plan->plan;
                         if (options.zebrageo_path.empty()) {
                           options.zebrageo_path = ThisProgram();
                         }
                         RunOptions run;
                         if (!plan->options_file.empty()) {
                           run = ReadRunOptions(plan->options_file);
                         }
                         const Campaign c = PlanCampaign(
                             plan->surveys, plan->campaign, options, run);
                         std::cout << "plan: " << c.folder << ": "
                                   << c.blocks.size() << " blocks, "
                                   << c.overlaps.size()
                                   << " overlaps; submit with " << c.folder
                                   << "/slurm/submit.sh\n";
                       }});

  auto block = std::make_shared<RunBlockArguments>();
  CLI::App* r = app->add_subcommand(
      "run-block",
      "Run one block of a campaign (resumable: a rerun finishes it or does "
      "nothing). The index is --index, SLURM_ARRAY_TASK_ID or "
      "JOB_COMPLETION_INDEX.");
  block->command = r;
  r->add_option("campaign", block->campaign, "campaign folder")->required();
  r->add_option("--index", block->index, "block index (0-based)");
  AddThreadsOption(r, &block->threads);
  commands->push_back(
      {r, [block] {
         const int index = BlockIndex(*block);
         RunOptions options = CampaignRunOptions(block->campaign);
         ApplyThreadsOption(*block->command->get_option("--threads"),
                            block->threads, &options);
         RunContext context;
         context.progress = ProgressBars();
         context.cancel = CancelOnSignal();
         const BlockRunResult result =
             RunCampaignBlock(block->campaign, index, options, context);
         std::cout << "run-block " << index << ": "
                   << (result.already_done ? "already done" : "done") << "\n";
       }});

  auto merge = std::make_shared<StageArguments>();
  CLI::App* m = app->add_subcommand(
      "merge",
      "Join a campaign's blocks into one result per survey, with the "
      "campaign's report.");
  m->add_option("campaign", merge->survey, "campaign folder")->required();
  m->add_option("-o,--output", merge->results, "results folder")->required();
  commands->push_back({m, [merge] {
                         MergeCampaign(merge->survey, merge->results);
                         std::cout << "merge: " << merge->results << "/"
                                   << kCampaignReportFile << "\n";
                       }});
}

}  // namespace zebrageo
