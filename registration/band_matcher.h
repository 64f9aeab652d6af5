// Matching reconstructed zebra bands to the road-mark database: which
// database band vertex each reconstructed vertex is, so that it can serve as
// a ground control point.
//
// Frames and units: `body` is the vehicle frame (FRD) at an exposure, `enu`
// the survey's working frame; metres, radians, seconds. Poses are survey
// Poses: p_enu = q_enu_body * p_body + p_enu (Eigen quaternions, Hamilton).
//
// Model. The measured trajectory is wrong by a slowly varying drift of up to
// metres. At one exposure its horizontal error is a PoseCorrection: a
// heading error about the vertical through the vehicle and a horizontal
// shift,
//   p_true = Rz(heading_rad) * (p_measured - p_vehicle) + p_vehicle + shift,
// with p_measured = q_enu_body * p_body + p_enu placed with the measured
// pose. Height is left to the adjustment (a zebra is flat).
//
// Method (one file per step: band_matcher_internal.h lists them):
//  1. Hypotheses. For each observation (the bands of one reconstructed
//     crossing group in one exposure) every pairing of an observed band with
//     a database band of compatible shape inside the drift gate gives a
//     correction; it is refined on all the bands it explains and scored:
//     +1 per band explained to `hit_tolerance_m` at all four corners,
//     -missing_band_weight per database band of an explained crossing that
//     the cameras would have seen whole but that was not observed,
//     -contradiction_weight per observed band lying in a gap of a database
//     crossing, -unexplained_band_weight per band outside every crossing.
//  2. Aggregation. The drift changes slowly, so observations within
//     `window_s` share the correction: a hypothesis is scored by the sum over
//     those observations of their own hypothesis at the same correction
//     (a missing database band counts for at most max_missing_views views,
//     and not at all if another view saw it: parked vehicles hide bands).
//  3. Decision. The best hypothesis must beat every distinct alternative
//     (another band offset, another crossing) by `min_margin`; with
//     `require_both_ends`, even without the evidence of the crossing end
//     that favours it most (a band missing on either side at that end must
//     not decide the 1 m periodicity).
//  4. Continuity. Crossings matched alone must imply consistent corrections
//     (within neighbour_tolerance_m + max_drift_rate_m_per_s * time apart);
//     outliers are refused, and observations ambiguous alone are resolved
//     when the correction predicted from matched neighbours (with an error
//     bound below max_resolve_bound_m) singles out one hypothesis.
//  5. Database faults are detected and reported: crossings missing from the
//     database, crossings gone from the street, bands missing on either
//     side, crossings shifted (repainted) by decimetres.
//
// Known limit: with require_both_ends = false (the default), a crossing
// whose far end is never in view is decided by its near end alone; an end
// band hidden from EVERY view (or missing from the street without the
// database knowing) then looks like a one-band shift. Continuity with
// neighbouring crossings catches it when they are close in time; otherwise
// set require_both_ends.
#ifndef ZEBRAGEO_REGISTRATION_BAND_MATCHER_H_
#define ZEBRAGEO_REGISTRATION_BAND_MATCHER_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "registration/paint_probe.h"
#include "registration/roadmark_index.h"
#include "survey/cancellation.h"
#include "survey/results.h"
#include "survey/results_match.h"
#include "survey/rig.h"
#include "survey/trajectory.h"

namespace zebrageo {

struct MatchOptions {
  // --- Candidate gating -------------------------------------------------
  // Horizontal error of the measured trajectory the search allows. The
  // GNSS/INS sd_* are often optimistic by an order of magnitude in urban
  // canyons: raise this for long outages, lower it to speed up clean data.
  double max_drift_m = 4.0;
  // The gate also covers this many times the trajectory's claimed
  // horizontal sd, when that is larger than max_drift_m.
  double sd_gate_factor = 5.0;
  // Heading error of the measured trajectory the search allows (2 degrees).
  double max_heading_error_rad = 0.035;
  // Cross-track error the search allows at the crossing (0: max_drift_m
  // only). The second registration pass after an adjustment by road lines
  // alone (rematch.cc) knows the cross-track position to centimetres and
  // the along-track one not at all; band offsets lie across the road.
  double max_cross_track_m = 0.0;

