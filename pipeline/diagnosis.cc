#include "pipeline/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "survey/csv.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

std::string Cm(double m) { return FormatFixed(100.0 * m, 0) + " cm"; }

std::string Signed(double m) {
  return (m >= 0.0 ? "+" : "") + FormatFixed(m, 2);
}

}  // namespace

std::string DiagnosisOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, min_common_offset_m, 0.0);
  OPTION_GE(check, min_stated_sigmas, 0.0);
  OPTION_GT(check, max_spread_fraction, 0.0);
  OPTION_GE(check, min_spread_m, 0.0);
  OPTION_GE(check, min_crossings, 2);
  return check.problem();
}

std::optional<Diagnosis> DiagnoseCommonOffset(
    const std::vector<CrossingCorrection>& crossings,
    const std::string& roadmarks_file, const std::string& trajectory_file,
    const DiagnosisOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("DiagnosisOptions: " + problem);
  }
  if (static_cast<int>(crossings.size()) < options.min_crossings) {
    return std::nullopt;
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double stated_m = 0.0;
  for (const CrossingCorrection& c : crossings) {
    mean += c.correction_enu / crossings.size();
    stated_m = std::max(stated_m, c.stated_sd_enu.head<2>().norm());
  }
  const double offset_m = mean.head<2>().norm();
  if (offset_m < options.min_common_offset_m ||
      offset_m < options.min_stated_sigmas * stated_m) {
    return std::nullopt;
  }
  double spread_m = 0.0;
  for (const CrossingCorrection& c : crossings) {
    spread_m = std::max(spread_m, (c.correction_enu - mean).head<2>().norm());
  }
  if (spread_m >
      std::max(options.min_spread_m, options.max_spread_fraction * offset_m)) {
    return std::nullopt;
  }
  Diagnosis diagnosis;
  diagnosis.cause = "database_offset";
  diagnosis.message =
      "diagnosis: all " + std::to_string(crossings.size()) +
      " matched crossings moved the trajectory by one common offset, E " +
      Signed(mean.x()) + " N " + Signed(mean.y()) + " U " + Signed(mean.z()) +
      " m (" + Cm(offset_m) + " horizontally, each crossing within " +
      Cm(spread_m) + " of it), " +
      FormatFixed(offset_m / std::max(stated_m, 1e-3), 0) +
      " times the accuracy " + trajectory_file + " states (sd " + Cm(stated_m) +
      "): a drift that large and that constant is rarer than a datum or "
      "epoch mix-up; check that " +
      roadmarks_file +
      " is in WGS84 at the trajectory's epoch (not ETRF89/NAD83/GDA94, "
      "0.8 to 2 m off: name its CRS in survey.yaml's roadmarks_crs) and "
      "that the trajectory's datum is WGS84; if the database is right, the "
      "trajectory was that far off and the result stands";
  return diagnosis;
}

}  // namespace zebrageo
