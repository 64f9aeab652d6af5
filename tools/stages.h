// Each processing stage as one call on a survey and a results folder, shared
// by the stage commands and `zebrageo run`. Each returns its warnings and
// throws InputError (bad input) or StageFailedError (no usable result).
#ifndef ZEBRAGEO_TOOLS_STAGES_H_
#define ZEBRAGEO_TOOLS_STAGES_H_

#include <functional>
#include <string>
#include <vector>

#include "adjustment/trajectory_adjuster.h"
#include "reconstruction/reconstruction.h"
#include "reconstruction/road_lines.h"
#include "survey/survey.h"

namespace zebrageo {

// Writes reconstructed_bands.csv. `road_plane`, if given, receives the
// road plane in the body frame as the stage estimated it.
std::vector<std::string> RunReconstructStage(
    const Survey& survey, const ReconstructionOptions& options,
    const std::string& results_folder,
    const std::function<void(int, int)>& progress,
    RoadPlane* road_plane = nullptr);

// Writes reconstructed_lines.csv (road lines, issue 9) using the road plane
// of the zebra stage.
std::vector<std::string> RunRoadLinesStage(
    const Survey& survey, const RoadPlane& road_plane,
    const RoadLineOptions& options, int threads,
    const std::string& results_folder,
    const std::function<void(int, int)>& progress);

// Writes trajectory_corrected.csv, poses.csv, gcp_residuals.csv,
// bands.geojson, adjustment.json and colmap/. Draws its own progress bars
// (tie points, then the solve).
std::vector<std::string> RunAdjustStage(const std::string& survey_folder,
                                        const std::string& results_folder,
                                        const AdjustmentOptions& options,
                                        bool tie_points);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TOOLS_STAGES_H_