  // --- Band shape -------------------------------------------------------
  // Observed bands outside these sizes are not zebra bands (lane marks,
  // stop lines, truncated bands) and are not used to hypothesise.
  double min_band_length_m = 1.5;
  double max_band_length_m = 8.0;
  double min_band_width_m = 0.25;
  double max_band_width_m = 0.9;
  // An observed band pairs with a database band only if the sizes agree.
  double max_length_difference_m = 0.6;
  double max_width_difference_m = 0.2;

  // --- Scoring ----------------------------------------------------------
  // A band is explained ("hit") when its four corners, after the
  // correction, lie within this of a database band's corners. Well below
  // half the 1 m band period, above database error + drift change.
  double hit_tolerance_m = 0.3;
  // A vertex becomes a control point only if, after the correction refined
  // on the observation's own bands, it lies within this of its database
  // corner, and every corner of its band lies within this across the
  // band's axis (the band is the database's), two of them whole. An end
  // seen short or drawn long loses its two corners, not the band.
  double vertex_tolerance_m = 0.15;
  double missing_band_weight = 1.0;
  // Over the window, a database band that should have been seen counts as
  // missing in at most this many views, and not at all if it was seen in
  // another: a vehicle parked at the kerb hides a band from many views at
  // once, and views of one place are not independent.
  int max_missing_views = 2;
  double contradiction_weight = 2.0;
  double unexplained_band_weight = 0.5;
  // A fit that leaves more observed bands outside every crossing than this
  // many per band it explains is refused, whatever its margin: paint the
  // database lacks next to the bands it places says the place is wrong
  // (with the stated position sd too small after a GNSS outage, the one
  // offset inside the gate can put most of a crossing's bands beyond its
  // end and still win alone).
  double max_unexplained_per_hit = 1.0;
  // Visibility of database bands (for missing-band evidence): a band counts
  // as "should have been seen" only when all its corners project at least
  // this far inside both images of a stereo pair...
  // 0: learn it from the data: the 1st percentile of how close to the image
  // border the observed bands come, plus visibility_safety_px.
  double visibility_margin_px = 0.0;
  double visibility_safety_px = 20.0;
  // ... and its centre lies within this horizontal range of the vehicle.
  // 0: take the 90th percentile of the observed bands' ranges.
  double visibility_range_m = 0.0;
  // With an image probe (MatchInput::paint_probe), a predicted band is
  // looked for wherever its centre lies in the probe's image within this
  // range; the probe decides whether enough of it is in view.
  double probe_range_m = 20.0;

  // --- Aggregation over time --------------------------------------------
  // Observations within +-window_s of each other share one correction.
  double window_s = 3.0;
  // Two hypotheses are the same correction when they place the observed
  // bands within this of each other (plus the drift change over the time
  // between them).
  double same_correction_tolerance_m = 0.2;
  // How fast the trajectory error may change (metres per second): an INS
  // drifting 3 m in a minute-long outage changes by ~0.05 m/s.
  double drift_rate_m_per_s = 0.05;

  // --- Decision ---------------------------------------------------------
  // Bands an observation must explain itself to be matched.
  int min_hit_bands = 2;
  // Aggregated score by which the best hypothesis must beat the best
  // distinct one (in band-equivalents: 2 = two exposures that see what lies
  // beyond an end of the crossing).
  double min_margin = 2.0;
  // The 1 m periodicity is resolved at the crossing's ends. A database
  // fault at one end (its end band missing on either side) makes the
  // evidence of that end point one band off. true: require the margin even
  // without the evidence of the stronger end, i.e. both ends must agree
  // (immune to one end fault, but a crossing whose far end is never in view
  // is then matched only through continuity). false: one end decides and
  // the continuity check between crossings is the safety net.
  bool require_both_ends = false;
  // A hypothesis must beat every other band offset of its crossing by at
  // least this much strong evidence (in views: bare road where the
  // alternative predicts a database band, held or implied by the
  // numbering; a band in a gap of the crossing or beyond its band 1), not
  // by band counts alone, which a database missing an end band or an end
  // band hidden in the images fakes, at one end or at both. Refused
  // (ambiguous) otherwise: continuity with neighbouring crossings may
  // still resolve it.
  double min_strong_margin = 1.0;

