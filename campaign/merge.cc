#include "campaign/merge.h"

#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "campaign/campaign.h"
#include "campaign/merge_report.h"
#include "pipeline/exit_codes.h"
#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/results.h"
#include "survey/survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

double Smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// One block's results, read back.
struct BlockOutputs {
  const CampaignBlock* block = nullptr;
  const double* before_end = nullptr;   // its overlap with the block before
  const double* after_start = nullptr;  // with the block after
  Trajectory corrected;
  std::map<std::pair<int64_t, std::string>, CameraPose> poses;
  std::vector<AdjustedBand> bands;
  std::vector<GcpResidual> residuals;
  json report;
  json done;
  double Weight(double t) const {
    return BlockWeight(t, block->start_time, block->end_time, before_end,
                       after_start);
  }
};

Pose Blend(const Pose& a, double wa, const Pose& b, double wb) {
  return InterpolatePoses(a, b, wb / (wa + wb));
}

BlockOutputs ReadBlock(const Campaign& campaign, const CampaignBlock& block,
                       const Survey& survey) {
  const fs::path folder = BlockFolder(campaign.folder, block.index);
  if (!fs::exists(folder / kBlockDoneFile)) {
    throw UsageError("merge: block " + std::to_string(block.index) +
                     " is not done (no " + (folder / kBlockDoneFile).string() +
                     "): run `zebrageo run-block " + campaign.folder +
                     " --index " + std::to_string(block.index) + "` first");
  }
  const fs::path results = folder / "results";
  BlockOutputs out;
  out.block = &block;
  out.done = ReadJsonFile((folder / kBlockDoneFile).string(),
                          (folder / kBlockDoneFile).string());
  const std::string trajectory = (results / kTrajectoryCorrectedFile).string();
  std::vector<TrajectorySample> samples =
      ReadTrajectorySamples(trajectory, trajectory);
  const int n = block.last_sample - block.first_sample + 1;
  if (static_cast<int>(samples.size()) != n) {
    throw InputError(trajectory, 0,
                     std::to_string(samples.size()) +
                         " samples, the block has " + std::to_string(n));
  }
  for (int i = 0; i < n; ++i) {
    const double t = survey.trajectory.samples()[block.first_sample + i].time;
    if (std::abs(samples[i].time - t) > 1e-6) {
      throw InputError(trajectory, samples[i].line,
                       "time differs from the survey's sample");
    }
    samples[i].time = t;
  }
  out.corrected = Trajectory(std::move(samples), survey.frame);
  const std::string poses = (results / kPosesFile).string();
  for (const CameraPose& p : ReadCameraPoses(poses, poses)) {
    out.poses[{p.exposure_id, p.camera}] = p;
  }
  const std::string bands = (results / kBandsGeoJsonFile).string();
  if (fs::exists(bands)) out.bands = ReadAdjustedBands(bands, bands);
  const std::string residuals = (results / kGcpResidualsFile).string();
  if (fs::exists(residuals)) {
    out.residuals = ReadGcpResiduals(residuals, residuals);
  }
  const std::string report = (results / kReportJsonFile).string();
  if (fs::exists(report)) out.report = ReadJsonFile(report, report);
  return out;
}

// The trajectory: each sample blended from the blocks holding it.
std::vector<TrajectorySample> MergedTrajectory(
    const Survey& survey, const std::vector<BlockOutputs>& blocks) {
  const std::vector<TrajectorySample>& input = survey.trajectory.samples();
  std::vector<double> times;
  times.reserve(input.size());
  for (const TrajectorySample& s : input) times.push_back(s.time);
  std::vector<BlockPoses> views;
  for (const BlockOutputs& b : blocks) {
    views.push_back(
        {b.block, b.before_end, b.after_start, &b.corrected.poses()});
  }
  std::vector<int> dominant;
  const std::vector<Pose> poses = BlendBlockPoses(times, views, &dominant);
  std::vector<TrajectorySample> merged;
  merged.reserve(input.size());
  for (size_t i = 0; i < input.size(); ++i) {
    const BlockOutputs& b = blocks[dominant[i]];
    const TrajectorySample& own =
        b.corrected.samples()[static_cast<int>(i) - b.block->first_sample];
    merged.push_back(SampleFromPose(times[i], poses[i], survey.frame,
                                    own.sd_enu_m, own.sd_attitude_rad));
  }
  return merged;
}

