// The road-line stage (issue 9): reconstructed_lines.csv from the stereo
// pairs, on the road plane the zebra stage estimated.
#include <glog/logging.h>

#include <filesystem>
#include <string>
#include <vector>

#include "reconstruction/road_lines.h"
#include "tools/exit_codes.h"
#include "tools/stages.h"

namespace zebrageo {

std::vector<std::string> RunRoadLinesStage(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads,
    const std::string& results_folder,
    const std::function<void(int, int)>& progress) {
  const std::string error = options.Check();
  if (!error.empty()) throw StageFailedError(error);
  std::filesystem::create_directories(results_folder);
  std::vector<ReconstructedLinePoint> points;
  const RoadLineSummary summary = ExtractSurveyLines(
      survey, road_plane, options, threads, &points, progress);
  std::vector<std::string> warnings;
  if (summary.lines == 0) warnings.push_back("no road line was reconstructed");
  WriteReconstructedLines(
      points, {"zebrageo reconstruct --lines: " + summary.BriefReport()},
      (std::filesystem::path(results_folder) / kReconstructedLinesFile)
          .string());
  LOG(INFO) << "road lines: " << summary.BriefReport();
  return warnings;
}

}  // namespace zebrageo
