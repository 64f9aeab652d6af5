#include "pipeline/reconstruct_stage.h"

#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/exit_codes.h"
#include "pipeline/stereo_order.h"
#include "reconstruction/reconstruction.h"
#include "reconstruction/road_lines.h"
#include "survey/input_error.h"
#include "survey/results.h"
#include "survey/results_lines.h"
#include "survey/results_survey.h"

namespace zebrageo {

namespace {

// Images that exist but cannot be decoded are only found here (loading
// checks existence): the same share as for missing images makes the survey
// invalid rather than quietly thin.
void ThrowIfTooManyUnreadable(const Survey& survey,
                              const ReconstructionSummary& summary) {
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

// The zebra bands; *road_plane: the road plane in the body frame as the
// stage estimated it.
std::vector<std::string> ReconstructBands(
    const Survey& survey, const ReconstructionOptions& options,
    StageResults* results, const std::function<void(int, int)>& progress,
    const CancellationToken& cancel, RoadPlane* road_plane) {
  std::vector<ReconstructedVertex> vertices;
  const ReconstructionSummary summary =
      ReconstructSurvey(survey, options, &vertices, progress, cancel);
  ThrowIfTooManyUnreadable(survey, summary);
  if (!summary.IsUsable()) throw StageFailedError(summary.message);
  *road_plane = summary.final_road_plane;

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
  WriteReconstructedBands(vertices,
                          WithSurveyIdentity(survey.exposures, comments),
                          results->PathOf(kReconstructedBandsFile));
  results->SetReconstruction(std::move(vertices), std::move(skipped));
  LOG(INFO) << "reconstruct: " << summary.BriefReport() << " in "
            << summary.wall_time_s << " s";
  LOG(INFO) << "reconstruct: " << comments[1];
  std::vector<std::string> warnings = summary.warnings;
  if (summary.bands == 0) {
    // Nothing at all: what the images say of the cause.
    const std::optional<Diagnosis> order =
        DiagnoseStereoOrder(survey, options, StereoOrderOptions());
    if (order) {
      LOG(WARNING) << order->message;
      warnings.push_back(order->message);
    }
  }
  return warnings;
}

// The road lines on `road_plane`.
std::vector<std::string> ReconstructRoadLines(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads, StageResults* results,
    const std::function<void(int, int)>& progress,
    const CancellationToken& cancel) {
  std::vector<ReconstructedLinePoint> points;
  const RoadLineSummary summary = ExtractSurveyLines(
      survey, road_plane, options, threads, &points, progress, cancel);
  std::vector<std::string> warnings;
  if (summary.lines == 0) warnings.push_back("no road line was reconstructed");
  WriteReconstructedLines(
      points,
      WithSurveyIdentity(survey.exposures, {"zebrageo reconstruct --lines: " +
                                            summary.BriefReport()}),
      results->PathOf(kReconstructedLinesFile));
  results->SetLinePoints(std::move(points));
  LOG(INFO) << "road lines: " << summary.BriefReport();
  return warnings;
}

}  // namespace

std::vector<std::string> RunReconstructStage(
    const Survey& survey, StageResults* results, const RunOptions& options,
    const std::function<void(int, int)>& progress,
    const ProgressListener& steps, const CancellationToken& cancel) {
  std::filesystem::create_directories(results->folder());
  RoadPlane road_plane;
  std::vector<std::string> warnings = ReconstructBands(
      survey, options.reconstruction, results, progress, cancel, &road_plane);
  if (!options.lines) return warnings;
  cancel.ThrowIfCancelled();
  StepProgress step(steps, "road lines");
  for (const std::string& w : ReconstructRoadLines(
           survey, road_plane, options.road_lines, options.threads, results,
           step.Callback(), cancel)) {
    warnings.push_back(w);
  }
  step.Finish();
  return warnings;
}

}  // namespace zebrageo