// poses.csv: one row per image any block has, blended likewise.
std::vector<CameraPose> MergedPoses(const Survey& survey,
                                    const std::vector<BlockOutputs>& blocks) {
  // A block holds the images within its times only, and the blocks follow
  // each other in time: those holding an image are found by binary search
  // (a long survey's thousands of blocks are not all asked per image).
  std::vector<double> starts;
  for (const BlockOutputs& b : blocks) starts.push_back(b.block->start_time);
  std::vector<CameraPose> merged;
  for (const ExposureImage& image : survey.exposures.images) {
    const std::string camera =
        survey.rig.cameras.at(image.camera).camera.name();
    const int last =
        static_cast<int>(
            std::upper_bound(starts.begin(), starts.end(), image.time) -
            starts.begin()) -
        1;
    int first = last + 1;
    while (first > 0 && blocks[first - 1].block->end_time >= image.time) {
      --first;
    }
    CameraPose result;
    Pose pose;
    double weight = 0.0;
    for (int k = first; k <= last; ++k) {
      const BlockOutputs& b = blocks[k];
      const auto it = b.poses.find({image.exposure_id, camera});
      if (it == b.poses.end()) continue;
      const double w = std::max(b.Weight(image.time), 1e-12);
      Pose p;
      p.p_enu = it->second.p_enu;
      p.q_enu_body = it->second.q_enu_cam;
      pose = weight == 0.0 ? p : Blend(pose, weight, p, w);
      weight += w;
      result = it->second;
    }
    if (weight == 0.0) continue;  // unreadable in its block: left out
    result.p_enu = pose.p_enu;
    result.q_enu_cam = pose.q_enu_body;
    result.position = survey.frame.GeodeticFromEnu(pose.p_enu);
    merged.push_back(result);
  }
  return merged;
}

// Bands and residuals from the block that dominates where they were seen.
void MergedBandsAndResiduals(const std::vector<BlockOutputs>& blocks,
                             const Survey& survey,
                             std::vector<AdjustedBand>* bands,
                             std::vector<GcpResidual>* residuals) {
  std::map<int64_t, double> time_of;
  for (const Exposure& e : survey.exposures.exposures)
    time_of[e.exposure_id] = e.time;
  // crossing -> (best weight, block)
  std::map<std::string, std::pair<double, size_t>> owner;
  for (size_t k = 0; k < blocks.size(); ++k) {
    for (const AdjustedBand& band : blocks[k].bands) {
      const double w = blocks[k].Weight(time_of[band.exposure_id]);
      if (w >= 0.5) bands->push_back(band);
      if (!band.crossing_id) continue;
      auto [it, inserted] = owner.try_emplace(*band.crossing_id, w, k);
      if (!inserted && w > it->second.first) it->second = {w, k};
    }
  }
  for (size_t k = 0; k < blocks.size(); ++k) {
    for (const GcpResidual& r : blocks[k].residuals) {
      const auto it = owner.find(r.crossing_id);
      const size_t from = it == owner.end() ? 0 : it->second.second;
      if (from == k) residuals->push_back(r);
    }
  }
}

json MergeSurvey(const Campaign& campaign, int survey_index,
                 const fs::path& folder) {
  const CampaignSurvey& entry = campaign.surveys[survey_index];
  SurveyLoadOptions load;
  load.require_images = false;
  const Survey survey = LoadSurvey(entry.folder, load);
  std::vector<BlockOutputs> blocks;
  for (const CampaignBlock& block : campaign.blocks) {
    if (block.survey == survey_index) {
      blocks.push_back(ReadBlock(campaign, block, survey));
    }
  }
  for (size_t k = 0; k < campaign.overlaps.size(); ++k) {
    const CampaignOverlap& o = campaign.overlaps[k];
    for (BlockOutputs& b : blocks) {
      if (b.block->index == o.after)
        b.before_end = &campaign.overlaps[k].end_time;
      if (b.block->index == o.before) {
        b.after_start = &campaign.overlaps[k].start_time;
      }
    }
  }
  fs::create_directories(folder);
  const std::vector<TrajectorySample> trajectory =
      MergedTrajectory(survey, blocks);
  WriteTrajectorySamples(trajectory,
                         (folder / kTrajectoryCorrectedFile).string());
  WriteCameraPoses(MergedPoses(survey, blocks), (folder / kPosesFile).string());
  std::vector<AdjustedBand> bands;
  std::vector<GcpResidual> residuals;
  MergedBandsAndResiduals(blocks, survey, &bands, &residuals);
  WriteAdjustedBands(bands, (folder / kBandsGeoJsonFile).string());
  WriteGcpResiduals(residuals, (folder / kGcpResidualsFile).string());

  MergeReportInputs inputs;
  inputs.campaign = &campaign;
  inputs.survey_index = survey_index;
  inputs.survey = &survey;
  inputs.merged = Trajectory(trajectory, survey.frame);
  for (const BlockOutputs& b : blocks) {
    const BlockOutputs* view = &b;
    inputs.blocks.push_back({b.block, &b.corrected, &b.report, &b.done,
                             [view](double t) { return view->Weight(t); }});
  }
  const json report = SurveyMergeReport(inputs, residuals);
  WriteFileAtomically(
      (folder / kReportJsonFile).string(),
      [&report](std::ostream& out) { out << report.dump(2) << "\n"; });
  WriteFileAtomically(
      (folder / kReportHtmlFile).string(),
      [&report](std::ostream& out) { out << MergeReportHtml(report); });
  return report;
}

}  // namespace

