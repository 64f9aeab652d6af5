// The geometry sweep of issue 17: random simulated surveys, in memory,
// through the matcher and the adjustment, scored against the truth as
// ../shared/tools/score_results.py scores a results folder.
//
// For each seed: the random preset's options (simulator.h, ApplyPreset
// "random"), the survey in memory (simulated_survey.h, no images), a
// synthetic reconstruction and paint probe (synthetic_reconstruction.h),
// and road-line points (synthetic_lines.h), then BuildObservations +
// MatchBands and the adjustment with zebra crossings and road lines as
// `zebrageo run` does (no tie points), single-threaded.
//
// Scoring (score_results.py, modes match and poses):
//  - a matched vertex is right when its position placed with the TRUE pose
//    lies within 0.2 m of the truth corner named by (crossing_id, band,
//    db_vertex), wrong otherwise (also when that band is not in the street);
//  - crossings matched: those with a right match, among the matchable
//    ones (in the street, in the database, and reconstructed);
//  - poses: per image, the camera's projection centre and rotation against
//    the truth, horizontal and vertical RMS and attitude RMS, after the
//    adjustment and before it (the measured trajectory).
// Frames and units: ENU metres, radians inside; the printed figures are in
// centimetres and degrees.
#ifndef ZEBRAGEO_TESTS_SUPPORT_GEOMETRY_SWEEP_H_
#define ZEBRAGEO_TESTS_SUPPORT_GEOMETRY_SWEEP_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "simulator/simulator.h"

namespace zebrageo::support {

struct GeometrySweepOptions {
  // Road lengths drawn by the random preset are limited to this (metres):
  // the ctest keeps surveys small. 0: the preset's own range.
  double max_road_length_m = 0.0;
  // Junctions of the random preset (RandomPresetLimits::junctions): -1
  // drawn, 0 none, N exactly N per survey.
  int junctions = -1;
  // Avenues of the random preset (RandomPresetLimits::avenues, issue 52):
  // -1 drawn, 0 none (the default), 1 every survey.
  int avenues = 0;
  // Only surveys of this random kind (simulator.h: RandomKinds()); empty:
  // all.
  std::string only_kind;
  // A named preset (simulator.h) instead of the random one, with the seed:
  // to compare the sweep with `zebrageo run` on the same survey.
  std::string preset;
  // Simulator options set after the draw, "key=value" as `simulate --set`
  // reads them (simulator.h: SetOption): a regression seed held to the
  // scene it was written for, or one knob of the preset swept.
  std::vector<std::string> sim_set;
  // A survey is worse than its input when the adjusted horizontal and
  // vertical error, hypot(H, V), exceeds the input's by more than this, or
  // the attitude error by more than worse_attitude_deg.
  double worse_position_m = 0.005;
  double worse_attitude_deg = 0.01;
  // The sequence of `zebrageo run` (pipeline.cc): after the adjustment, the
  // matches it rejected removed, the undecided observations matched again
  // with the adjusted trajectory, and the adjustment again if that added
  // matches. false: match, then adjust once.
  bool rematch = true;
  // Road lines as `zebrageo run` uses them (pipeline/adjustment_pass.h): the
  // lane lines' points synthesised (synthetic_lines.h), control in the
  // adjustment, and the trajectory they alone correct searched by the
  // second pass when the adjustment had too few crossings. false: zebra
  // crossings only.
  bool lines = true;
  // The adjustment's "never worse than the input" (issue 43): its outage
  // readings and its guard (AdjustmentOptions::never_worse). false: off,
  // the adjustment as before them.
  bool outage_readings = true;
  bool guard = true;
  // RunGeometrySurvey's dump renders the survey's images (false: geometry
  // only, to look at the trajectories and matches).
  bool dump_images = true;

