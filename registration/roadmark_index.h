// The road-mark database in the survey's working frame: bands reprojected to
// ENU, grouped into crossings, with an R-tree over the bands' footprints.
//
// Frames and units: `enu` is the survey's LocalFrame (x east, y north, z up),
// metres. 2D quantities (Eigen::Vector2d) are the east/north components; the
// matcher works in the horizontal plane. Directions are unit vectors; an
// "axis" is a direction up to sign (a band has no front or back).
//
// Crossing geometry, as a photogrammetrist would read it off the map:
//   band_axis    the bands' long direction (along the road the vehicle drives)
//   across_axis  the direction of increasing band number, perpendicular to
//                band_axis (the 1 m periodicity of a zebra lies along it)
//   spacing_m    centre-to-centre distance of consecutive band numbers,
//                measured along across_axis (about 1.0 m)
//   skew_rad     angle between the line through the band centres and
//                across_axis: 0 for a square crossing, the parallelogram's
//                angle for a skewed one (each band is shifted along the road)
#ifndef ZEBRAGEO_REGISTRATION_ROADMARK_INDEX_H_
#define ZEBRAGEO_REGISTRATION_ROADMARK_INDEX_H_

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "survey/geodesy.h"
#include "survey/roadmarks.h"

namespace zebrageo {

struct IndexedBand {
  int source_index = 0;  // index in RoadmarkDatabase::bands
  int crossing = 0;      // index in RoadmarkIndex::crossings()
  std::string crossing_id;
  int band = 0;  // 1-based band number of the database
  std::array<Eigen::Vector3d, 4> corners_enu;  // the file's ring order
  Eigen::Vector2d centre_enu = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis_enu = Eigen::Vector2d::UnitX();  // long sides, unit
  double length_m = 0.0;  // mean of the two long sides
  double width_m = 0.0;   // area / length (perpendicular width)
  double sigma_xy_m = 0.0;
  double sigma_z_m = 0.0;
  // A band the database's own numbering says exists but that it does not
  // hold (a crossing numbered from 3 has bands 1 and 2 in the street; one
  // numbered 1, 2, 4 lacks band 3): its corners extrapolated from the
  // nearest held band by the crossing's period. Never a control point
  // (source_index -1), but a hypothesis that puts paint there must find
  // paint there, and an observed band there is explained.
  bool implied = false;
};

struct IndexedCrossing {
  std::string crossing_id;
  std::vector<int> bands;  // indices in RoadmarkIndex::bands(), by band number
  Eigen::Vector2d centre_enu = Eigen::Vector2d::Zero();  // mean band centre
  Eigen::Vector2d band_axis = Eigen::Vector2d::UnitX();
  Eigen::Vector2d across_axis = Eigen::Vector2d::UnitY();
  double spacing_m = 1.0;
  double skew_rad = 0.0;
  double band_length_m = 0.0;  // median over the bands
  double band_width_m = 0.0;   // median over the bands
  int first_band = 0;          // smallest band number
  int last_band = 0;           // largest band number
  // Band numbers absent between first_band and last_band (the database
  // lost them, or the crossing has a gap).
  std::vector<int> missing_band_numbers;
  // Runs of two or more consecutive absent numbers: a refuge island's
  // places (SURVEY_FORMAT.md: a crossing an island interrupts may skip
  // them), where nothing is painted. Not in missing_band_numbers, so no
  // band is implied there and a band seen there contradicts the fit
  // (issue 52: a band of one half never takes the other half's id).
  std::vector<int> island_band_numbers;
  // The implied bands (indices in RoadmarkIndex::bands()): numbers 1 ..
  // first_band - 1 and missing_band_numbers, where the period is known
  // (at least two held bands).
  std::vector<int> implied_bands;
  // Centres of the first and last bands: the crossing's ends.
  Eigen::Vector2d first_end_enu = Eigen::Vector2d::Zero();
  Eigen::Vector2d last_end_enu = Eigen::Vector2d::Zero();
  // Radius of the circle around centre_enu holding every corner.
  double radius_m = 0.0;

  // Coordinates of an ENU point in the crossing's frame: x along band_axis,
  // y along across_axis, origin at centre_enu.
  Eigen::Vector2d ToCrossing(const Eigen::Vector2d& p_enu) const;
};

// Immutable once built; queries are const and thread-compatible.
class RoadmarkIndex {
 public:
  // An empty index.
  RoadmarkIndex();
  // Reprojects every band of `database` into `frame` and builds the index
  // (R-tree bulk load, O(n log n)). Bands of one crossing_id form a crossing.
  RoadmarkIndex(const RoadmarkDatabase& database, const LocalFrame& frame);
  ~RoadmarkIndex();
  RoadmarkIndex(RoadmarkIndex&&) noexcept;
  RoadmarkIndex& operator=(RoadmarkIndex&&) noexcept;

  // The database's bands first (num_database_bands() of them, in the
  // database's order), then the implied ones.
  const std::vector<IndexedBand>& bands() const;
  int num_database_bands() const;
  const std::vector<IndexedCrossing>& crossings() const;
  // Index of the crossing named `crossing_id`, or -1.
  int FindCrossing(const std::string& crossing_id) const;

  // Appends to `bands` (cleared first) the indices of the bands whose
  // footprint's bounding box comes within `radius_m` of `point_enu`.
  void BandsWithin(const Eigen::Vector2d& point_enu, double radius_m,
                   std::vector<int>* bands) const;
  // The same for crossings: every crossing with a band within `radius_m`,
  // each once, ascending.
  void CrossingsWithin(const Eigen::Vector2d& point_enu, double radius_m,
                       std::vector<int>* crossings) const;
  // The band whose footprint box is nearest to `point_enu`, or -1 if empty.
  int NearestBand(const Eigen::Vector2d& point_enu) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Shape of a band given by 4 corners in order around it (either sense):
// centre, unit long axis, mean long-side length and perpendicular width.
struct BandShape {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis = Eigen::Vector2d::UnitX();
  double length_m = 0.0;
  double width_m = 0.0;
};
BandShape ShapeOfBand(const std::array<Eigen::Vector2d, 4>& corners);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_ROADMARK_INDEX_H_
