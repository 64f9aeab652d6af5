// What the reconstruction and the image evidence of a simulated survey would
// give, synthesised from its truth without rendering (the geometry sweep,
// issue 17): reconstructed_bands.csv rows and the matcher's paint probe.
//
// Frames and units: the survey's ENU frame, body FRD, camera OpenCV; metres,
// radians, pixels. Reconstructed vertices are the TRUE band corners in the
// body frame of the TRUE pose plus noise, and their pixels the true corners
// projected with the TRUE camera poses plus noise; the matcher then places
// them with the MEASURED pose, as it does with the real stage's output.
//
// The synthesis must not flatter the matcher or the adjustment:
//  - a band is reconstructed in a stereo pair only when its four corners lie
//    in front of both cameras and project inside both images (with a
//    margin), and its centre is within max_range_m of the left camera;
//  - parked vehicles hide bands (ray-box tests from both cameras): a band
//    with one end hidden is reported with that end inferred from the
//    crossing (as the real stage does within max_inferred_range_m), any
//    other occlusion drops it;
//  - recall falls with range: near_recall up to near_range_m, falling
//    linearly to far_recall at far_range_m and staying there;
//  - now and then a band is cut short (a stain, worn paint: one end's
//    vertices lie inside the paint) or an end is not seen and inferred;
//  - vertex noise grows with range, mostly along the viewing ray (stereo
//    depth), with a part shared by the band's four vertices (its sides are
//    fitted as lines).
#ifndef ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_RECONSTRUCTION_H_
#define ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_RECONSTRUCTION_H_

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "registration/paint_probe.h"
#include "simulator/simulated_survey.h"
#include "survey/results.h"
#include "survey/trajectory.h"

namespace zebrageo::support {

struct ReconstructionModel {
  // Visibility: every corner at least this far inside both images, and this
  // far in front of both cameras; the band's centre within max_range_m of
  // the left camera (the real stage's max_band_range_m).
  double margin_px = 10.0;
  double min_depth_m = 1.0;
  double max_range_m = 15.05;
  // Recall of the bands in full view, by range of the band's centre.
  double near_recall = 0.99;
  double near_range_m = 8.0;
  double far_recall = 0.6;
  double far_range_m = 11.0;
  // Vertex noise (sd) along the viewing ray of the left camera at 5 m; it
  // grows as (range / 5 m)^range_exponent (1.5: 0.5 cm at 5 m, 2.6 cm at
  // 15 m). Across the ray: perpendicular_share of it, at least
  // min_sigma_m. shared_share of the variance is common to the band's four
  // vertices.
  double ray_sigma_at_5m_m = 0.005;
  double range_exponent = 1.5;
  double perpendicular_share = 0.3;
  double min_sigma_m = 0.002;
  double shared_share = 0.5;
  // Noise of the vertices' pixels (both images).
  double pixel_sigma_px = 0.3;
  // Per band seen: one end cut short by 0.25-1 m (its vertices lie inside
  // the paint), or one end not seen and inferred from the crossing.
  double cut_short_probability = 0.01;
  double hidden_end_probability = 0.02;
  // An inferred end: its vertices' sd along the band, the score factor, and
  // the range beyond which the real stage does not report such a band.
  double inferred_sigma_m = 0.03;
  double inferred_score_factor = 0.5;
  double max_inferred_range_m = 13.0;
  // Image evidence (paint probe): share of the probes that cannot tell
  // (shadows, low contrast) even where the truth is clear.
  double probe_unknown_share = 0.1;

  // A model drawn for one survey: far_recall in [0.2, 0.9], noise,
  // faults and probe dropouts at random (deterministic in `seed`).
  static ReconstructionModel Random(uint64_t seed);
  // Probability of reconstructing a band in full view at `range_m`.
  double RecallAt(double range_m) const;
  // "" or "field = value: must be ...".
  std::string Check() const;
  // The drawn values in short, for a sweep's log line.
  std::string Brief() const;
};

// What each reconstructed band is (by band_id).
struct SyntheticBandTruth {
  int world_band = -1;  // index into World::bands
  double range_m = 0.0;
  bool cut_short = false;
  bool inferred_end = false;
};

struct SyntheticReconstruction {
  std::vector<ReconstructedVertex> vertices;
  std::map<int64_t, SyntheticBandTruth> truth_of_band;
  // Band views in full view and range, hidden by vehicles (whole or at one
  // end), and reconstructed.
  int views_in_range = 0;
  int views_hidden = 0;
  int views_reconstructed = 0;
};

// The true pose of every exposure of the survey, by exposure_id.
std::map<int64_t, Pose> TruePoses(const sim::SimulatedSurvey& survey);

SyntheticReconstruction SynthesiseReconstruction(
    const sim::SimulatedSurvey& survey, const ReconstructionModel& model,
    uint64_t seed);

// True when the segment from `from` to `to` (ENU) passes through a parked
// vehicle of the world.
bool HiddenByVehicle(const sim::World& world, const Eigen::Vector3d& from,
                     const Eigen::Vector3d& to);

// The matcher's image evidence (MatchInput::paint_probe) from the truth:
// the database band, placed with the hypothesis' pose, is mapped through
// the TRUE pose to where the left camera of the first stereo pair really
// looks; over the middle half of the band, paint where a band or a line is
// painted, bare road where the street has no paint and nothing hides it,
// unknown where a vehicle hides it, out of the image, mixed, without seen
// bands to compare with, or in probe_unknown_share of the cases at random.
// `survey` must outlive the probe. Thread-compatible (const).
class TruthPaintProbe {
 public:
  TruthPaintProbe(const sim::SimulatedSurvey& survey,
                  const ReconstructionModel& model, uint64_t seed);

  PaintEvidence Classify(int64_t exposure_id, const Pose& pose,
                         const BandCornersEnu& band,
                         const std::vector<BandCornersEnu>& seen) const;

 private:
  bool IsPainted(const Eigen::Vector3d& p_enu, double s_hint) const;

  const sim::SimulatedSurvey& survey_;
  double unknown_share_ = 0.0;
  uint64_t seed_ = 0;
  std::map<int64_t, Pose> true_pose_;
  std::map<int64_t, double> s_of_exposure_;
};

}  // namespace zebrageo::support

#endif  // ZEBRAGEO_TESTS_SUPPORT_SYNTHETIC_RECONSTRUCTION_H_
