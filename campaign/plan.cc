#include "campaign/plan.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "campaign/block_plan.h"
#include "campaign/job_scripts.h"
#include "pipeline/exit_codes.h"
#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

// A folder name of letters, digits, '.', '_' and '-', unique in `taken`.
std::string UniqueName(const std::string& wanted,
                       std::set<std::string>* taken) {
  std::string base;
  for (char c : wanted) {
    base += std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
                    c == '_' || c == '-'
                ? c
                : '_';
  }
  if (base.empty() || base == "." || base == "..") base = "survey";
  std::string name = base;
  for (int k = 2; taken->count(name); ++k)
    name = base + "-" + std::to_string(k);
  taken->insert(name);
  return name;
}

// Index of the last sample at or before `s`, or of the first at or after.
int SampleAtOrBefore(const std::vector<double>& arc, double s) {
  const auto it = std::upper_bound(arc.begin(), arc.end(), s + 1e-9);
  return std::max(0, static_cast<int>(it - arc.begin()) - 1);
}
int SampleAtOrAfter(const std::vector<double>& arc, double s) {
  const auto it = std::lower_bound(arc.begin(), arc.end(), s - 1e-9);
  return std::min(static_cast<int>(arc.size()) - 1,
                  static_cast<int>(it - arc.begin()));
}

}  // namespace

void PlanSurveyBlocks(const Survey& survey, int survey_index,
                      const PlanOptions& options, Campaign* campaign) {
  const std::vector<double> arc = ArcLengths(survey.trajectory);
  const std::vector<CrossingSpan> spans =
      CrossingSpansAlong(survey.trajectory, arc, survey.roadmarks, survey.frame,
                         options.crossing_max_offset_m);
  CampaignSurvey& entry = campaign->surveys[survey_index];
  entry.length_m = arc.back();
  entry.crossings = static_cast<int>(spans.size());
  const std::vector<BlockRange> ranges =
      PlanBlockRanges(arc.back(), spans, options);
  const int first_block = static_cast<int>(campaign->blocks.size());
  const int pairs_per_exposure =
      static_cast<int>(survey.rig.stereo_pairs.size());
  for (size_t k = 0; k < ranges.size(); ++k) {
    CampaignBlock b;
    b.index = static_cast<int>(campaign->blocks.size());
    b.survey = survey_index;
    b.first_sample = k == 0 ? 0 : SampleAtOrBefore(arc, ranges[k].start_m);
    b.last_sample = k + 1 == ranges.size()
                        ? survey.trajectory.size() - 1
                        : SampleAtOrAfter(arc, ranges[k].end_m);
    b.start_m = arc[b.first_sample];
    b.end_m = arc[b.last_sample];
    b.start_time = survey.trajectory.samples()[b.first_sample].time;
    b.end_time = survey.trajectory.samples()[b.last_sample].time;
    // Exposures are sorted by time: the block's are a range.
    const std::vector<Exposure>& exposures = survey.exposures.exposures;
    auto e = std::lower_bound(
        exposures.begin(), exposures.end(), b.start_time,
        [](const Exposure& x, double t) { return x.time < t; });
    for (; e != exposures.end() && e->time <= b.end_time; ++e) {
      ++b.exposures;
      for (int image : e->image_of_camera) b.images += image >= 0;
    }
    b.crossings = static_cast<int>(
        CrossingsInside(spans, b.start_m, b.end_m, options).size());
    const double pairs = static_cast<double>(b.exposures) * pairs_per_exposure;
    b.estimated_cpu_s =
        options.cost.cpu_s_base + options.cost.cpu_s_per_pair * pairs;
    b.estimated_memory_mb =
        options.cost.memory_mb_base + options.cost.memory_mb_per_pair * pairs;
    campaign->blocks.push_back(b);
  }
  for (size_t k = 1; k < ranges.size(); ++k) {
    const CampaignBlock& before = campaign->blocks[first_block + k - 1];
    const CampaignBlock& after = campaign->blocks[first_block + k];
    CampaignOverlap o;
    o.survey = survey_index;
    o.before = before.index;
    o.after = after.index;
    o.start_time = after.start_time;
    o.end_time = before.end_time;
    o.start_m = after.start_m;
    o.end_m = before.end_m;
    o.crossings = CrossingsInside(spans, o.start_m, o.end_m, options);
    campaign->overlaps.push_back(o);
  }
}

Campaign PlanCampaign(const std::vector<std::string>& survey_folders,
                      const std::string& campaign_folder,
                      const PlanOptions& options,
                      const RunOptions& run_options) {
  std::string problem = options.Check();
  if (!problem.empty()) throw UsageError("plan: " + problem);
  problem = run_options.Check();
  if (!problem.empty()) throw UsageError("plan: " + problem);
  if (survey_folders.empty()) throw UsageError("plan: no survey");
  const fs::path folder = fs::absolute(campaign_folder).lexically_normal();
  if (fs::exists(folder / kCampaignFile)) {
    throw UsageError("plan: " + folder.string() +
                     " already holds a campaign (plan into a new folder)");
  }
  Campaign campaign;
  campaign.folder = folder.string();
  campaign.name = folder.filename().string();
  campaign.options = options;
  if (campaign.options.results_folder.empty()) {
    campaign.options.results_folder = (folder / "results").string();
  }
  campaign.options.results_folder =
      fs::absolute(campaign.options.results_folder).lexically_normal();
  std::set<std::string> names;
  for (const std::string& survey_folder : survey_folders) {
    const Survey survey = LoadSurvey(survey_folder);
    if (!survey.manifest.crs_grid_dirs.empty()) {
      throw InputError(survey.PathOf("survey.yaml"), 0,
                       "crs_grid_dirs: a campaign's blocks cannot carry "
                       "grid folders yet; give PROJ_DATA instead");
    }
    CampaignSurvey entry;
    entry.folder = fs::absolute(survey_folder).lexically_normal().string();
    entry.name = UniqueName(survey.manifest.name.empty()
                                ? fs::path(entry.folder).filename().string()
                                : survey.manifest.name,
                            &names);
    entry.origin = survey.frame.origin();
    entry.samples = survey.trajectory.size();
    entry.images = static_cast<int>(survey.exposures.images.size());
    campaign.surveys.push_back(entry);
    PlanSurveyBlocks(survey, static_cast<int>(campaign.surveys.size()) - 1,
                     campaign.options, &campaign);
    LOG(INFO) << "plan: " << campaign.surveys.back().name << ": "
              << campaign.surveys.back().length_m << " m, "
              << campaign.surveys.back().crossings << " crossings";
  }
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) {
    throw UsageError("plan: cannot create " + folder.string() + ": " +
                     error.message());
  }
  WriteFileAtomically((folder / kCampaignOptionsFile).string(),
                      [&run_options](std::ostream& out) {
                        out << RunOptionsToJson(run_options).dump(2) << "\n";
                      });
  WriteJobFiles(campaign);
  // Last: a folder with campaign.json is a whole campaign.
  WriteCampaign(campaign);
  return campaign;
}

RunOptions CampaignRunOptions(const std::string& campaign_folder) {
  return ReadRunOptions(
      (fs::path(campaign_folder) / kCampaignOptionsFile).string());
}

}  // namespace zebrageo
