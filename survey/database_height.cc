#include "survey/database_height.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// A band's height and the trajectory sample nearest to it.
struct BandHeight {
  const RoadmarkBand* band = nullptr;
  int sample = 0;
  double offset_m = 0.0;  // band height - (sample height - IMU height)
};

// The EGM96 geoid's height above the WGS84 ellipsoid at `where` (m), from
// PROJ's egm96_15.gtx (Debian's proj-data); nullopt without the grid.
std::optional<double> Egm96Undulation(const Geodetic& where) {
  try {
    const CrsTransformer egm96(Crs("EPSG:4326+5773"));
    const double orthometric = egm96.FromWgs84(where).z();
    return where.h_m - orthometric;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::string Metres(double m) { return FormatFixed(m, 1) + " m"; }

}  // namespace

std::string DatabaseHeightOptions::Check() const {
  OptionCheck check;
  OPTION_GT(check, max_band_distance_m, 0.0);
  OPTION_GE(check, nominal_imu_height_m, 0.0);
  OPTION_GT(check, max_height_offset_m, 0.0);
  return check.problem();
}

std::string DatabaseHeightProblem(const Trajectory& trajectory,
                                  const std::string& trajectory_file,
                                  const RoadmarkDatabase& database,
                                  const LocalFrame& frame,
                                  const DatabaseHeightOptions& options) {
  std::vector<BandHeight> near;
  const int step = std::max(1, trajectory.size() / 5000);
  for (const RoadmarkBand& band : database.bands) {
    if (!band.height_known) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double height = 0.0;
    for (const Geodetic& corner : band.corners) {
      centre += 0.25 * frame.EnuFromGeodetic(corner);
      height += 0.25 * corner.h_m;
    }
    double best = std::numeric_limits<double>::infinity();
    int sample = -1;
    for (int i = 0; i < trajectory.size(); i += step) {
      const double d = (trajectory.poses()[i].p_enu - centre).head<2>().norm();
      if (d < best) best = d, sample = i;
    }
    if (sample < 0 || best > options.max_band_distance_m) continue;
    const double road = trajectory.samples()[sample].position.h_m -
                        options.nominal_imu_height_m;
    near.push_back({&band, sample, height - road});
  }
  if (near.empty()) return "";
  std::sort(near.begin(), near.end(),
            [](const BandHeight& a, const BandHeight& b) {
              return a.offset_m < b.offset_m;
            });
  const BandHeight& median = near[near.size() / 2];
  if (std::abs(median.offset_m) <= options.max_height_offset_m) return "";
  const TrajectorySample& sample = trajectory.samples()[median.sample];
  std::string problem =
      "its zebra bands lie a median of " + Metres(std::abs(median.offset_m)) +
      (median.offset_m < 0.0 ? " below" : " above") +
      " the road under the trajectory (" + std::to_string(near.size()) +
      " bands within " + Metres(options.max_band_distance_m) +
      " of it; crossing " + median.band->crossing_id + " band " +
      std::to_string(median.band->band) + " at h " +
      Metres(median.band->corners[0].h_m) + ", " + trajectory_file + " line " +
      std::to_string(sample.line) + " at h " + Metres(sample.position.h_m) +
      ", the INS about " + Metres(options.nominal_imu_height_m) +
      " above the road), more than " + Metres(options.max_height_offset_m) +
      "; no reconstructed band can match a band that far off";
  const std::optional<double> undulation = Egm96Undulation(sample.position);
  // Heights above sea level read as ellipsoidal: the bands sit the geoid's
  // height too low (a few metres: the local geoid model is not EGM96).
  if (undulation && std::abs(median.offset_m + *undulation) < 3.0) {
    problem +=
        ": the database's heights look like heights above sea level (the "
        "geoid lies " +
        Metres(*undulation) +
        " above the WGS84 ellipsoid here, EGM96) read as the ellipsoidal "
        "heights the trajectory has. Name the database's vertical datum in "
        "survey.yaml's roadmarks_crs as a compound CRS, its horizontal CRS "
        "plus its height's: e.g. EPSG:2154+5720 (Lambert-93, NGF-IGN69 "
        "heights, with IGN's grid in crs_grid_dirs), EPSG:2154+5773 or "
        "EPSG:4326+5773 (EGM96 heights)";
  } else {
    problem +=
        ": check the database's vertical datum (survey.yaml's "
        "roadmarks_crs) and the trajectory's heights (ellipsoidal)";
  }
  return problem;
}

}  // namespace zebrageo
