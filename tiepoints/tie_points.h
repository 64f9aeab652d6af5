// Tie points: image features matched between the two images of each stereo
// pair and between consecutive exposures (OpenCV ORB), chained into tracks,
// triangulated with the INS poses and cleaned of outliers. In the
// adjustment their reprojection errors tie the exposures together where
// there is no control.
//
// Frames: tracks are triangulated in the survey's ENU frame; observations
// are distorted pixel coordinates (pixel (0,0) = centre of the top-left
// pixel), as the vertex observations. Angles in radians.
//
// The tracks and the summary are plain data of survey/tie_tracks.h: the
// adjustment receives them without including this library.
#ifndef ZEBRAGEO_TIEPOINTS_TIE_POINTS_H_
#define ZEBRAGEO_TIEPOINTS_TIE_POINTS_H_

#include <functional>
#include <string>
#include <vector>

#include "survey/cancellation.h"
#include "survey/exposures.h"
#include "survey/math_util.h"
#include "survey/rig.h"
#include "survey/tie_tracks.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct TiePointOptions {
  // ORB features detected per image.
  int max_features_per_image = 1500;
  // ORB pyramid levels (scale 1.2 each): few, because a coarse level
  // localises a corner to a fraction of its pixel, i.e. several pixels.
  int orb_levels = 4;
  // Refine keypoints to sub-pixel corners (cv::cornerSubPix, 5x5 window);
  // off: it did not improve the urban preset (H 15.9 vs 15.3 cm).
  bool refine_subpixel = false;
  // Lowe's ratio test on the two nearest descriptors.
  double max_descriptor_ratio = 0.8;
  // Matches are kept when the epipolar distance implied by the INS relative
  // pose is below this (pixels; the INS is accurate over a fraction of a
  // second, so this is a tight geometric check).
  double max_epipolar_distance_px = 2.0;
  // Consecutive exposures matched with each exposure (1 = the next one).
  int exposure_window = 2;
  // Triangulated tracks are kept when every reprojection error is below
  // this (pixels), the point is 2 to max_range_m in front of each camera
  // and the largest intersection angle exceeds min_triangulation_angle_rad.
  double max_reprojection_error_px = 1.5;
  double max_range_m = 40.0;
  double min_triangulation_angle_rad = DegToRad(2.0);
  int min_track_length = 4;
  // Keep only tracks seen by both cameras of a stereo pair at least once.
  bool require_stereo = true;
  // Tracks kept per exposure (the longest first), to bound the
  // adjustment's size. Where the GNSS/INS jitters from one exposure to the
  // next, the tracks are what carries the along-track position between
  // crossings: buenos-aires (field case) H 5.5 cm with 25, 4.3 cm with
  // 100 (150 tracks in place of 132); the urban preset keeps 1794 tracks in
  // place of 1711, its adjustment ~20% longer.
  int max_tracks_per_exposure = 100;

  // "" when valid, else "field = value: constraint".
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_features_per_image", max_features_per_image);
    v("orb_levels", orb_levels);
    v("refine_subpixel", refine_subpixel);
    v("max_descriptor_ratio", max_descriptor_ratio);
    v("max_epipolar_distance_px", max_epipolar_distance_px);
    v("exposure_window", exposure_window);
    v("max_reprojection_error_px", max_reprojection_error_px);
    v("max_range_m", max_range_m);
    v("min_triangulation_angle_rad", min_triangulation_angle_rad);
    v("min_track_length", min_track_length);
    v("require_stereo", require_stereo);
    v("max_tracks_per_exposure", max_tracks_per_exposure);
  }
};

// Builds tie-point tracks from the survey's images. Images that cannot be
// read are skipped (counted in `summary`, which may be null).
// `progress(done, total)` is called after each exposure when set. Throws
// std::invalid_argument ("TiePointOptions: field = value: constraint") when
// options.Check() fails.
std::vector<TieTrack> BuildTieTracks(
    const TiePointOptions& options, const std::string& survey_folder,
    const Rig& rig, const Trajectory& trajectory,
    const ExposureTable& exposures, TiePointSummary* summary,
    const std::function<void(int, int)>& progress = nullptr,
    const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_TIEPOINTS_TIE_POINTS_H_
