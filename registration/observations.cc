#include "registration/observations.h"

#include <algorithm>
#include <map>
#include <utility>

#include "survey/input_error.h"

namespace zebrageo {
namespace {

// The trajectory's claimed horizontal sd at `time` (the larger of the two
// bracketing samples, the larger of east and north).
double ClaimedHorizontalSd(const Trajectory& trajectory, double time) {
  const int i = trajectory.FindSegment(time);
  if (i < 0) return 0.0;
  double sd = 0.0;
  for (int k = i; k <= i + 1; ++k) {
    const TrajectorySample& s = trajectory.samples()[k];
    sd = std::max({sd, s.sd_enu_m.x(), s.sd_enu_m.y()});
  }
  return sd;
}

}  // namespace

std::vector<CrossingObservation> BuildObservations(
    const Survey& survey, const std::vector<ReconstructedVertex>& vertices,
    const std::string& display_name, int* incomplete_bands) {
  std::map<int64_t, double> time_of_exposure;
  for (const Exposure& exposure : survey.exposures.exposures) {
    time_of_exposure[exposure.exposure_id] = exposure.time;
  }
  // (exposure, group) -> band_id -> vertices, in file order.
  std::map<std::pair<int64_t, int64_t>,
           std::map<int64_t, std::vector<const ReconstructedVertex*>>>
      groups;
  std::vector<std::pair<int64_t, int64_t>> order;
  for (const ReconstructedVertex& v : vertices) {
    if (!time_of_exposure.count(v.exposure_id)) {
      throw InputError(display_name, 0,
                       "band_id " + std::to_string(v.band_id) +
                           ": exposure_id " + std::to_string(v.exposure_id) +
                           " is not in " + survey.manifest.exposures);
    }
    if (v.pair < 0 ||
        v.pair >= static_cast<int>(survey.rig.stereo_pairs.size())) {
      throw InputError(display_name, 0,
                       "band_id " + std::to_string(v.band_id) + ": pair " +
                           std::to_string(v.pair) +
                           " is not a stereo pair of " + survey.manifest.rig);
    }
    const auto key = std::make_pair(v.exposure_id, v.group_id);
    if (!groups.count(key)) order.push_back(key);
    groups[key][v.band_id].push_back(&v);
  }
  int incomplete = 0;
  std::vector<CrossingObservation> observations;
  for (const auto& key : order) {
    CrossingObservation obs;
    obs.exposure_id = key.first;
    obs.group_id = key.second;
    obs.time_s = time_of_exposure[key.first];
    // Exposures were checked to lie inside the trajectory by LoadSurvey.
    if (!survey.trajectory.InterpolatePose(obs.time_s, &obs.pose)) {
      throw InputError(display_name, 0,
                       "exposure " + std::to_string(key.first) +
                           " is outside the trajectory");
    }
    obs.sd_horizontal_m = ClaimedHorizontalSd(survey.trajectory, obs.time_s);
    for (const auto& [band_id, list] : groups[key]) {
      if (list.size() != 4) {
        ++incomplete;
        continue;
      }
      std::vector<const ReconstructedVertex*> sorted = list;
      std::sort(sorted.begin(), sorted.end(),
                [](const ReconstructedVertex* a, const ReconstructedVertex* b) {
                  return a->vertex < b->vertex;
                });
      ObservedBand band;
      band.band_id = band_id;
      band.pair = sorted[0]->pair;
      double score = 1.0;
      for (int k = 0; k < 4; ++k) {
        band.vertex[k] = sorted[k]->vertex;
        band.p_body[k] = sorted[k]->p_body;
        score = std::min(score, sorted[k]->score);
      }
      band.score = score;
      obs.bands.push_back(band);
    }
    observations.push_back(std::move(obs));
  }
  if (incomplete_bands != nullptr) *incomplete_bands = incomplete;
  return observations;
}

std::vector<ExposurePose> ExposurePoses(const Survey& survey) {
  std::vector<ExposurePose> poses;
  for (const Exposure& exposure : survey.exposures.exposures) {
    ExposurePose pose;
    pose.exposure_id = exposure.exposure_id;
    pose.time_s = exposure.time;
    if (survey.trajectory.InterpolatePose(exposure.time, &pose.pose)) {
      poses.push_back(pose);
    }
  }
  return poses;
}

}  // namespace zebrageo
