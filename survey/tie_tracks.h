// Tie-point tracks: what the tie-point matcher (tiepoints/tie_points.h)
// hands to the trajectory adjustment (adjustment/trajectory_adjuster.h),
// plain data so that neither library includes the other.
//
// Frames: tracks are triangulated in the survey's ENU frame; observations
// are distorted pixel coordinates (pixel (0,0) = centre of the top-left
// pixel), as the vertex observations.
#ifndef ZEBRAGEO_SURVEY_TIE_TRACKS_H_
#define ZEBRAGEO_SURVEY_TIE_TRACKS_H_

#include <Eigen/Core>
#include <vector>

namespace zebrageo {

struct TieObservation {
  int image = 0;  // index into ExposureTable::images
  double time = 0.0;
  int camera = 0;  // index into Rig::cameras
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  // The feature's pyramid scale (1.2^octave): a corner found on a coarser
  // level is localised that many times less precisely.
  double scale = 1.0;
};

struct TieTrack {
  std::vector<TieObservation> observations;         // at most one per image
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();  // triangulated
};

// What the matching did (adjustment.json's "tie_points").
struct TiePointSummary {
  int images_read = 0;
  int images_missing = 0;
  int matches = 0;
  int tracks = 0;
  int observations = 0;
  double time_in_seconds = 0.0;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_TIE_TRACKS_H_
