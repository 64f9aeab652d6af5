// Internals of MatchBands (band_matcher.h), shared by its five steps:
//   band_matcher_hypotheses.cc  1. observations in the measured placement,
//                                  one-band seeds refined into hypotheses
//   band_matcher_evidence.cc    2. what each view says about a correction
//                                  (hits, gaps, bands the images show bare:
//                                  the paint probe), summed over the window
//   band_matcher_decision.cc    3. each observation alone: margins over
//                                  every distinct alternative, the strong-
//                                  evidence rule between band offsets
//   band_matcher_continuity.cc  4. across crossings: inconsistent passes
//                                  refused, ambiguous observations resolved,
//                                  shifted crossings found
//   band_matcher_output.cc      5. corrections refined into vertex matches,
//                                  database faults, the result
// band_matcher.cc runs them in that order. Not part of the library's API.
//
// Frames and units as in band_matcher.h: ENU metres, radians, seconds; an
// observed band's corners q are measured ENU minus the vehicle position.
#ifndef ZEBRAGEO_REGISTRATION_BAND_MATCHER_INTERNAL_H_
#define ZEBRAGEO_REGISTRATION_BAND_MATCHER_INTERNAL_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "registration/band_matcher.h"
#include "registration/roadmark_index.h"
#include "survey/csv.h"

namespace zebrageo {
namespace band_matcher_internal {

// Two hypotheses of one observation closer than this are one hypothesis.
constexpr double kDuplicateHypothesisM = 0.1;
// Observations of one crossing further apart in time start a new pass.
constexpr double kPassGapFactor = 2.0;
// Evidence counts as strong only from a view whose own best hypothesis lies
// within this of the correction scored (see WindowEvidence).
constexpr double kStrongAgreementM = 0.1;
// A non-explained band this close (across) to a database band's centre
// line is that band seen partly (truncated, occluded): no evidence either way.
constexpr double kPartialBandAcrossM = 0.25;

inline Eigen::Matrix2d Rotation2(double angle) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

// Corner k of an observed band goes to database corner Corner(perm, k):
// 4 starting corners x 2 senses (the ring orders of the two may differ).
inline int PermutedCorner(int perm, int k) {
  const int start = perm % 4;
  return perm < 4 ? (start + k) % 4 : (start - k + 4) % 4;
}

// Where a correction moves a point q (relative to the vehicle).
inline Eigen::Vector2d Apply(const PoseCorrection& c,
                             const Eigen::Vector2d& vehicle,
                             const Eigen::Vector2d& q) {
  return Rotation2(c.heading_rad) * q + vehicle + c.shift_enu_m;
}

// How far apart two corrections place an observation's bands.
inline double CorrectionDistance(const PoseCorrection& a,
                                 const PoseCorrection& b,
                                 const Eigen::Vector2d& centroid_q) {
  return ((Rotation2(a.heading_rad) - Rotation2(b.heading_rad)) * centroid_q +
          a.shift_enu_m - b.shift_enu_m)
      .norm();
}

inline Pose CorrectedPose(const Pose& measured, const PoseCorrection& c) {
  Pose pose;
  pose.q_enu_body = Eigen::Quaterniond(Eigen::AngleAxisd(
                        c.heading_rad, Eigen::Vector3d::UnitZ())) *
                    measured.q_enu_body;
  pose.p_enu = measured.p_enu;
  pose.p_enu.head<2>() += c.shift_enu_m;
  return pose;
}

// ---------------------------------------------------------------------------
// Observations, precomputed in the measured placement.

struct ObsBand {
  bool usable = false;
  std::array<Eigen::Vector2d, 4> q;  // measured ENU minus vehicle position
  BandShape shape;                   // of q (centre relative to the vehicle)
  double range_m = 0.0;
};

struct Obs {
  const CrossingObservation* source = nullptr;
  Eigen::Vector2d vehicle = Eigen::Vector2d::Zero();
  std::vector<ObsBand> bands;
  Eigen::Vector2d centroid_q = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  int usable = 0;
};

// ---------------------------------------------------------------------------
// Evaluation of one correction for one observation.

struct Hit {
  int rec = 0;
  int db = 0;
  int perm = 0;
  double max_error_m = 0.0;
};

struct Eval {
  std::vector<Hit> hits;
  std::vector<int> missing;         // database bands
  std::vector<int> contradictions;  // observed bands
  std::vector<int> unexplained;     // observed bands
  // The unexplained bands lying beyond the crossing's band 1 (held or
  // implied): the database's numbering says the crossing ends there, so a
  // hypothesis that leaves a band there is contradicted, not merely short
  // of a band the database may have lost at its far end.
  std::vector<int> beyond_first;
  std::vector<int> partial;  // observed bands
  // Database bands predicted in view, not reconstructed, where the image
  // probe saw paint, or could not tell (a vehicle, a shadow, out of view):
  // no evidence against the hypothesis, and no database fault (issue 52).
  std::vector<int> painted;
  std::vector<int> unclear;
  // Where the stereo pair shows something standing above the road.
  std::vector<int> occluded;
  double score = 0.0;