  std::string Check() const;
};

struct GeometryRunResult {
  uint64_t seed = 0;
  std::string kind;      // the random preset's kind
  std::string params;    // the drawn parameters in short
  bool skipped = false;  // not of the kind asked for
  std::string error;     // an exception escaped (a bug)
  // Reconstruction.
  int bands_reconstructed = 0;
  int line_points = 0;  // synthesised road-line points
  // Matching.
  // Of the matches kept as control (the adjustment's rejects removed).
  int wrong = 0;
  int right = 0;
  int rejected_by_adjustment = 0;  // vertex matches
  int rematched = 0;  // observations the second registration pass matched
  // Wrong matches of vertices of bands the synthesis cut short (one end's
  // vertices 0.25-1 m inside the paint): the band is the right one, its
  // vertices are not where the database's are.
  int wrong_on_cut_bands = 0;
  // Matches whose (crossing_id, band) is not the truth band the
  // reconstructed band came from (issue 52: across a refuge island), and
  // matches checked so.
  int wrong_ids = 0;
  int ids_checked = 0;
  int crossings_matchable = 0;
  int crossings_matched = 0;
  // Matchable crossings that are not repainted: a consistent set exists.
  int consistent_crossings = 0;
  // Of those, matched; and repainted crossings kept as control (their
  // paint is not where the database has it: they should be rejected).
  int consistent_matched = 0;
  int repainted_matched = 0;
  std::vector<std::string> wrong_crossings;  // crossing_id:band of wrong ones
  // The most frequent reason of the observations not matched (refused or
  // without a candidate), and how many gave it.
  std::string refusal;
  int refusals = 0;
  // Adjustment.
  bool usable = false;
  std::string message;  // the adjustment's message when not usable
  int cameras = 0;
  // RMS per image: horizontal, vertical (metres), attitude (degrees).
  double h_before_m = 0.0, v_before_m = 0.0, att_before_deg = 0.0;
  double h_after_m = 0.0, v_after_m = 0.0, att_after_deg = 0.0;
  bool worse_position = false;
  bool worse_attitude = false;
  // Stretches where the guard kept the input (control_guard.h).
  int input_kept_stretches = 0;
  // Crossings with a right match kept as control (crossing_id), and per
  // image after the adjustment (when usable): its time, its camera's true
  // position (ENU) and its horizontal error (metres).
  std::vector<std::string> matched_crossings;
  struct ImageError {
    double time = 0.0;
    Eigen::Vector3d p_true_enu = Eigen::Vector3d::Zero();
    double h_m = 0.0;
  };
  std::vector<ImageError> h_after_by_image;
  double seconds = 0.0;

  // "exit 3" while a consistent set of crossings exists.
  bool UnusableWithControl() const {
    return !usable && consistent_crossings > 0;
  }
  // One line: seed, parameters, figures and what failed.
  std::string Line() const;
};

// Runs one random survey. When `dump_folder` is not empty, writes the
// survey there (SimulateSurvey, images rendered, in dump_folder/survey),
// and the synthetic reconstructed_bands.csv with the sweep's matches.csv,
// crossing_decisions.csv and poses.csv in dump_folder/results.
GeometryRunResult RunGeometrySurvey(uint64_t seed,
                                    const GeometrySweepOptions& options,
                                    const std::string& dump_folder = "");

// Runs seeds [first, last] on `threads` threads (each survey single
// threaded), results in seed order. `done` (may be empty) is called, from
// one thread at a time, with each result as it completes.
std::vector<GeometryRunResult> RunGeometrySweep(
    uint64_t first, uint64_t last, int threads,
    const GeometrySweepOptions& options,
    const std::function<void(const GeometryRunResult&)>& done = {});

// The "Done when" for the geometry sweep.
struct GeometrySweepSummary {
  int surveys = 0;  // run (not skipped)
  int errors = 0;   // exceptions
  int wrong_matches = 0;
  int wrong_on_cut_bands = 0;
  int surveys_with_wrong_matches = 0;
  int wrong_ids = 0;  // GeometryRunResult::wrong_ids, summed
  int ids_checked = 0;
  int right_matches = 0;
  int crossings_matchable = 0;
  int crossings_matched = 0;
  int consistent_crossings = 0;  // matchable and not repainted
  int consistent_matched = 0;
  int repainted_matched = 0;  // repainted crossings kept as control
  int worse_position = 0;
  int worse_attitude = 0;
  int input_kept = 0;  // surveys where the guard kept the input somewhere
  int unusable = 0;
  int unusable_with_control = 0;
  double seconds = 0.0;  // summed over surveys
  // Over the usable runs: median, 95th percentile, worst.
  std::array<double, 3> h_after_cm{}, v_after_cm{}, att_after_deg{};
  std::array<double, 3> h_before_cm{}, v_before_cm{}, att_before_deg{};
  // Per kind of the random preset: surveys, wrong matches, worse in
  // position, worse in attitude, unusable with control, crossings matched,
  // matchable.
  std::map<std::string, std::array<int, 7>> by_kind;

  // Of the matchable crossings that are not repainted: a repainted one's
  // paint lies 0.2-1 m from where the database has it, and the issue asks
  // that it be found and rejected, not used as control.
  double MatchedShare() const {
    return consistent_crossings > 0
               ? static_cast<double>(consistent_matched) / consistent_crossings
               : 1.0;
  }
  // Of every matchable crossing, repainted ones included.
  double AllMatchedShare() const {
    return crossings_matchable > 0
               ? static_cast<double>(crossings_matched) / crossings_matchable
               : 1.0;
  }
  // Empty when the sweep meets the criteria (0 wrong matches, no
  // run worse than its input, no unusable adjustment while a consistent set
  // of crossings exists, >= 90 % of the matchable crossings that are not
  // repainted matched), else one sentence per failed criterion.
  std::vector<std::string> Failures() const;
  std::string Report() const;
};

GeometrySweepSummary Summarise(const std::vector<GeometryRunResult>& results);

}  // namespace zebrageo::support

#endif  // ZEBRAGEO_TESTS_SUPPORT_GEOMETRY_SWEEP_H_
