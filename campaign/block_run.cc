#include "campaign/block_run.h"

#include <glog/logging.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>

#include "pipeline/exit_codes.h"
#include "pipeline/results_session.h"
#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/results.h"
#include "survey/survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

// `to` as a hard link of `from` (the same file, no copy, no path outside
// the block's folder); a copy when they are on different file systems.
void LinkFile(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  std::error_code error;
  fs::create_hard_link(fs::canonical(from), to, error);
  if (error == std::errc::cross_device_link) {
    LOG(WARNING) << "run-block: " << from << " is on another file system: "
                 << "copied, not linked";
    fs::copy_file(fs::canonical(from), to);
    return;
  }
  if (error) {
    throw std::runtime_error("cannot link " + from.string() + " to " +
                             to.string() + ": " + error.message());
  }
}

// The database file and its sidecars (a shapefile's .shx, .dbf, .prj).
void LinkDatabase(const Survey& survey, const fs::path& folder,
                  SurveyManifest* manifest) {
  const std::string& source = survey.manifest.roadmarks;
  if (source.rfind("PG:", 0) == 0) return;  // a database server: as it is
  const fs::path file = fs::canonical(survey.PathOf(source));
  const std::string name = "db-" + file.filename().string();
  for (const fs::directory_entry& e :
       fs::directory_iterator(file.parent_path())) {
    if (e.path().stem() == file.stem() && e.is_regular_file()) {
      LinkFile(e.path(), folder / ("db-" + e.path().filename().string()));
    }
  }
  manifest->roadmarks = name;
}

double CpuSeconds(const rusage& usage) {
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace

void WriteBlockSurvey(const Campaign& campaign, const CampaignBlock& block,
                      const std::string& folder_name) {
  const CampaignSurvey& entry = campaign.surveys.at(block.survey);
  const Survey survey = LoadSurvey(entry.folder);
  if (survey.trajectory.size() != entry.samples ||
      !(std::abs(survey.frame.origin().lat_deg - entry.origin.lat_deg) <
            1e-12 &&
        std::abs(survey.frame.origin().lon_deg - entry.origin.lon_deg) <
            1e-12)) {
    throw InputError(survey.PathOf(survey.manifest.trajectory), 0,
                     "changed since the campaign was planned (" +
                         std::to_string(survey.trajectory.size()) +
                         " samples, the plan has " +
                         std::to_string(entry.samples) + ")");
  }
  const fs::path folder(folder_name);
  fs::create_directories(folder);
  SurveyManifest manifest;
  manifest.name = entry.name + "-block-" + std::to_string(block.index);
  manifest.origin = entry.origin;
  manifest.roadmarks_crs = survey.manifest.roadmarks_crs;
  manifest.output_crs = survey.manifest.output_crs;
  manifest.roadmarks_layer = survey.manifest.roadmarks_layer;
  manifest.roadmarks_fields = survey.manifest.roadmarks_fields;
  manifest.roadmarks_margin_m = survey.manifest.roadmarks_margin_m;
  manifest.roadmarks = survey.manifest.roadmarks;
  LinkDatabase(survey, folder, &manifest);
  LinkFile(survey.PathOf(survey.manifest.rig), folder / manifest.rig);
  // The trajectory in WGS84 as the contract writes it (trajectory_crs
  // converted on reading).
  const std::vector<TrajectorySample>& samples = survey.trajectory.samples();
  WriteTrajectorySamples(
      std::vector<TrajectorySample>(samples.begin() + block.first_sample,
                                    samples.begin() + block.last_sample + 1),
      (folder / manifest.trajectory).string());
  ExposureTable table;
  for (const ExposureImage& image : survey.exposures.images) {
    if (image.time < block.start_time || image.time > block.end_time) continue;
    table.images.push_back(image);
    const fs::path source = survey.PathOf(image.image);
    std::error_code error;
    if (fs::is_regular_file(source, error)) {
      LinkFile(source, folder / image.image);
    }
  }
  WriteExposures(table, survey.rig, (folder / manifest.exposures).string());
  WriteManifest(manifest, (folder / "survey.yaml").string());
}

BlockRunResult RunCampaignBlock(const std::string& campaign_folder, int index,
                                const RunOptions& options,
                                const RunContext& context) {
  const Campaign campaign = ReadCampaign(campaign_folder);
  if (index < 0 || index >= static_cast<int>(campaign.blocks.size())) {
    throw UsageError("run-block: index " + std::to_string(index) +
                     " out of range: the campaign has " +
                     std::to_string(campaign.blocks.size()) + " blocks");
  }
  const CampaignBlock& block = campaign.blocks[index];
  const fs::path folder = BlockFolder(campaign.folder, index);
  const fs::path done = folder / kBlockDoneFile;
  BlockRunResult result;
  if (fs::exists(done)) {
    result.already_done = true;
    result.block = ReadJsonFile(done.string(), done.string());
    return result;
  }
  const auto start = std::chrono::steady_clock::now();
  const fs::path survey_folder = folder / "survey";
  if (!fs::exists(survey_folder)) {
    const fs::path partial = folder / "survey.partial";
    fs::remove_all(partial);
    WriteBlockSurvey(campaign, block, partial.string());
    fs::rename(partial, survey_folder);
  }
  const fs::path results = folder / "results";
  ResultsSession session(results.string(),
                         ResultsSession::OnError::kRemoveContractOutputs);
  const Survey survey = LoadSurvey(survey_folder.string());
  session.Open();
  const RunSummary run =
      RunSurveyPipeline(survey, results.string(), options, context);
  session.Succeeded();

  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  json& b = result.block;
  b["index"] = index;
  b["survey"] = campaign.surveys[block.survey].name;
  b["wall_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  b["cpu_s"] = CpuSeconds(usage);
  b["peak_memory_mb"] = usage.ru_maxrss / 1024.0;
  b["estimated_cpu_s"] = block.estimated_cpu_s;
  b["estimated_memory_mb"] = block.estimated_memory_mb;
  b["resumed_stages"] = run.report.value("resumed_stages", json::array());
  b["warnings"] = run.warnings;
  WriteFileAtomically(done.string(),
                      [&b](std::ostream& out) { out << b.dump(2) << "\n"; });
  return result;
}

}  // namespace zebrageo
