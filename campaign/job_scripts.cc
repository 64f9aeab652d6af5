#include "campaign/job_scripts.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "survey/atomic_file.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// A word for bash: single-quoted, with ' as '\''.
std::string Quote(const std::string& word) {
  std::string quoted = "'";
  for (char c : word)
    quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// A Kubernetes object name (RFC 1123 label): lower-case letters, digits
// and '-', at most `max` characters, starting and ending alphanumeric.
std::string KubernetesName(const std::string& wanted, size_t max) {
  std::string name;
  for (char c : wanted) {
    const char l =
        static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    name += std::isalnum(static_cast<unsigned char>(l)) ? l : '-';
  }
  if (name.size() > max) name.resize(max);
  while (!name.empty() && name.back() == '-') name.pop_back();
  while (!name.empty() && name.front() == '-') name.erase(name.begin());
  return name.empty() ? "campaign" : name;
}

// The deepest folder holding the campaign, its results and every survey:
// the one volume the pods mount (hard links need one file system anyway).
std::string CommonRoot(const Campaign& campaign) {
  std::vector<fs::path> paths{fs::path(campaign.folder),
                              fs::path(campaign.options.results_folder)};
  for (const CampaignSurvey& s : campaign.surveys) paths.emplace_back(s.folder);
  fs::path root;
  bool first = true;
  for (const fs::path& p : paths) {
    if (first) {
      root = p;
      first = false;
      continue;
    }
    fs::path common;
    auto a = root.begin();
    auto b = p.begin();
    for (; a != root.end() && b != p.end() && *a == *b; ++a, ++b) common /= *a;
    root = common;
  }
  return root.empty() ? "/" : root.string();
}

std::string Program(const Campaign& campaign) {
  return campaign.options.zebrageo_path.empty()
             ? "zebrageo"
             : campaign.options.zebrageo_path;
}

std::string LogsFolder(const Campaign& campaign) {
  return (fs::path(campaign.folder) / "logs").string();
}

}  // namespace

BlockResources BlockResourcesOf(const Campaign& campaign) {
  double cpu_s = 0.0, memory_mb = 0.0;
  for (const CampaignBlock& b : campaign.blocks) {
    cpu_s = std::max(cpu_s, b.estimated_cpu_s);
    memory_mb = std::max(memory_mb, b.estimated_memory_mb);
  }
  const double safety = campaign.options.cost.safety;
  BlockResources r;
  r.cpus = campaign.options.cpus_per_task;
  r.memory_mb = static_cast<int>(std::ceil(memory_mb * safety));
  // CPU seconds as wall time: no credit taken for the threads' scaling.
  // At least 15 minutes: a small block on a busy node is not a reason to
  // kill it.
  r.time_minutes =
      std::max(15, static_cast<int>(std::ceil(cpu_s * safety / 60.0)));
  return r;
}

std::string SlurmArrayScript(const Campaign& campaign) {
  const BlockResources r = BlockResourcesOf(campaign);
  const int n = static_cast<int>(campaign.blocks.size());
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# zebrageo campaign " << campaign.name << ": one array task per block ("
    << n << " blocks).\n"
    << "# Resources: the largest block's estimated cost times "
    << campaign.options.cost.safety << " (campaign.json).\n"
    << "# A requeued task resumes its block and gives the same result.\n"
    << "#SBATCH --job-name=zebrageo-blocks\n"
    << "#SBATCH --array=0-" << (n - 1) << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << r.cpus << "\n"
    << "#SBATCH --mem=" << r.memory_mb << "M\n"
    << "#SBATCH --time=" << r.time_minutes << "\n"
    << "#SBATCH --requeue\n"
    << "#SBATCH --open-mode=append\n"
    << "#SBATCH --output=" << LogsFolder(campaign) << "/block-%a.log\n"
    << "set -euo pipefail\n"
    << "exec " << Quote(Program(campaign)) << " run-block "
    << Quote(campaign.folder)
    << " --index \"${SLURM_ARRAY_TASK_ID}\" --threads \"${SLURM_CPUS_PER_TASK:-"
    << r.cpus << "}\"\n";
  return s.str();
}

std::string SlurmMergeScript(const Campaign& campaign) {
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# zebrageo campaign " << campaign.name
    << ": the merge, after every block (submit.sh: --dependency=afterok).\n"
    << "#SBATCH --job-name=zebrageo-merge\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --mem=" << BlockResourcesOf(campaign).memory_mb << "M\n"
    << "#SBATCH --time=" << BlockResourcesOf(campaign).time_minutes << "\n"
    << "#SBATCH --output=" << LogsFolder(campaign) << "/merge.log\n"
    << "set -euo pipefail\n"
    << "exec " << Quote(Program(campaign)) << " merge "
    << Quote(campaign.folder) << " -o "
    << Quote(campaign.options.results_folder) << "\n";
  return s.str();
}

