#include "campaign/campaign.h"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "survey/atomic_file.h"
#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

using json = nlohmann::json;

json CostJson(const BlockCostModel& c) {
  return {{"cpu_s_per_pair", c.cpu_s_per_pair},
          {"cpu_s_base", c.cpu_s_base},
          {"memory_mb_per_pair", c.memory_mb_per_pair},
          {"memory_mb_base", c.memory_mb_base},
          {"safety", c.safety}};
}

json OptionsJson(const PlanOptions& o) {
  return {{"block_length_m", o.block_length_m},
          {"overlap_m", o.overlap_m},
          {"min_overlap_crossings", o.min_overlap_crossings},
          {"max_overlap_m", o.max_overlap_m},
          {"boundary_search_share", o.boundary_search_share},
          {"crossing_view_m", o.crossing_view_m},
          {"crossing_margin_m", o.crossing_margin_m},
          {"crossing_max_offset_m", o.crossing_max_offset_m},
          {"cost", CostJson(o.cost)},
          {"zebrageo_path", o.zebrageo_path},
          {"cpus_per_task", o.cpus_per_task},
          {"results_folder", o.results_folder},
          {"kubernetes_image", o.kubernetes_image},
          {"kubernetes_claim", o.kubernetes_claim},
          {"kubernetes_parallelism", o.kubernetes_parallelism}};
}

template <typename T>
void Get(const json& j, const char* key, T* value) {
  *value = j.at(key).get<T>();
}

PlanOptions OptionsFrom(const json& j) {
  PlanOptions o;
  Get(j, "block_length_m", &o.block_length_m);
  Get(j, "overlap_m", &o.overlap_m);
  Get(j, "min_overlap_crossings", &o.min_overlap_crossings);
  Get(j, "max_overlap_m", &o.max_overlap_m);
  Get(j, "boundary_search_share", &o.boundary_search_share);
  Get(j, "crossing_view_m", &o.crossing_view_m);
  Get(j, "crossing_margin_m", &o.crossing_margin_m);
  Get(j, "crossing_max_offset_m", &o.crossing_max_offset_m);
  const json& c = j.at("cost");
  Get(c, "cpu_s_per_pair", &o.cost.cpu_s_per_pair);
  Get(c, "cpu_s_base", &o.cost.cpu_s_base);
  Get(c, "memory_mb_per_pair", &o.cost.memory_mb_per_pair);
  Get(c, "memory_mb_base", &o.cost.memory_mb_base);
  Get(c, "safety", &o.cost.safety);
  Get(j, "zebrageo_path", &o.zebrageo_path);
  Get(j, "cpus_per_task", &o.cpus_per_task);
  Get(j, "results_folder", &o.results_folder);
  Get(j, "kubernetes_image", &o.kubernetes_image);
  Get(j, "kubernetes_claim", &o.kubernetes_claim);
  Get(j, "kubernetes_parallelism", &o.kubernetes_parallelism);
  return o;
}

json GeodeticJson(const Geodetic& g) { return {g.lat_deg, g.lon_deg, g.h_m}; }

}  // namespace

std::string BlockCostModel::Check() const {
  OptionCheck check;
  OPTION_GE(check, cpu_s_per_pair, 0.0);
  OPTION_GE(check, cpu_s_base, 0.0);
  OPTION_GE(check, memory_mb_per_pair, 0.0);
  OPTION_GT(check, memory_mb_base, 0.0);
  OPTION_GE(check, safety, 1.0);
  return check.problem();
}

std::string PlanOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, block_length_m, 0.0);
  OPTION_GT(check, overlap_m, 0.0);
  OPTION_LT(check, overlap_m, block_length_m);
  OPTION_GE(check, min_overlap_crossings, 0);
  OPTION_GE(check, max_overlap_m, overlap_m);
  OPTION_IN(check, boundary_search_share, "[", 0.0, 0.5, ")");
  OPTION_GE(check, crossing_view_m, 0.0);
  OPTION_GE(check, crossing_margin_m, 0.0);
  OPTION_GT(check, crossing_max_offset_m, 0.0);
  OPTION_NESTED(check, cost);
  OPTION_GE(check, cpus_per_task, 1);
  OPTION_GE(check, kubernetes_parallelism, 1);
  return check.problem();
}

std::string BlockFolder(const std::string& campaign_folder, int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "block-%04d", index);
  return (std::filesystem::path(campaign_folder) / "blocks" / name).string();
}