double BlockWeight(double t, double start_time, double end_time,
                   const double* before_overlap_end,
                   const double* after_overlap_start) {
  if (t < start_time || t > end_time) return 0.0;
  double w = 1.0;
  if (before_overlap_end != nullptr && *before_overlap_end > start_time) {
    w *= Smoothstep((t - start_time) / (*before_overlap_end - start_time));
  }
  if (after_overlap_start != nullptr && end_time > *after_overlap_start) {
    w *= 1.0 - Smoothstep((t - *after_overlap_start) /
                          (end_time - *after_overlap_start));
  }
  return w;
}

std::vector<Pose> BlendBlockPoses(const std::vector<double>& times,
                                  const std::vector<BlockPoses>& blocks,
                                  std::vector<int>* dominant) {
  const int n = static_cast<int>(times.size());
  std::vector<Pose> poses(n);
  std::vector<double> weight(n, 0.0), best(n, -1.0);
  dominant->assign(n, -1);
  for (size_t k = 0; k < blocks.size(); ++k) {
    const BlockPoses& b = blocks[k];
    const int first = std::max(0, b.block->first_sample);
    const int last = std::min(n - 1, b.block->last_sample);
    for (int i = first; i <= last; ++i) {
      const Pose& pose = (*b.poses)[i - b.block->first_sample];
      // The ends of the survey belong to its first and last block whole.
      const double w =
          std::max(BlockWeight(times[i], b.block->start_time, b.block->end_time,
                               b.before_overlap_end, b.after_overlap_start),
                   1e-12);
      poses[i] = weight[i] == 0.0 ? pose : Blend(poses[i], weight[i], pose, w);
      weight[i] += w;
      if (w > best[i]) {
        best[i] = w;
        (*dominant)[i] = static_cast<int>(k);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    if ((*dominant)[i] < 0) {
      throw UsageError("merge: trajectory sample " + std::to_string(i) +
                       " is in no block (campaign.json damaged?)");
    }
  }
  return poses;
}

json MergeCampaign(const std::string& campaign_folder,
                   const std::string& results_folder) {
  const Campaign campaign = ReadCampaign(campaign_folder);
  const fs::path results = fs::absolute(results_folder).lexically_normal();
  if (fs::exists(results) && !fs::is_directory(results)) {
    throw UsageError("merge: " + results.string() + " is a file");
  }
  const fs::path partial =
      results.parent_path() / ("." + results.filename().string() + ".partial-" +
                               std::to_string(::getpid()));
  fs::remove_all(partial);
  json report;
  report["campaign"] = campaign.name;
  report["surveys"] = json::array();
  try {
    for (int s = 0; s < static_cast<int>(campaign.surveys.size()); ++s) {
      report["surveys"].push_back(
          MergeSurvey(campaign, s, partial / campaign.surveys[s].name));
      LOG(INFO) << "merge: " << campaign.surveys[s].name << " merged";
    }
    WriteFileAtomically(
        (partial / kCampaignReportFile).string(),
        [&report](std::ostream& out) { out << report.dump(2) << "\n"; });
  } catch (...) {
    fs::remove_all(partial);
    throw;
  }
  // The old results go only once the new ones are whole.
  fs::remove_all(results);
  fs::create_directories(results.parent_path());
  fs::rename(partial, results);
  return report;
}

}  // namespace zebrageo