  // --- Continuity between crossings -------------------------------------
  // Matched crossings within this time of each other must agree.
  double neighbour_window_s = 30.0;
  // Allowed disagreement at zero time apart (database error, noise), plus
  // max_drift_rate_m_per_s per second apart: a worst case, not a typical
  // rate, since refusing a good crossing costs as much as a wrong one here.
  double neighbour_tolerance_m = 0.35;
  double max_drift_rate_m_per_s = 0.1;
  // Neighbours whose allowed disagreement exceeds this cannot tell a
  // one-band error from drift and do not vote.
  double max_informative_tolerance_m = 0.8;
  // Ambiguous observations are resolved from neighbours only when the
  // bound on the predicted correction's error is below max_resolve_bound_m
  // (well below half the 1 m band period), and no GNSS event (the claimed
  // sd changing by more than max_sd_ratio) lies between them. The bound is
  // resolve_base_m plus, extrapolating from one side, drift_rate_m_per_s *
  // time to the match, or, interpolating between matches at tb and ta,
  // max_drift_acceleration_m_per_s2 * (t - tb) * (ta - t) / 2 (an INS
  // drift is smooth: 1 m of error varying over a minute accelerates by
  // ~0.01 m/s^2), whichever of these and max_drift_per_metre is larger.
  double resolve_base_m = 0.1;
  double max_drift_acceleration_m_per_s2 = 0.01;
  // A GNSS/INS error may also switch by a metre within ~40 m of road
  // (multipath in a street canyon) without the claimed sd showing it: the
  // bound grows by this per metre travelled from the nearest match.
  double max_drift_per_metre = 0.025;
  double max_resolve_bound_m = 0.4;
  // An observation refused only because some band offsets of its crossing
  // were beaten by band counts alone (min_strong_margin) is accepted when
  // the prediction, with a bound up to this, lies within its bound of the
  // observation's best and further than that from every such offset: the
  // images ruled out the near offsets, continuity the far ones.
  double max_exclusion_bound_m = 1.2;
  double max_sd_ratio = 2.0;

  // --- Database faults --------------------------------------------------
  // A matched crossing whose correction departs from its neighbours' by
  // more than this is reported as shifted (repainted).
  double shifted_crossing_threshold_m = 0.15;
  // Refuse matches to crossings reported as shifted (they would bias the
  // adjustment by the shift).
  bool refuse_shifted_crossings = false;
  // Views needed before a crossing or band is reported missing or gone.
  int min_views_for_fault = 2;