  // The crossing most hits fall on, or -1.
  int MainCrossing(const RoadmarkIndex& index) const {
    std::map<int, int> count;
    for (const Hit& h : hits) ++count[index.bands()[h.db].crossing];
    int best = -1;
    int best_count = 0;
    for (const auto& [crossing, n] : count) {
      if (n > best_count) {
        best = crossing;
        best_count = n;
      }
    }
    return best;
  }
};

struct Hypothesis {
  PoseCorrection correction;
  Eval eval;
  int main_crossing = -1;
  // Over the window:
  double aggregated = 0.0;
};

// Visibility of a database band from a corrected pose, through the rig.
class Visibility {
 public:
  Visibility(const Rig* rig, double margin_px, double range_m);
  bool enabled() const { return rig_ != nullptr && range_m_ > 0.0; }
  double range_m() const { return range_m_; }

  // Whether the image probe may look for `band` from `pose`: its centre
  // in front of the left camera of the first stereo pair (the probe's),
  // inside that image, within probe_range_m. The probe itself then says
  // whether enough of the band is in the image to tell paint from asphalt
  // (PaintProbeOptions::min_inside_share): bare road seen where a band is
  // predicted is evidence whether or not the reconstruction could have
  // delivered that band whole.
  bool ProbeMayLook(const Pose& pose, const IndexedBand& band,
                    double probe_range_m) const;
  bool BandVisible(const Pose& pose, const IndexedBand& band) const;

 private:
  const Rig* rig_;
  double margin_px_;
  double range_m_;
  std::vector<Eigen::Isometry3d> T_cam_body_;
};

// Passes: runs of matched observations of one crossing.
struct Pass {
  int crossing = -1;
  std::vector<int> obs;
  double t0 = 0.0;
  double t1 = 0.0;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();  // median
  bool rejected = false;
};

// Evidence of one crossing end (or of nothing, unit -1): `strong` is
// what neither a database missing an end band nor an end band hidden in
// the images can fake (bare road where paint is predicted, a band in a
// gap of the crossing or beyond its band 1); `weak` is the rest (bands
// explained, bands beyond the crossing's last band).
struct Evidence {
  double weak = 0.0;
  double strong = 0.0;
};

// Aggregated margin of one hypothesis over another (MarginOver).
struct Margin {
  double raw = 0.0;        // aggregated score difference
  double both_ends = 0.0;  // without the evidence of the stronger end
  double strong = 0.0;     // of the strong evidence alone
};

// What the steps share: the inputs, the observations in the measured
// placement (step 1), their hypotheses, and the decisions as the steps
// make them. Indices `o` are observations, in input order.
struct MatchState {
  MatchState(const MatchInput& input, const MatchOptions& options)
      : input(input),
        options(options),
        index(*input.index),
        visibility(nullptr, 0.0, 0.0) {}

  const MatchInput& input;
  const MatchOptions& options;
  const RoadmarkIndex& index;
  Visibility visibility;

