// Diagnosis (issue 48): when a stage's result is suspicious or empty, the
// likeliest cause named from the evidence, with the file or key to check.
// Input errors beyond doubt are refused when the survey is loaded
// (survey/); what remains here is a plausible survey whose evidence points
// at a mistake: a warning, for stderr and report.json.
//
// A database offset: a datum or epoch mix-up (ETRF89 against ITRF/WGS84,
// about 0.8 m in Europe today; NAD83 1 to 2 m; GDA94 1.8 m) moves every
// crossing of the database by one vector. The adjustment then moves the
// trajectory by that vector at every crossing: the control agrees with
// itself, so neither the blunder tests nor the never-worse guard (which
// measures against the database) can see it. Only its size, far beyond
// what the trajectory claims, and its constancy give it away.
//
// Plain data in and out. Frames: ENU metres of the survey's origin.
#ifndef ZEBRAGEO_PIPELINE_DIAGNOSIS_H_
#define ZEBRAGEO_PIPELINE_DIAGNOSIS_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace zebrageo {

// The adjustment's correction of the trajectory (adjusted minus input
// position) at a matched crossing, and the accuracy the trajectory states
// there.
struct CrossingCorrection {
  std::string crossing_id;
  double time_s = 0.0;
  Eigen::Vector3d correction_enu = Eigen::Vector3d::Zero();
  Eigen::Vector3d stated_sd_enu = Eigen::Vector3d::Zero();
};

struct DiagnosisOptions {
  // A common horizontal correction at least this large (m) is suspicious:
  // the field cases' GNSS/INS biases are 0.26 to 0.48 m, datum and epoch
  // mix-ups 0.8 to 2 m.
  double min_common_offset_m = 0.6;
  // ... and at least this many times the stated horizontal sd.
  double min_stated_sigmas = 5.0;
  // "Common": every crossing's correction within this fraction of the
  // offset's length (or 0.1 m) of their mean.
  double max_spread_fraction = 0.25;
  double min_spread_m = 0.1;
  // Fewer crossings say nothing about constancy.
  int min_crossings = 2;

  std::string Check() const;
};

struct Diagnosis {
  std::string cause;    // e.g. "database_offset"
  std::string message;  // names the evidence and what to check
};

// The database offset's diagnosis, or nullopt. Throws
// std::invalid_argument when options.Check() fails.
std::optional<Diagnosis> DiagnoseCommonOffset(
    const std::vector<CrossingCorrection>& crossings,
    const std::string& roadmarks_file, const std::string& trajectory_file,
    const DiagnosisOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_DIAGNOSIS_H_
