#include "reconstruction/band.h"

#include <sstream>

#include "survey/option_check.h"

namespace zebrageo {

std::string BandOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, max_side_angle_rad, "(", 0.0, 0.5, ")");
  OPTION_IN(check, min_side_overlap_fraction, "[", 0.0, 1.0, "]");
  OPTION_IN(check, extremity_length_fraction, "(", 0.0, 1.0, "]");
  OPTION_GT(check, transversal_search_m, 0.0);
  OPTION_GE(check, side_margin_m, 0.0);
  OPTION_IN(check, transversal_max_angle_rad, "(", 0.0, 1.5, ")");
  OPTION_GT(check, point_angle_tolerance_rad, 0.0);
  OPTION_IN(check, hough_angle_step_rad, "(", 0.0, 0.2, ")");
  OPTION_GT(check, hough_rho_step_px, 0.0);
  OPTION_IN(check, hough_score_fraction, "(", 0.0, 1.0, "]");
  OPTION_IN(check, pair_score_fraction, "(", 0.0, 1.0, "]");
  OPTION_GT(check, hough_min_gradient, 0.0);
  OPTION_GT(check, refine_distance_px, 0.0);
  OPTION_GE(check, min_transversal_points, 2);
  OPTION_GT(check, max_stereo_disagreement_m, 0.0);
  OPTION_GT(check, max_crossing_gap_m, 0.0);
  OPTION_GT(check, max_band_range_m, 0.0);
  OPTION_GT(check, min_line_sigma_px, 0.0);
  OPTION_GT(check, min_sigma_m, 0.0);
  OPTION_IN(check, min_end_step_fraction, "[", 0.0, 1.0, ")");
  OPTION_GE(check, end_step_profile_px, 1.0);
  OPTION_GT(check, end_angle_full_range_m, 0.0);
  OPTION_IN(check, end_angle_min_share, "(", 0.0, 1.0, "]");
  OPTION_GT(check, max_end_disagreement_rad_per_m, 0.0);
  OPTION_GE(check, completion_min_bands, 3);
  OPTION_GT(check, completion_tolerance_m, 0.0);
  OPTION_GT(check, completion_min_sigma_m, 0.0);
  OPTION_IN(check, inferred_score_factor, "(", 0.0, 1.0, "]");
  OPTION_IN(check, max_end_angle_rad, "(", 0.0, 1.5, ")");
  OPTION_GT(check, max_transversal_run_on, 0.0);
  OPTION_GT(check, max_inferred_range_m, 0.0);
  OPTION_GT(check, hidden_end_max_rms_m, 0.0);
  OPTION_GT(check, hidden_end_max_offset_m, 0.0);
  OPTION_GE(check, max_length_excess_m, 0.0);
  OPTION_GE(check, min_end_direction_observations, 2);
  OPTION_GT(check, ladder_gap_reach_m, 0.0);
  OPTION_IN(check, max_ladder_join_step_fraction, "[", 0.0, 1.0, ")");
  OPTION_GT(check, ladder_min_bar_width_m, 0.0);
  OPTION_GT(check, ladder_max_bar_width_m, ladder_min_bar_width_m);
  OPTION_GT(check, min_paint_gap_m, 0.0);
  OPTION_IN(check, min_paint_gap_drop_fraction, "(", 0.0, 1.0, "]");
  OPTION_GE(check, min_piece_widths, 0.0);
  OPTION_GT(check, max_crossing_length_excess_m, 0.0);
  OPTION_GT(check, crossing_length_agreement_m, 0.0);
  OPTION_GE(check, ladder_end_sigma_m, 0.0);
  return check.problem();
}

const char* EndEvidenceName(EndEvidence evidence) {
  switch (evidence) {
    case EndEvidence::kLadderBar:
      return "ladder_bar";
    case EndEvidence::kCrossingLine:
      return "crossing_line";
    case EndEvidence::kPaintEnd:
      break;
  }
  return "paint_end";
}

}  // namespace zebrageo
