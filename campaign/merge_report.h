// The report of a merged survey (report.json, report.html in
// RESULTS/<survey>/): per-block figures, the seams at the block
// boundaries, uncontrolled stretches and database faults of the blocks.
#ifndef ZEBRAGEO_CAMPAIGN_MERGE_REPORT_H_
#define ZEBRAGEO_CAMPAIGN_MERGE_REPORT_H_

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "campaign/campaign.h"
#include "survey/results.h"
#include "survey/survey.h"

namespace zebrageo {

struct MergedBlockView {
  const CampaignBlock* block = nullptr;
  const Trajectory* corrected = nullptr;   // the block's samples
  const nlohmann::json* report = nullptr;  // its report.json
  const nlohmann::json* done = nullptr;    // its block.json
  std::function<double(double)> weight;    // its merge weight in time
};

struct MergeReportInputs {
  const Campaign* campaign = nullptr;
  int survey_index = 0;
  const Survey* survey = nullptr;
  Trajectory merged;
  std::vector<MergedBlockView> blocks;
};

// The seams: over each overlap, the two blocks' corrected trajectories
// compared sample by sample (largest and at the overlap's middle, where a
// hard cut would be), against the database's accuracy there.
nlohmann::json SeamFigures(const MergeReportInputs& inputs);

nlohmann::json SurveyMergeReport(const MergeReportInputs& inputs,
                                 const std::vector<GcpResidual>& residuals);
std::string MergeReportHtml(const nlohmann::json& report);

}  // namespace zebrageo

#endif  // ZEBRAGEO_CAMPAIGN_MERGE_REPORT_H_