void WriteCampaign(const Campaign& campaign) {
  json j;
  j["format"] = "zebrageo-campaign";
  j["version"] = 1;
  j["name"] = campaign.name;
  j["options"] = OptionsJson(campaign.options);
  j["surveys"] = json::array();
  for (const CampaignSurvey& s : campaign.surveys) {
    j["surveys"].push_back({{"name", s.name},
                            {"folder", s.folder},
                            {"origin", GeodeticJson(s.origin)},
                            {"samples", s.samples},
                            {"images", s.images},
                            {"length_m", s.length_m},
                            {"crossings", s.crossings}});
  }
  j["blocks"] = json::array();
  for (const CampaignBlock& b : campaign.blocks) {
    j["blocks"].push_back({{"index", b.index},
                           {"survey", b.survey},
                           {"first_sample", b.first_sample},
                           {"last_sample", b.last_sample},
                           {"start_time", b.start_time},
                           {"end_time", b.end_time},
                           {"start_m", b.start_m},
                           {"end_m", b.end_m},
                           {"exposures", b.exposures},
                           {"images", b.images},
                           {"crossings", b.crossings},
                           {"estimated_cpu_s", b.estimated_cpu_s},
                           {"estimated_memory_mb", b.estimated_memory_mb}});
  }
  j["overlaps"] = json::array();
  for (const CampaignOverlap& o : campaign.overlaps) {
    j["overlaps"].push_back({{"survey", o.survey},
                             {"before", o.before},
                             {"after", o.after},
                             {"start_time", o.start_time},
                             {"end_time", o.end_time},
                             {"start_m", o.start_m},
                             {"end_m", o.end_m},
                             {"crossings", o.crossings}});
  }
  const std::string path =
      (std::filesystem::path(campaign.folder) / kCampaignFile).string();
  WriteFileAtomically(path, [&j](std::ostream& out) {
    out.precision(17);
    out << j.dump(2) << "\n";
  });
}

Campaign ReadCampaign(const std::string& campaign_folder) {
  const std::string path =
      (std::filesystem::path(campaign_folder) / kCampaignFile).string();
  const json j = ReadJsonFile(path, path);
  Campaign c;
  c.folder = std::filesystem::absolute(campaign_folder).lexically_normal();
  try {
    if (j.at("format").get<std::string>() != "zebrageo-campaign") {
      throw InputError(path, 0, "not a zebrageo campaign manifest");
    }
    Get(j, "name", &c.name);
    c.options = OptionsFrom(j.at("options"));
    for (const json& s : j.at("surveys")) {
      CampaignSurvey survey;
      Get(s, "name", &survey.name);
      Get(s, "folder", &survey.folder);
      const json& o = s.at("origin");
      survey.origin = Geodetic{o.at(0).get<double>(), o.at(1).get<double>(),
                               o.at(2).get<double>()};
      Get(s, "samples", &survey.samples);
      Get(s, "images", &survey.images);
      Get(s, "length_m", &survey.length_m);
      Get(s, "crossings", &survey.crossings);
      c.surveys.push_back(survey);
    }
    for (const json& b : j.at("blocks")) {
      CampaignBlock block;
      Get(b, "index", &block.index);
      Get(b, "survey", &block.survey);
      Get(b, "first_sample", &block.first_sample);
      Get(b, "last_sample", &block.last_sample);
      Get(b, "start_time", &block.start_time);
      Get(b, "end_time", &block.end_time);
      Get(b, "start_m", &block.start_m);
      Get(b, "end_m", &block.end_m);
      Get(b, "exposures", &block.exposures);
      Get(b, "images", &block.images);
      Get(b, "crossings", &block.crossings);
      Get(b, "estimated_cpu_s", &block.estimated_cpu_s);
      Get(b, "estimated_memory_mb", &block.estimated_memory_mb);
      c.blocks.push_back(block);
    }
    for (const json& o : j.at("overlaps")) {
      CampaignOverlap overlap;
      Get(o, "survey", &overlap.survey);
      Get(o, "before", &overlap.before);
      Get(o, "after", &overlap.after);
      Get(o, "start_time", &overlap.start_time);
      Get(o, "end_time", &overlap.end_time);
      Get(o, "start_m", &overlap.start_m);
      Get(o, "end_m", &overlap.end_m);
      Get(o, "crossings", &overlap.crossings);
      c.overlaps.push_back(overlap);
    }
  } catch (const json::exception& e) {
    throw InputError(path, 0,
                     std::string("bad campaign manifest: ") + e.what());
  }
  const int n_surveys = static_cast<int>(c.surveys.size());
  const int n_blocks = static_cast<int>(c.blocks.size());
  for (int i = 0; i < n_blocks; ++i) {
    const CampaignBlock& b = c.blocks[i];
    if (b.index != i || b.survey < 0 || b.survey >= n_surveys ||
        b.first_sample < 0 || b.last_sample <= b.first_sample ||
        b.last_sample >= c.surveys[b.survey].samples) {
      throw InputError(path, 0,
                       "block " + std::to_string(i) +
                           ": index, survey or sample range out of range");
    }
  }
  for (const CampaignOverlap& o : c.overlaps) {
    if (o.before < 0 || o.before >= n_blocks || o.after < 0 ||
        o.after >= n_blocks || o.end_time <= o.start_time) {
      throw InputError(path, 0, "an overlap names a block out of range");
    }
  }
  if (c.blocks.empty()) throw InputError(path, 0, "no blocks");
  return c;
}

}  // namespace zebrageo