std::string SlurmSubmitScript(const Campaign& campaign) {
  const fs::path slurm = fs::path(campaign.folder) / "slurm";
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# Submits the campaign's block array, then its merge once every task\n"
    << "# has succeeded. Prints the two job ids. Extra arguments go to both\n"
    << "# sbatch calls (e.g. --partition=NAME).\n"
    << "set -euo pipefail\n"
    << "mkdir -p " << Quote(LogsFolder(campaign)) << "\n"
    << "array=$(sbatch --parsable \"$@\" "
    << Quote((slurm / "blocks.sbatch").string()) << ")\n"
    << "array=${array%%;*}\n"
    << "merge=$(sbatch --parsable \"$@\" --dependency=afterok:${array} "
    << "--kill-on-invalid-dep=yes " << Quote((slurm / "merge.sbatch").string())
    << ")\n"
    << "echo \"${array} ${merge%%;*}\"\n";
  return s.str();
}

std::string KubernetesManifest(const Campaign& campaign) {
  const BlockResources r = BlockResourcesOf(campaign);
  const int n = static_cast<int>(campaign.blocks.size());
  const std::string name = KubernetesName("zebrageo-" + campaign.name, 50);
  const std::string root = CommonRoot(campaign);
  auto pod = [&](const std::string& container,
                 const std::vector<std::string>& command, bool indexed) {
    YAML::Node c;
    c["name"] = container;
    c["image"] = campaign.options.kubernetes_image;
    for (const std::string& word : command) c["command"].push_back(word);
    if (indexed) {
      // Kubernetes sets JOB_COMPLETION_INDEX itself for Indexed Jobs; it is
      // named here so the wiring to run-block is explicit.
      YAML::Node env;
      env["name"] = "JOB_COMPLETION_INDEX";
      env["valueFrom"]["fieldRef"]["fieldPath"] =
          "metadata.annotations['batch.kubernetes.io/job-completion-index']";
      c["env"].push_back(env);
    }
    c["resources"]["requests"]["cpu"] = std::to_string(r.cpus);
    c["resources"]["requests"]["memory"] = std::to_string(r.memory_mb) + "Mi";
    c["resources"]["limits"]["memory"] = std::to_string(r.memory_mb) + "Mi";
    YAML::Node mount;
    mount["name"] = "data";
    mount["mountPath"] = root;
    c["volumeMounts"].push_back(mount);
    YAML::Node spec;
    spec["restartPolicy"] = "Never";
    spec["containers"].push_back(c);
    YAML::Node volume;
    volume["name"] = "data";
    volume["persistentVolumeClaim"]["claimName"] =
        campaign.options.kubernetes_claim;
    spec["volumes"].push_back(volume);
    return spec;
  };
  YAML::Node blocks;
  blocks["apiVersion"] = "batch/v1";
  blocks["kind"] = "Job";
  blocks["metadata"]["name"] = name + "-blocks";
  blocks["metadata"]["labels"]["app"] = "zebrageo";
  blocks["spec"]["completionMode"] = "Indexed";
  blocks["spec"]["completions"] = n;
  blocks["spec"]["parallelism"] =
      std::min(n, campaign.options.kubernetes_parallelism);
  // A failed pod is retried: run-block resumes and gives the same result.
  blocks["spec"]["backoffLimit"] = 3 * n;
  blocks["spec"]["template"]["spec"] =
      pod("run-block",
          // One word: a number alone would be a YAML integer, and a
          // container's command is a list of strings.
          {"zebrageo", "run-block", campaign.folder,
           "--threads=" + std::to_string(r.cpus)},
          true);
  YAML::Node merge;
  merge["apiVersion"] = "batch/v1";
  merge["kind"] = "Job";
  merge["metadata"]["name"] = name + "-merge";
  merge["metadata"]["labels"]["app"] = "zebrageo";
  merge["spec"]["completions"] = 1;
  merge["spec"]["backoffLimit"] = 2;
  merge["spec"]["template"]["spec"] =
      pod("merge",
          {"zebrageo", "merge", campaign.folder, "-o",
           campaign.options.results_folder},
          false);
  YAML::Emitter out;
  out << YAML::BeginDoc << blocks << YAML::EndDoc;
  out << YAML::BeginDoc << merge << YAML::EndDoc;
  std::ostringstream text;
  text << "# zebrageo campaign " << campaign.name << " on Kubernetes: the " << n
       << " blocks as an Indexed Job, then the merge\n"
       << "# (kubectl apply the first document, kubectl wait "
          "--for=condition=complete job/"
       << name << "-blocks, then the second).\n"
       << "# The PersistentVolumeClaim " << campaign.options.kubernetes_claim
       << " must hold " << root << " at the same path.\n"
       << out.c_str() << "\n";
  return text.str();
}

void WriteJobFiles(const Campaign& campaign) {
  const fs::path folder(campaign.folder);
  fs::create_directories(folder / "slurm");
  fs::create_directories(folder / "kubernetes");
  fs::create_directories(folder / "logs");
  const auto write = [](const fs::path& path, const std::string& text,
                        bool executable) {
    WriteFileAtomically(path.string(),
                        [&text](std::ostream& out) { out << text; });
    if (executable) {
      fs::permissions(path,
                      fs::perms::owner_exec | fs::perms::group_exec |
                          fs::perms::others_exec,
                      fs::perm_options::add);
    }
  };
  write(folder / "slurm" / "blocks.sbatch", SlurmArrayScript(campaign), true);
  write(folder / "slurm" / "merge.sbatch", SlurmMergeScript(campaign), true);
  write(folder / "slurm" / "submit.sh", SlurmSubmitScript(campaign), true);
  write(folder / "kubernetes" / "job.yaml", KubernetesManifest(campaign),
        false);
}

}  // namespace zebrageo
