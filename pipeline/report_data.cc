#include "pipeline/report_data.h"

#include <cmath>
#include <filesystem>
#include <set>

#include "survey/input_error.h"
#include "survey/json_file.h"
#include "survey/math_util.h"
#include "survey/output_crs.h"
#include "survey/results_adjustment.h"
#include "survey/results_lines.h"

namespace zebrageo {
namespace report_internal {
namespace {

using nlohmann::json;

bool Exists(const std::string& path) {
  return std::filesystem::is_regular_file(path);
}

}  // namespace

ReportData Collect(const ReportInputs& inputs) {
  const Survey& survey = *inputs.survey;
  const std::string folder = inputs.results_folder + "/";
  ReportData data;
  const Trajectory& trajectory = survey.trajectory;
  for (int i = 0; i < trajectory.size(); ++i) {
    data.time_s.push_back(trajectory.samples()[i].time);
    data.input_enu.push_back(trajectory.poses()[i].p_enu);
    if (i > 0) {
      data.length_m +=
          (trajectory.poses()[i].p_enu - trajectory.poses()[i - 1].p_enu)
              .norm();
    }
  }
  if (Exists(folder + kTrajectoryCorrectedFile)) {
    const std::vector<TrajectorySample> corrected = ReadTrajectorySamples(
        folder + kTrajectoryCorrectedFile, kTrajectoryCorrectedFile);
    if (static_cast<int>(corrected.size()) != trajectory.size()) {
      throw InputError(kTrajectoryCorrectedFile, 0,
                       "has " + std::to_string(corrected.size()) +
                           " samples, the input trajectory " +
                           std::to_string(trajectory.size()));
    }
    data.has_corrected = true;
    for (int i = 0; i < trajectory.size(); ++i) {
      const Eigen::Vector3d p =
          survey.frame.EnuFromGeodetic(corrected[i].position);
      data.correction_enu.push_back(p - data.input_enu[i]);
      data.heading_correction_deg.push_back(
          RadToDeg(std::remainder(corrected[i].attitude.heading -
                                      trajectory.samples()[i].attitude.heading,
                                  2.0 * kPi)));
    }
  } else {
    data.missing_files.push_back(kTrajectoryCorrectedFile);
  }

  // Database geometry for placing residuals and crossings.
  std::map<std::pair<std::string, int>, const RoadmarkBand*> db_bands;
  std::map<std::string, std::pair<Eigen::Vector3d, int>> sums;
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    db_bands[{band.crossing_id, band.band}] = &band;
    for (const Geodetic& corner : band.corners) {
      // try_emplace with an explicit zero: a value-initialised
      // Eigen::Vector3d is not zeroed (the centres came out of garbage).
      auto& sum = sums.try_emplace(band.crossing_id, Eigen::Vector3d::Zero(), 0)
                      .first->second;
      sum.first += survey.frame.EnuFromGeodetic(corner);
      sum.second += 1;
    }
  }
  for (const auto& [id, sum] : sums) {
    data.crossing_centres_enu[id] = sum.first / sum.second;
  }

  if (Exists(folder + kGcpResidualsFile)) {
    data.residuals =
        ReadGcpResiduals(folder + kGcpResidualsFile, kGcpResidualsFile);
    for (const GcpResidual& r : data.residuals) {
      const auto it = db_bands.find({r.crossing_id, r.band});
      data.residual_positions_enu.push_back(
          it == db_bands.end()
              ? Eigen::Vector3d::Constant(NAN)
              : survey.frame.EnuFromGeodetic(it->second->corners[r.vertex]));
    }
  } else {
    data.missing_files.push_back(kGcpResidualsFile);
  }
  if (Exists(folder + kCrossingDecisionsFile)) {
    data.decisions = ReadCrossingDecisions(folder + kCrossingDecisionsFile,
                                           kCrossingDecisionsFile);
  } else {
    data.missing_files.push_back(kCrossingDecisionsFile);
  }
  std::vector<VertexMatch> matches;
  if (Exists(folder + kMatchesFile)) {
    matches = ReadMatches(folder + kMatchesFile, kMatchesFile);
    data.matched_vertices = static_cast<int>(matches.size());
  }
  std::vector<ReconstructedVertex> vertices;
  if (Exists(folder + kReconstructedBandsFile)) {
    vertices = ReadReconstructedBands(folder + kReconstructedBandsFile,
                                      kReconstructedBandsFile);
    std::set<int64_t> bands;
    for (const ReconstructedVertex& v : vertices) bands.insert(v.band_id);
    data.reconstructed_bands = static_cast<int>(bands.size());
  } else {
    data.missing_files.push_back(kReconstructedBandsFile);
  }
  if (Exists(folder + kPosesFile) && !matches.empty()) {
    data.image_residuals =
        ReprojectControl(survey, data.residuals, matches, vertices,
                         ReadCameraPoses(folder + kPosesFile, kPosesFile));
  }
  if (survey.manifest.output_crs.is_set()) {
    data.output_crs = survey.manifest.output_crs.definition;
    try {
      data.output_crs_description = OutputCrs::Of(survey)->Description();
    } catch (const std::exception& error) {
      // The stages reported it; the report names the CRS as written.
      data.output_crs_description = "";
    }
  }
  if (Exists(folder + "match_evidence.json")) {
    data.match_evidence =
        ReadJsonFile(folder + "match_evidence.json", "match_evidence.json");
  }
  if (Exists(folder + kAdjustmentJsonFile)) {
    data.adjustment = AdjustmentJson(ReadAdjustmentRecord(
        folder + kAdjustmentJsonFile, kAdjustmentJsonFile));
  }
  if (Exists(folder + "reconstruction.json")) {
    data.reconstruction =
        ReadJsonFile(folder + "reconstruction.json", "reconstruction.json");
  }
  // Written by the adjustment only when road lines were used: not missing
  // otherwise.
  if (Exists(folder + kLineControlFile)) {
    data.line_control = LineControlJson(
        ReadLineControl(folder + kLineControlFile, kLineControlFile));
  }
  return data;
}

}  // namespace report_internal
}  // namespace zebrageo
