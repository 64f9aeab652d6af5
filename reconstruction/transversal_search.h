// The search space of a band's transversal sides (Soheilian et al.,
// section 5.1): the approximate transversal sides of each crossing, lines
// of the plane frame fitted on the extremities of its longer bands, around
// which each band's ends are searched (BandOptions::transversal_search_m on
// each side).
//
// Frames: the plane frame of long_sides.h (metres).
#ifndef ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SEARCH_H_
#define ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SEARCH_H_

#include <Eigen/Core>
#include <vector>

#include "reconstruction/band.h"
#include "reconstruction/band_pairs.h"

namespace zebrageo {

// A 2D line of the plane frame: point + t * direction.
struct PlaneLine {
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d::UnitX();
};

// TLS line through 2D points; when they are fewer than 2 or spread less
// than 0.3 m, the line through their mean along `fallback`.
PlaneLine FitPlaneLine(const std::vector<Eigen::Vector2d>& points,
                       const Eigen::Vector2d& fallback);

// Robust line through the band extremities of a crossing: the line through
// two of them (at least 0.3 m apart, within 40 degrees of `fallback`, the
// perpendicular to the bands) with the most points within 0.1 m, refitted
// on those. A band cut short by an occlusion or a wrongly paired side is an
// outlier. One point, or none qualifying: the line through the median
// point along `fallback`.
PlaneLine FitRobustPlaneLine(const std::vector<Eigen::Vector2d>& points,
                             const Eigen::Vector2d& fallback);

// Point of `line` at lateral coordinate `lateral` (x . normal), shifted by
// `shift` along the band direction.
Eigen::Vector2d AtLateral(const PlaneLine& line, const Eigen::Vector2d& along,
                          const Eigen::Vector2d& normal, double lateral,
                          double shift);

// The approximate transversal sides of each crossing of `bands`, at the
// begin and at the end of its bands: robust lines (FitRobustPlaneLine)
// through the ends of the overlaps of its seen bands at least
// extremity_length_fraction of its longest, in the middle of each band.
struct TransversalSearch {
  std::vector<PlaneLine> begin_lines;  // one per crossing
  std::vector<PlaneLine> end_lines;
};
// `excluded` (empty, or one flag per pair): pairs whose extremities do not
// vote (longer than their crossing's, band_modeling.cc).
TransversalSearch ApproximateTransversalSides(
    const BandPairs& bands, const BandOptions& options,
    const std::vector<char>& excluded = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_TRANSVERSAL_SEARCH_H_