  // "" or the first invalid field, e.g. "max_drift_m = -1: must be > 0".
  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("max_drift_m", max_drift_m);
    v("sd_gate_factor", sd_gate_factor);
    v("max_heading_error_rad", max_heading_error_rad);
    v("max_cross_track_m", max_cross_track_m);
    v("min_band_length_m", min_band_length_m);
    v("max_band_length_m", max_band_length_m);
    v("min_band_width_m", min_band_width_m);
    v("max_band_width_m", max_band_width_m);
    v("max_length_difference_m", max_length_difference_m);
    v("max_width_difference_m", max_width_difference_m);
    v("hit_tolerance_m", hit_tolerance_m);
    v("vertex_tolerance_m", vertex_tolerance_m);
    v("missing_band_weight", missing_band_weight);
    v("max_missing_views", max_missing_views);
    v("contradiction_weight", contradiction_weight);
    v("unexplained_band_weight", unexplained_band_weight);
    v("max_unexplained_per_hit", max_unexplained_per_hit);
    v("visibility_margin_px", visibility_margin_px);
    v("visibility_safety_px", visibility_safety_px);
    v("visibility_range_m", visibility_range_m);
    v("probe_range_m", probe_range_m);
    v("window_s", window_s);
    v("same_correction_tolerance_m", same_correction_tolerance_m);
    v("drift_rate_m_per_s", drift_rate_m_per_s);
    v("min_hit_bands", min_hit_bands);
    v("min_margin", min_margin);
    v("require_both_ends", require_both_ends);
    v("min_strong_margin", min_strong_margin);
    v("neighbour_window_s", neighbour_window_s);
    v("neighbour_tolerance_m", neighbour_tolerance_m);
    v("max_drift_rate_m_per_s", max_drift_rate_m_per_s);
    v("max_informative_tolerance_m", max_informative_tolerance_m);
    v("resolve_base_m", resolve_base_m);
    v("max_drift_acceleration_m_per_s2", max_drift_acceleration_m_per_s2);
    v("max_drift_per_metre", max_drift_per_metre);
    v("max_resolve_bound_m", max_resolve_bound_m);
    v("max_exclusion_bound_m", max_exclusion_bound_m);
    v("max_sd_ratio", max_sd_ratio);
    v("shifted_crossing_threshold_m", shifted_crossing_threshold_m);
    v("refuse_shifted_crossings", refuse_shifted_crossings);
    v("min_views_for_fault", min_views_for_fault);
  }
};

// One reconstructed band of an observation.
struct ObservedBand {
  int64_t band_id = 0;
  int pair = 0;  // stereo pair index
  // The vertex labels as written (column `vertex`) and the positions.
  std::array<int, 4> vertex = {0, 1, 2, 3};
  std::array<Eigen::Vector3d, 4> p_body;
  double score = 1.0;
};

// The bands of one reconstructed crossing group seen in one exposure.
struct CrossingObservation {
  int64_t exposure_id = 0;
  int64_t group_id = 0;
  double time_s = 0.0;
  Pose pose;                     // measured T_enu_body at time_s
  double sd_horizontal_m = 0.0;  // the trajectory's claimed sd (max of e, n)
  std::vector<ObservedBand> bands;
};

// Every exposure of the survey (also those where nothing was seen: a
// crossing gone from the street is recognised by what was NOT observed).
struct ExposurePose {
  int64_t exposure_id = 0;
  double time_s = 0.0;
  Pose pose;  // measured
};

struct MatchInput {
  std::vector<CrossingObservation> observations;
  std::vector<ExposurePose> exposures;
  const RoadmarkIndex* index = nullptr;  // required
  // Cameras for visibility reasoning; nullptr: no missing-band evidence
  // (fewer matches, never wrong ones).
  const Rig* rig = nullptr;
  // Image evidence (paint_probe.h): what the image shows where a database
  // band is predicted in view but was not reconstructed. Only kBareRoad
  // makes it a missing band (evidence against the hypothesis); empty: every
  // such band counts as missing, and an end band hidden in every view can
  // pass for a one-band shift.
  std::function<PaintEvidence(int64_t exposure_id, const Pose& pose,
                              const BandCornersEnu& band,
                              const std::vector<BandCornersEnu>& seen)>
      paint_probe;
};

// Matches every observation. Deterministic. `progress` (may be empty) is
// called with (done, total) observations.
// Throws CancelledError when `cancel` is cancelled (checked between
// observations).
MatchResult MatchBands(const MatchInput& input, const MatchOptions& options,
                       const std::function<void(int, int)>& progress = {},
                       const CancellationToken& cancel = {});

// The ENU position of a body-frame point under a measured pose corrected by
// `correction` (horizontal only).
Eigen::Vector3d CorrectedEnu(const Pose& measured,
                             const PoseCorrection& correction,
                             const Eigen::Vector3d& p_body);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_BAND_MATCHER_H_
