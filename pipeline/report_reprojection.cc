// The report's per-camera reprojection residuals of the control and check
// points (report_data.h: ImageResidual), from the results folder's files:
// where the adjusted camera poses put each point's adjusted position in the
// image, against where the reconstruction measured it.
#include <map>
#include <tuple>

#include "pipeline/report_data.h"

namespace zebrageo {
namespace report_internal {

std::vector<ImageResidual> ReprojectControl(
    const Survey& survey, const std::vector<GcpResidual>& residuals,
    const std::vector<VertexMatch>& matches,
    const std::vector<ReconstructedVertex>& vertices,
    const std::vector<CameraPose>& poses) {
  // The adjusted position of each control and check point, ENU. Rejected
  // points (blunders) are out of the adjustment: not reprojected.
  std::map<std::tuple<std::string, int, int>, const RoadmarkBand*> bands;
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    for (int k = 0; k < 4; ++k) bands[{band.crossing_id, band.band, k}] = &band;
  }
  std::map<std::tuple<std::string, int, int>,
           std::pair<Eigen::Vector3d, GcpRole>>
      points;
  for (const GcpResidual& r : residuals) {
    if (r.status == GcpStatus::kRejected) continue;
    const auto it = bands.find({r.crossing_id, r.band, r.vertex});
    if (it == bands.end()) continue;
    const Eigen::Vector3d database_enu =
        survey.frame.EnuFromGeodetic(it->second->corners[r.vertex]);
    points[{r.crossing_id, r.band, r.vertex}] = {database_enu + r.d_enu,
                                                 r.role};
  }
  std::map<std::tuple<int64_t, int64_t, int>, const ReconstructedVertex*>
      measured;
  for (const ReconstructedVertex& v : vertices) {
    measured[{v.exposure_id, v.band_id, v.vertex}] = &v;
  }
  std::map<std::pair<int64_t, std::string>, const CameraPose*> pose_of;
  for (const CameraPose& pose : poses) {
    pose_of[{pose.exposure_id, pose.camera}] = &pose;
  }
  const Rig& rig = survey.rig;
  std::vector<ImageResidual> out;
  for (const VertexMatch& m : matches) {
    const auto point = points.find({m.crossing_id, m.band, m.db_vertex});
    const auto v = measured.find({m.exposure_id, m.band_id, m.vertex});
    if (point == points.end() || v == measured.end()) continue;
    const int pair = v->second->pair;
    if (pair < 0 || pair >= static_cast<int>(rig.stereo_pairs.size())) {
      continue;
    }
    for (int side = 0; side < 2; ++side) {
      const RigCamera& camera = rig.cameras[rig.stereo_pairs[pair][side]];
      const auto pose = pose_of.find({m.exposure_id, camera.camera.name()});
      if (pose == pose_of.end()) continue;
      const Eigen::Vector3d p_cam = pose->second->q_enu_cam.conjugate() *
                                    (point->second.first - pose->second->p_enu);
      Eigen::Vector2d uv;
      if (!camera.camera.Project(p_cam, &uv)) continue;
      const Eigen::Vector2d& uv_measured =
          side == 0 ? v->second->uv_left : v->second->uv_right;
      out.push_back({camera.camera.name(), m.exposure_id, point->second.second,
                     (uv - uv_measured).norm()});
    }
  }
  return out;
}

}  // namespace report_internal
}  // namespace zebrageo
