// The reconstruct stage: zebra bands (and road lines) of every stereo pair
// into the results folder.
#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/exit_codes.h"
#include "pipeline/stages.h"
#include "survey/input_error.h"
#include "survey/results.h"

namespace zebrageo {

void ThrowIfTooManyUnreadable(const Survey& survey,
                              const ReconstructionSummary& summary) {
  // Images that exist but cannot be decoded are only found here (loading
  // checks existence); the same share as for missing images makes the survey
  // invalid rather than quietly thin.
  const int total = static_cast<int>(survey.exposures.exposures.size());
  const double max_fraction = SurveyLoadOptions().max_missing_image_fraction;
  if (summary.exposures_skipped == 0 ||
      summary.exposures_skipped <= max_fraction * total) {
    return;
  }
  // The skipped exposures' warnings name the image and the problem.
  std::string first = "?";
  for (const std::string& warning : summary.warnings) {
    if (warning.find("skipped") != std::string::npos) {
      first = warning;
      break;
    }
  }
  std::ostringstream problem;
  problem << summary.exposures_skipped << " of " << total
          << " exposures have an unreadable image (more than "
          << max_fraction * 100 << "%); first: " << first;
  throw InputError(survey.manifest.exposures, 0, problem.str());
}

std::vector<std::string> RunReconstructStage(
    const Survey& survey, const ReconstructionOptions& options,
    StageResults* results, const std::function<void(int, int)>& progress,
    RoadPlane* road_plane) {
  std::filesystem::create_directories(results->folder());
  std::vector<ReconstructedVertex> vertices;
  const ReconstructionSummary summary =
      ReconstructSurvey(survey, options, &vertices, progress);
  ThrowIfTooManyUnreadable(survey, summary);
  if (!summary.IsUsable()) throw StageFailedError(summary.message);
  if (road_plane != nullptr) *road_plane = summary.final_road_plane;

  StepTimings mean = summary.timings;
  const double n = std::max(1, summary.pairs_processed);
  mean.read_images_s /= n;
  mean.rectify_s /= n;
  mean.edges_s /= n;
  mean.matching_s /= n;
  mean.road_plane_s /= n;
  mean.long_sides_s /= n;
  mean.bands_s /= n;
  mean.debug_images_s /= n;
  std::vector<std::string> comments = {
      "zebrageo reconstruct: " + summary.BriefReport(),
      "per stereo pair: " + mean.Report()};
  for (const std::string& warning : summary.warnings) {
    comments.push_back("warning: " + warning);
  }
  std::vector<SkippedExposure> skipped;
  for (const auto& [exposure_id, reason] : summary.skipped_exposures) {
    skipped.push_back({exposure_id, reason});
  }
  WriteSkippedExposures(skipped, results->PathOf(kSkippedExposuresFile));
  WriteReconstructedBands(vertices, comments,
                          results->PathOf(kReconstructedBandsFile));
  results->SetReconstruction(std::move(vertices), std::move(skipped));
  LOG(INFO) << "reconstruct: " << summary.BriefReport() << " in "
            << summary.wall_time_s << " s";
  LOG(INFO) << "reconstruct: " << comments[1];
  return summary.warnings;
}

std::vector<std::string> RunRoadLinesStage(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads, StageResults* results,
    const std::function<void(int, int)>& progress) {
  const std::string error = options.Check();
  if (!error.empty()) throw StageFailedError(error);
  std::filesystem::create_directories(results->folder());
  std::vector<ReconstructedLinePoint> points;
  const RoadLineSummary summary = ExtractSurveyLines(
      survey, road_plane, options, threads, &points, progress);
  std::vector<std::string> warnings;
  if (summary.lines == 0) warnings.push_back("no road line was reconstructed");
  WriteReconstructedLines(
      points, {"zebrageo reconstruct --lines: " + summary.BriefReport()},
      results->PathOf(kReconstructedLinesFile));
  results->SetLinePoints(std::move(points));
  LOG(INFO) << "road lines: " << summary.BriefReport();
  return warnings;
}

}  // namespace zebrageo
