// Crossing designs (issue 52): the ladder design's bars and the band sizes
// drawn per crossing.
#include <algorithm>
#include <cmath>

#include "simulator/noise.h"
#include "simulator/world.h"
#include "simulator/world_internal.h"

namespace zebrageo::sim {
namespace world_internal {

CrossingDesignDraw DrawCrossingDesign(const SimulationOptions& options,
                                      std::mt19937_64* rng) {
  // Every draw is made whatever the options: the next crossing's draws
  // stay where they were.
  const double width =
      Uniform(rng, options.min_band_width_m, options.max_band_width_m);
  const double gap =
      Uniform(rng, options.min_band_gap_m, options.max_band_gap_m);
  const bool ladder = Bernoulli(rng, options.ladder_probability);
  const double bar = Uniform(rng, options.min_ladder_bar_width_m,
                             options.max_ladder_bar_width_m);
  CrossingDesignDraw draw;
  if (options.band_sizes_per_crossing) {
    draw.band_width_m = width;
    draw.band_gap_m = gap;
  } else {
    draw.band_width_m = options.band_width_m;
    draw.band_gap_m = options.band_gap_m;
  }
  draw.ladder_bar_width_m = ladder ? bar : 0.0;
  return draw;
}

}  // namespace world_internal

bool InLadderBar(const Crossing& crossing, double o, double a) {
  const double bar = crossing.ladder_bar_width_m;
  if (bar <= 0.0 || crossing.num_street_bands <= 0) return false;
  // The bars join the painted bands' ends: from the first band's outer
  // long side to the last painted band's.
  const double o_lo = crossing.first_offset_m;
  const double o_hi = crossing.first_offset_m +
                      (crossing.num_street_bands - 1) * crossing.band_period_m +
                      crossing.band_width_m;
  if (o < o_lo || o > o_hi) return false;
  const double half = 0.5 * crossing.band_length_m;
  const double beyond = std::abs(a) - half;
  return beyond >= 0.0 && beyond <= bar;
}

}  // namespace zebrageo::sim
