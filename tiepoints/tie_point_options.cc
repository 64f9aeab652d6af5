#include <sstream>
#include <string>

#include "tiepoints/tie_points.h"

namespace zebrageo {

std::string TiePointOptions::Check() const {
  std::ostringstream message;
  if (max_features_per_image < 10) {
    message << "max_features_per_image = " << max_features_per_image
            << ": must be >= 10";
  } else if (!(max_descriptor_ratio > 0.0 && max_descriptor_ratio <= 1.0)) {
    message << "max_descriptor_ratio = " << max_descriptor_ratio
            << ": must be in (0, 1]";
  } else if (!(max_epipolar_distance_px > 0.0)) {
    message << "max_epipolar_distance_px = " << max_epipolar_distance_px
            << ": must be > 0";
  } else if (exposure_window < 1) {
    message << "exposure_window = " << exposure_window << ": must be >= 1";
  } else if (!(max_reprojection_error_px > 0.0)) {
    message << "max_reprojection_error_px = " << max_reprojection_error_px
            << ": must be > 0";
  } else if (!(max_range_m > 2.0)) {
    message << "max_range_m = " << max_range_m << ": must be > 2";
  } else if (!(min_triangulation_angle_rad >= 0.0)) {
    message << "min_triangulation_angle_rad = " << min_triangulation_angle_rad
            << ": must be >= 0";
  } else if (min_track_length < 2) {
    message << "min_track_length = " << min_track_length << ": must be >= 2";
  } else if (max_tracks_per_exposure < 1) {
    message << "max_tracks_per_exposure = " << max_tracks_per_exposure
            << ": must be >= 1";
  }
  return message.str();
}

}  // namespace zebrageo
