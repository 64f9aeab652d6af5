#include "reconstruction/hidden_ends.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

namespace zebrageo {

std::vector<CrossingEndLines> FitCrossingEndLines(
    const std::vector<Band>& bands, const std::vector<LongSide>& sides,
    const PlaneFrame& frame, int crossings, const BandOptions& options) {
  std::vector<CrossingEndLines> ends(crossings);
  for (int c = 0; c < crossings; ++c) {
    for (int e = 0; e < 2; ++e) {
      std::vector<Eigen::Vector2d> points;
      Eigen::Vector2d across = Eigen::Vector2d::UnitY();
      for (const Band& band : bands) {
        if (band.crossing != c || band.inferred_side >= 0) continue;
        const Eigen::Vector2d a =
            frame.To2d(band.vertices_body[e == 0 ? 0 : 3]);
        const Eigen::Vector2d b =
            frame.To2d(band.vertices_body[e == 0 ? 1 : 2]);
        points.push_back(a);
        points.push_back(b);
        across = sides[band.sides[0]].Normal2d();
        ends[c].lateral_range[0] =
            std::min(ends[c].lateral_range[0], a.dot(across));
        ends[c].lateral_range[1] =
            std::max(ends[c].lateral_range[1], b.dot(across));
      }
      if (static_cast<int>(points.size()) < 2 * options.completion_min_bands) {
        continue;
      }
      ends[c].lines[e] = FitPlaneLine(points, across);
      const Eigen::Vector2d normal(-ends[c].lines[e].direction.y(),
                                   ends[c].lines[e].direction.x());
      double sum_squares = 0.0;
      for (const Eigen::Vector2d& p : points) {
        sum_squares += std::pow((p - ends[c].lines[e].point).dot(normal), 2);
      }
      const double rms =
          std::sqrt(sum_squares / static_cast<double>(points.size() - 2));
      VLOG(2) << "crossing " << c << " end " << e << ": line through "
              << points.size() / 2 << " bands, rms " << rms;
      ends[c].rms[e] = rms;
      if (rms <= options.hidden_end_max_rms_m) {
        ends[c].sigma[e] = std::max(options.completion_min_sigma_m, 2.0 * rms);
      }
    }
  }
  return ends;
}

void InferHiddenEnds(const BandContext& context,
                     const std::vector<int>& without_transversal,
                     const std::vector<Eigen::Vector2d>& crossing_direction,
                     const std::vector<char>& has_direction,
                     std::vector<Band>* bands) {
  const PlaneFrame& frame = context.frame;
  const BandOptions& options = context.options;
  const ZebraSpecification& zebra = context.zebra;
  const std::vector<LongSide>& sides = context.bands.sides;
  const std::vector<BandCandidate>& pairs = context.bands.pairs;
  const std::vector<int>& crossing_of = context.bands.crossing_of;
  const std::vector<CrossingEndLines> ends = FitCrossingEndLines(
      *bands, sides, frame, context.bands.crossings, options);
  for (int i : without_transversal) {
    const int c = crossing_of[i];
    if (ends[c].rms[0] < 0.0 || ends[c].rms[1] < 0.0) continue;
    // Next to the seen bands: at most one band period out of them.
    const LongSide& lo = sides[pairs[i].lo];
    const LongSide& hi = sides[pairs[i].hi];
    const Eigen::Vector2d across = lo.Normal2d();
    const double reach = 2.5 * zebra.band_width_m;
    const double lateral_lo = frame.To2d(lo.point_body).dot(across);
    const double lateral_hi = frame.To2d(hi.point_body).dot(across);
    if (lateral_lo < ends[c].lateral_range[0] - reach ||
        lateral_hi > ends[c].lateral_range[1] + reach) {
      continue;
    }
    for (int e = 0; e < 2; ++e) {
      if (ends[c].sigma[e] < 0.0) continue;  // not reliable
      KnownEnd known[2];
      known[e].line = &ends[c].lines[e];
      known[e].sigma_m = ends[c].sigma[e];
      known[1 - e].expected = &ends[c].lines[1 - e];
      if (has_direction[c]) known[1 - e].direction = &crossing_direction[c];
      Band band;
      if (ModelBand(context, i, known, nullptr, &band) != BandOutcome::kBand) {
        continue;
      }
      // The seen end on the crossing's line of that end.
      const PlaneLine& other = ends[c].lines[1 - e];
      const Eigen::Vector2d normal(-other.direction.y(), other.direction.x());
      double worst = 0.0;
      for (int v :
           e == 0 ? std::array<int, 2>{2, 3} : std::array<int, 2>{0, 1}) {
        worst = std::max(
            worst,
            std::abs(
                (frame.To2d(band.vertices_body[v]) - other.point).dot(normal)));
      }
      VLOG(2) << "band " << i << ": hidden end " << e << ", seen end " << worst
              << " m off the crossing's line";
      if (worst >
          std::max(options.hidden_end_max_offset_m, 3.0 * ends[c].rms[1 - e])) {
        continue;
      }
      bands->push_back(band);
      break;
    }
  }
}

}  // namespace zebrageo
