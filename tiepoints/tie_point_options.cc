#include <sstream>
#include <string>

#include "survey/option_check.h"
#include "tiepoints/tie_points.h"

namespace zebrageo {

std::string TiePointOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, max_features_per_image, 10);
  OPTION_IN(check, max_descriptor_ratio, "(", 0.0, 1.0, "]");
  OPTION_GT(check, max_epipolar_distance_px, 0.0);
  OPTION_GE(check, exposure_window, 1);
  OPTION_GT(check, max_reprojection_error_px, 0.0);
  OPTION_GT(check, max_range_m, 2.0);
  OPTION_GE(check, min_triangulation_angle_rad, 0.0);
  OPTION_GE(check, min_track_length, 2);
  OPTION_GE(check, max_tracks_per_exposure, 1);
  return check.problem();
}

}  // namespace zebrageo
