#include "reconstruction/band.h"

#include <sstream>

namespace zebrageo {

std::string BandOptions::Check() const {
  std::ostringstream error;
  if (!(max_side_angle_rad > 0.0 && max_side_angle_rad < 0.5)) {
    error << "max_side_angle_rad = " << max_side_angle_rad
          << ": must be in (0, 0.5)";
  } else if (!(min_side_overlap_fraction >= 0.0 &&
               min_side_overlap_fraction <= 1.0)) {
    error << "min_side_overlap_fraction = " << min_side_overlap_fraction
          << ": must be in [0, 1]";
  } else if (!(extremity_length_fraction > 0.0 &&
               extremity_length_fraction <= 1.0)) {
    error << "extremity_length_fraction = " << extremity_length_fraction
          << ": must be in (0, 1]";
  } else if (!(transversal_search_m > 0.0)) {
    error << "transversal_search_m = " << transversal_search_m
          << ": must be > 0";
  } else if (!(side_margin_m >= 0.0)) {
    error << "side_margin_m = " << side_margin_m << ": must be >= 0";
  } else if (!(transversal_max_angle_rad > 0.0 &&
               transversal_max_angle_rad < 1.5)) {
    error << "transversal_max_angle_rad = " << transversal_max_angle_rad
          << ": must be in (0, 1.5)";
  } else if (!(point_angle_tolerance_rad > 0.0)) {
    error << "point_angle_tolerance_rad = " << point_angle_tolerance_rad
          << ": must be > 0";
  } else if (!(hough_angle_step_rad > 0.0 && hough_angle_step_rad < 0.2)) {
    error << "hough_angle_step_rad = " << hough_angle_step_rad
          << ": must be in (0, 0.2)";
  } else if (!(hough_rho_step_px > 0.0)) {
    error << "hough_rho_step_px = " << hough_rho_step_px << ": must be > 0";
  } else if (!(hough_score_fraction > 0.0 && hough_score_fraction <= 1.0)) {
    error << "hough_score_fraction = " << hough_score_fraction
          << ": must be in (0, 1]";
  } else if (!(pair_score_fraction > 0.0 && pair_score_fraction <= 1.0)) {
    error << "pair_score_fraction = " << pair_score_fraction
          << ": must be in (0, 1]";
  } else if (!(hough_min_gradient > 0.0)) {
    error << "hough_min_gradient = " << hough_min_gradient << ": must be > 0";
  } else if (!(refine_distance_px > 0.0)) {
    error << "refine_distance_px = " << refine_distance_px << ": must be > 0";
  } else if (min_transversal_points < 2) {
    error << "min_transversal_points = " << min_transversal_points
          << ": must be >= 2";
  } else if (!(max_stereo_disagreement_m > 0.0)) {
    error << "max_stereo_disagreement_m = " << max_stereo_disagreement_m
          << ": must be > 0";
  } else if (!(max_crossing_gap_m > 0.0)) {
    error << "max_crossing_gap_m = " << max_crossing_gap_m << ": must be > 0";
  } else if (!(max_band_range_m > 0.0)) {
    error << "max_band_range_m = " << max_band_range_m << ": must be > 0";
  } else if (!(min_line_sigma_px > 0.0)) {
    error << "min_line_sigma_px = " << min_line_sigma_px << ": must be > 0";
  } else if (!(min_sigma_m > 0.0)) {
    error << "min_sigma_m = " << min_sigma_m << ": must be > 0";
  } else if (!(min_end_step_fraction >= 0.0 && min_end_step_fraction < 1.0)) {
    error << "min_end_step_fraction = " << min_end_step_fraction
          << ": must be in [0, 1)";
  } else if (!(end_step_profile_px >= 1.0)) {
    error << "end_step_profile_px = " << end_step_profile_px
          << ": must be >= 1";
  } else if (!(end_angle_full_range_m > 0.0)) {
    error << "end_angle_full_range_m = " << end_angle_full_range_m
          << ": must be > 0";
  } else if (!(end_angle_min_share > 0.0 && end_angle_min_share <= 1.0)) {
    error << "end_angle_min_share = " << end_angle_min_share
          << ": must be in (0, 1]";
  } else if (!(max_end_disagreement_rad_per_m > 0.0)) {
    error << "max_end_disagreement_rad_per_m = "
          << max_end_disagreement_rad_per_m << ": must be > 0";
  } else if (completion_min_bands < 3) {
    error << "completion_min_bands = " << completion_min_bands
          << ": must be >= 3";
  } else if (!(completion_tolerance_m > 0.0)) {
    error << "completion_tolerance_m = " << completion_tolerance_m
          << ": must be > 0";
  } else if (!(completion_min_sigma_m > 0.0)) {
    error << "completion_min_sigma_m = " << completion_min_sigma_m
          << ": must be > 0";
  } else if (!(inferred_score_factor > 0.0 && inferred_score_factor <= 1.0)) {
    error << "inferred_score_factor = " << inferred_score_factor
          << ": must be in (0, 1]";
  } else if (!(max_end_angle_rad > 0.0 && max_end_angle_rad < 1.5)) {
    error << "max_end_angle_rad = " << max_end_angle_rad
          << ": must be in (0, 1.5)";
  } else if (!(max_transversal_run_on > 0.0)) {
    error << "max_transversal_run_on = " << max_transversal_run_on
          << ": must be > 0";
  } else if (!(max_inferred_range_m > 0.0)) {
    error << "max_inferred_range_m = " << max_inferred_range_m
          << ": must be > 0";
  } else if (!(hidden_end_max_rms_m > 0.0)) {
    error << "hidden_end_max_rms_m = " << hidden_end_max_rms_m
          << ": must be > 0";
  } else if (!(hidden_end_max_offset_m > 0.0)) {
    error << "hidden_end_max_offset_m = " << hidden_end_max_offset_m
          << ": must be > 0";
  } else if (!(max_length_excess_m >= 0.0)) {
    error << "max_length_excess_m = " << max_length_excess_m
          << ": must be >= 0";
  } else if (min_end_direction_observations < 2) {
    error << "min_end_direction_observations = "
          << min_end_direction_observations << ": must be >= 2";
  }
  return error.str();
}

}  // namespace zebrageo