  std::vector<Obs> obs;
  std::vector<std::vector<Hypothesis>> hypotheses;
  std::vector<int> candidate_bands;  // per observation
  std::vector<int> chosen;           // hypothesis index or -1
  std::vector<bool> accepted;
  std::vector<bool> ambiguous;
  // Per observation refused by min_strong_margin alone: the band offsets
  // of its crossing that no strong evidence beat (continuity may rule them
  // out although it cannot single out one hypothesis among all).
  std::vector<std::vector<int>> unbeaten_offsets;
  std::set<int> inconsistent;  // refused by the continuity check
  std::vector<ObservationEvidence> evidence;
  std::vector<VertexMatch> matches;
  std::vector<DatabaseFault> faults;
  std::vector<UnrecognisedMark> unrecognised;
  std::vector<CrossingInView> crossings_in_view;
  std::vector<int> by_time;  // observation indices sorted by time
  // Per observation: [first, last) positions in by_time of its window.
  std::vector<std::pair<int, int>> window;
};

// --- 1. Hypotheses (band_matcher_hypotheses.cc) ----------------------------

// Fills obs, visibility (learning its margin and range from the data when
// the options leave them 0) and by_time.
void PrepareObservations(MatchState* state);
// The drift gate of one observation: max_drift_m, or more when the
// trajectory claims a larger sd.
double Gate(const MatchOptions& options, const Obs& obs);
// Fills hypotheses[o] and candidate_bands[o].
void GenerateHypotheses(int o, MatchState* state);
// The correction fitted on every band `eval` explains (from `start` when it
// explains none).
PoseCorrection Refine(const MatchState& state, const Obs& obs, const Eval& eval,
                      const PoseCorrection& start);

// --- 2. Evidence (band_matcher_evidence.cc) --------------------------------

// What one view shows under correction `c`.
Eval Evaluate(const MatchState& state, const Obs& obs, const PoseCorrection& c);
// Fills window and every hypothesis' aggregated score.
void Aggregate(MatchState* state);
// Score of correction `c` over the window of observation `o`: per view
// the hits and unexplained bands of the view's own hypothesis at `c`,
// plus the missing database bands counted per band (how, in
// band_matcher_evidence.cc). With `units`, the evidence by crossing end:
// key crossing * 2 + end, end 0 for the half of the crossing holding its
// first band, 1 for the other; -1 away from every crossing. Observed bands
// are placed with `placement`, so that two hypotheses attribute them alike.
double WindowEvidence(const MatchState& state, int o, const PoseCorrection& c,
                      const PoseCorrection& placement,
                      std::map<int, Evidence>* units);

// --- 3. Decision of each observation alone (band_matcher_decision.cc) ------

// Chooses the best hypothesis of `o` and accepts it, or refuses `o` (and
// says whether as ambiguous).
void DecideAlone(int o, MatchState* state);
// What `other` is with respect to `best` ("band offset +1 (1.00 m)",
// "crossing X also fits").
std::string DescribeAlternative(const RoadmarkIndex& index, const Obs& obs,
                                const Hypothesis& best,
                                const Hypothesis& other);

// --- 4. Continuity across crossings (band_matcher_continuity.cc) -----------

// Refuses the passes that disagree with more informative neighbours than
// agree.
void CheckContinuity(MatchState* state);
// Accepts ambiguous observations that the correction predicted from
// matched neighbours singles out.
void ResolveFromNeighbours(MatchState* state);
// Reports (and with refuse_shifted_crossings refuses) crossings whose
// correction departs from the one interpolated between neighbours.
void DetectShiftedCrossings(MatchState* state);

// --- 5. Vertex matches and findings (band_matcher_output.cc) ---------------

// Refuses accepted `o` when fewer than min_hit_bands bands fit after
// refinement (a hypothesis that fits only loosely); true when refused.
bool RefuseUnrefined(int o, MatchState* state);
// Appends the vertex matches of accepted `o` (or refuses it).
void EmitMatches(int o, MatchState* state);
void DetectFaults(MatchState* state);
// Moves the matches, evidence and faults into `result`, with a decision
// per observation and the summary's counts.
void Finish(MatchState* state, MatchResult* result);

}  // namespace band_matcher_internal
}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_BAND_MATCHER_INTERNAL_H_
