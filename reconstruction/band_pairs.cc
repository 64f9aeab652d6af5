#include "reconstruction/band_pairs.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "reconstruction/paint_gaps.h"
#include "survey/math_util.h"

namespace zebrageo {
namespace {

// Whether the paint between sides i (low) and j (high) is one band: no
// side between them where the paint ends (darkening) followed by one where
// it starts again (a side paired with the far edge of a lane line next to
// the band is not a band). [a0, a1] and [b0, b1]: their extents along
// their set's direction. `edge_between`: a lone edge lies between them (a
// shadow boundary running along the band, which must not hide the band).
bool OnePaint(const PlaneFrame& frame, const std::vector<LongSide>& sides,
              int i, int j, double a0, double a1, double b0, double b1,
              bool* edge_between) {
  const LongSide& a = sides[i];
  const LongSide& b = sides[j];
  const int n = static_cast<int>(sides.size());
  double first_end = 1e30;
  double last_start = -1e30;
  for (int k = 0; k < n; ++k) {
    const LongSide& s = sides[k];
    if (k == i || k == j || s.direction_set != a.direction_set) continue;
    if (s.lateral_m <= a.lateral_m + 0.05 ||
        s.lateral_m >= b.lateral_m - 0.05) {
      continue;
    }
    double s0, s1;
    SideExtent(frame, s, a.direction_2d, &s0, &s1);
    if (std::min(s1, std::min(a1, b1)) - std::max(s0, std::max(a0, b0)) <=
        0.0) {
      continue;
    }
    if (s.contrast < 0.0) first_end = std::min(first_end, s.lateral_m);
    if (s.contrast > 0.0) last_start = std::max(last_start, s.lateral_m);
  }
  *edge_between = first_end < 1e30 || last_start > -1e30;
  return !(first_end < last_start);
}

// Step 1: pairs of long sides, parallel, one band width apart,
// overlapping, with inverse gradients and the bright paint between them,
// cheapest first.
std::vector<BandCandidate> SidePairCandidates(
    const LongSideDetection& detection, const PlaneFrame& frame,
    const RoadRectification& rectification, const EdgeMap edges[2],
    const std::vector<LongSide>& sides, const ZebraSpecification& zebra,
    const BandOptions& options) {
  const int n = static_cast<int>(sides.size());
  std::vector<BandCandidate> candidates;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const LongSide& a = sides[i];
      const LongSide& b = sides[j];
      if (i == j || a.direction_set != b.direction_set) continue;
      if (!(a.lateral_m < b.lateral_m)) continue;
      if (std::acos(
              std::min(1.0, std::abs(a.direction_body.dot(b.direction_body)))) >
          options.max_side_angle_rad) {
        continue;
      }
      const double width = b.lateral_m - a.lateral_m;
      if (std::abs(width - zebra.band_width_m) > zebra.band_width_tolerance_m) {
        continue;
      }
      if (!(a.contrast > 0.0 && b.contrast < 0.0)) continue;
      double a0, a1, b0, b1;
      SideExtent(frame, a, a.direction_2d, &a0, &a1);
      SideExtent(frame, b, a.direction_2d, &b0, &b1);
      const double overlap = std::min(a1, b1) - std::max(a0, b0);
      if (overlap <
          options.min_side_overlap_fraction * std::min(a1 - a0, b1 - b0)) {
        continue;
      }
      BandCandidate c;
      if (!OnePaint(frame, sides, i, j, a0, a1, b0, b1, &c.edge_between)) {
        continue;
      }
      c.lo = i;
      c.hi = j;
      c.begin = std::max(a0, b0);
      c.end = std::min(a1, b1);
      // One piece of paint: the paint beside the crossing in line with a
      // band is cut off, and a row of squares is no band.
      if (options.cut_at_paint_gaps &&
          CutAtPaintGaps(detection.points_2d, frame, rectification, edges, a, b,
                         options, &c.begin, &c.end) > 0 &&
          c.end - c.begin < options.min_piece_widths * zebra.band_width_m) {
        continue;
      }
      // Longer than any band: the inner edge of a lane line and a kerb, or
      // a lane line's two edges and a gutter, running along the crossing.
      // Taken as one of its bands it would set the crossing's ends (the
      // extremities of its longest bands) far from the painted ones.
      if (c.end - c.begin >
          zebra.max_band_length_m + options.max_length_excess_m) {
        continue;
      }
      c.cost =
          std::abs(width - zebra.band_width_m) / zebra.band_width_tolerance_m -
          (c.end - c.begin) / zebra.min_band_length_m;
      candidates.push_back(c);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const BandCandidate& x, const BandCandidate& y) {
                     return x.cost < y.cost;
                   });
  return candidates;
}

// The cheapest candidates whose sides no cheaper one took; `side_used`
// marks the sides taken.
std::vector<BandCandidate> TakeCheapestPairs(
    const std::vector<BandCandidate>& candidates,
    std::vector<char>* side_used) {
  std::vector<BandCandidate> pairs;
  for (const BandCandidate& c : candidates) {
    if ((*side_used)[c.lo] || (*side_used)[c.hi]) continue;
    (*side_used)[c.lo] = (*side_used)[c.hi] = 1;
    pairs.push_back(c);
  }
  return pairs;
}

// A band with an edge along it (a shadow boundary, or a lane line and its
// kerb lit between two shadows) is kept only beside other bands of a
// crossing.
std::vector<BandCandidate> DropLoneBandsWithEdges(
    const std::vector<LongSide>& sides, const std::vector<BandCandidate>& pairs,
    const ZebraSpecification& zebra, const BandOptions& options) {
  std::vector<BandCandidate> kept;
  for (const BandCandidate& c : pairs) {
    int neighbours = 0;
    const LongSide& a = sides[c.lo];
    const double centre = 0.5 * (a.lateral_m + sides[c.hi].lateral_m);
    for (const BandCandidate& o : pairs) {
      const LongSide& b = sides[o.lo];
      if (o.edge_between || b.direction_set != a.direction_set) continue;
      const double other = 0.5 * (b.lateral_m + sides[o.hi].lateral_m);
      if (&o != &c &&
          std::abs(other - centre) <=
              options.max_crossing_gap_m + 2.0 * zebra.band_width_m &&
          std::min(c.end, o.end) - std::max(c.begin, o.begin) > 0.0) {
        ++neighbours;
      }
    }
    if (!c.edge_between || neighbours >= 2) kept.push_back(c);
  }
  return kept;
}

// Union-find root.
int Root(std::vector<int>* parent, int i) {
  while ((*parent)[i] != i) i = (*parent)[i] = (*parent)[(*parent)[i]];
  return i;
}

// Step 2: crossings, bands of one direction side by side. The crossing
// index of each pair, numbered in the order of their first pair.
std::vector<int> GroupCrossings(const std::vector<LongSide>& sides,
                                const std::vector<BandCandidate>& pairs,
                                const BandOptions& options) {
  const int m = static_cast<int>(pairs.size());
  std::vector<int> parent(m);
  std::iota(parent.begin(), parent.end(), 0);
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      const LongSide& a_lo = sides[pairs[i].lo];
      const LongSide& b_lo = sides[pairs[j].lo];
      if (a_lo.direction_set != b_lo.direction_set) continue;
      const double a_hi = sides[pairs[i].hi].lateral_m;
      const double b_hi = sides[pairs[j].hi].lateral_m;
      const double gap = std::max(b_lo.lateral_m - a_hi, a_lo.lateral_m - b_hi);
      if (gap > options.max_crossing_gap_m) continue;
      // The bands themselves overlap along their direction, not only
      // their sides: a side may run on along a lane line, and a pair of
      // lines before the crossing would join it and set its ends.
      if (std::min(pairs[i].end, pairs[j].end) -
              std::max(pairs[i].begin, pairs[j].begin) <=
          0.0) {
        continue;
      }
      parent[Root(&parent, i)] = Root(&parent, j);
    }
  }
  std::vector<int> crossing_of(m);
  std::vector<int> label(m, -1);
  int next_label = 0;
  for (int i = 0; i < m; ++i) {
    const int root = Root(&parent, i);
    if (label[root] < 0) label[root] = next_label++;
    crossing_of[i] = label[root];
  }
  return crossing_of;
}

// Least-squares line y = a + b x through the points (p[0], p[index]):
// {a, b}; b = 0 when the x spread is below 1 cm.
std::array<double, 2> LinearFit(const std::vector<std::array<double, 3>>& p,
                                int index) {
  double mean_x = 0.0, mean_y = 0.0;
  for (const auto& q : p) {
    mean_x += q[0];
    mean_y += q[index];
  }
  mean_x /= static_cast<double>(p.size());
  mean_y /= static_cast<double>(p.size());
  double sxx = 0.0, sxy = 0.0;
  for (const auto& q : p) {
    sxx += (q[0] - mean_x) * (q[0] - mean_x);
    sxy += (q[0] - mean_x) * (q[index] - mean_y);
  }
  const double b = sxx > 1e-4 * static_cast<double>(p.size()) ? sxy / sxx : 0.0;
  return {mean_y - b * mean_x, b};
}

// The regular pattern of a crossing's seen bands, for CompleteCrossings.
struct CrossingPattern {
  std::vector<double> centres;  // lateral band centres, ascending
  double width = 0.0;           // median band width
  double width_sigma = 0.0;     // spread of the widths
  double period = 0.0;          // median spacing of neighbouring bands
  // Begin and end of the bands along them, linear in the lateral position
  // (LinearFit).
  std::array<double, 2> begin_line = {0.0, 0.0};
  std::array<double, 2> end_line = {0.0, 0.0};
  double min_contrast = 0.0;   // half the median contrast of the sides
  double median_length = 0.0;  // of the sides
  int set = -1;
  Eigen::Vector3d direction_body = Eigen::Vector3d::Zero();
  Eigen::Vector2d along = Eigen::Vector2d::UnitX();
};

// The pattern of crossing c from its first m pairs; false when it has too
// few bands to be trusted or is not regular.
bool MeasureCrossingPattern(const BandPairs& bands, int m, int c,
                            const ZebraSpecification& zebra,
                            const BandOptions& options,
                            CrossingPattern* pattern) {
  std::vector<double> widths, contrasts, lengths;
  std::vector<std::array<double, 3>> extents;  // (centre, begin, end)
  std::vector<double>& centres = pattern->centres;
  for (int i = 0; i < m; ++i) {
    if (bands.crossing_of[i] != c) continue;
    const BandCandidate& pair = bands.pairs[i];
    const LongSide& lo = bands.sides[pair.lo];
    const LongSide& hi = bands.sides[pair.hi];
    centres.push_back(0.5 * (lo.lateral_m + hi.lateral_m));
    extents.push_back({centres.back(), pair.begin, pair.end});
    widths.push_back(hi.lateral_m - lo.lateral_m);
    contrasts.push_back(std::abs(lo.contrast));
    contrasts.push_back(std::abs(hi.contrast));
    lengths.push_back(lo.Length());
    lengths.push_back(hi.Length());
    pattern->set = lo.direction_set;
    pattern->direction_body = lo.direction_body;
    pattern->along = lo.direction_2d;
  }
  // A regular pattern needs a few bands to be trusted.
  if (static_cast<int>(centres.size()) < options.completion_min_bands) {
    return false;
  }
  std::sort(centres.begin(), centres.end());
  const double width = Median(widths);
  double width_spread = 0.0;
  for (double w : widths) width_spread += (w - width) * (w - width);
  pattern->width = width;
  pattern->width_sigma =
      std::max(options.completion_min_sigma_m,
               std::sqrt(width_spread / static_cast<double>(widths.size())));
  // Band period: the median spacing of neighbouring bands, ignoring
  // spacings across a missing band.
  std::vector<double> spacings;
  for (size_t k = 1; k < centres.size(); ++k) {
    spacings.push_back(centres[k] - centres[k - 1]);
  }
  const double smallest = *std::min_element(spacings.begin(), spacings.end());
  std::vector<double> regular;
  for (double d : spacings) {
    if (d < 1.5 * smallest) regular.push_back(d);
  }
  const double period = Median(regular);
  pattern->period = period;
  if (!(period > width + 0.2) ||
      std::abs(width - zebra.band_width_m) > zebra.band_width_tolerance_m) {
    return false;
  }
  bool irregular = false;
  for (double d : regular) {
    irregular =
        irregular || std::abs(d - period) > options.completion_tolerance_m;
  }
  if (irregular) return false;
  // A skewed crossing's bands are offset along the band: its ends are
  // lines across the bands, begin and end linear in the lateral position.
  pattern->begin_line = LinearFit(extents, 1);
  pattern->end_line = LinearFit(extents, 2);
  pattern->min_contrast = 0.5 * Median(contrasts);
  pattern->median_length = Median(lengths);
  return true;
}

// The best unused long side for each empty slot of the pattern (slot index
// from the first band): slot -> (residual, side).
std::map<int, std::pair<double, int>> SidesOfEmptySlots(
    const PlaneFrame& frame, const std::vector<LongSide>& sides,
    const std::vector<char>& side_used, const CrossingPattern& pattern,
    const BandOptions& options) {
  const int n = static_cast<int>(side_used.size());
  const std::vector<double>& centres = pattern.centres;
  const double period = pattern.period;
  std::map<int, std::pair<double, int>> best;
  for (int k = 0; k < n; ++k) {
    const LongSide& s = sides[k];
    if (side_used[k] || s.direction_set != pattern.set) continue;
    if (std::acos(std::min(
            1.0, std::abs(s.direction_body.dot(pattern.direction_body)))) >
        options.max_side_angle_rad) {
      continue;
    }
    if (std::abs(s.contrast) < pattern.min_contrast) continue;
    // Paint brightens towards +lateral at the low side of a band.
    const double centre =
        s.lateral_m + (s.contrast > 0.0 ? 0.5 : -0.5) * pattern.width;
    // Within the crossing along the band, and no longer than its bands'
    // sides (a lane line is; a side is longer than its band's overlap
    // with the other side).
    const double begin = pattern.begin_line[0] + pattern.begin_line[1] * centre;
    const double end = pattern.end_line[0] + pattern.end_line[1] * centre;
    double s0, s1;
    SideExtent(frame, s, pattern.along, &s0, &s1);
    if (s1 - s0 >
            pattern.median_length + options.completion_tolerance_m * 5.0 ||
        std::min(s1, end) - std::max(s0, begin) <
            options.min_side_overlap_fraction * (s1 - s0)) {
      continue;
    }
    const double position = (centre - centres.front()) / period;
    const int slot = static_cast<int>(std::lround(position));
    const double residual = std::abs(position - slot) * period;
    if (residual > options.completion_tolerance_m) continue;
    // One slot beyond the outer bands at most; not an occupied slot.
    const int last = static_cast<int>(
        std::lround((centres.back() - centres.front()) / period));
    if (slot < -1 || slot > last + 1) continue;
    bool occupied = false;
    for (double x : centres) {
      occupied = occupied ||
                 std::abs(x - (centres.front() + slot * period)) < 0.5 * period;
    }
    if (occupied) continue;
    auto it = best.find(slot);
    if (it == best.end() || residual < it->second.first) {
      best[slot] = {residual, k};
    }
  }
  return best;
}

// Appends to `bands` the band of crossing c made of the seen side k and a
// side inferred one band width away. `m`: the seen pairs.
void AddCompletedBand(const PlaneFrame& frame, int c, int k, int m,
                      const CrossingPattern& pattern, BandPairs* bands) {
  std::vector<LongSide>& sides = bands->sides;
  std::vector<BandCandidate>& pairs = bands->pairs;
  const LongSide seen = sides[k];
  LongSide other = seen;
  const double width = pattern.width;
  const double shift = seen.contrast > 0.0 ? width : -width;
  other.lateral_m = seen.lateral_m + shift;
  other.point_body =
      seen.point_body + shift * frame.Direction3d(seen.Normal2d());
  other.contrast = -seen.contrast;
  // The band plane is fitted on the seen side and the nearest band.
  int nearest = -1;
  double nearest_distance = 1e30;
  for (int i = 0; i < m; ++i) {
    if (bands->crossing_of[i] != c) continue;
    const double d = std::abs(sides[pairs[i].lo].lateral_m - other.lateral_m);
    if (d < nearest_distance) {
      nearest_distance = d;
      nearest = i;
    }
  }
  other.support.clear();
  for (int s : {pairs[nearest].lo, pairs[nearest].hi}) {
    const std::vector<int>& support = sides[s].support;
    other.support.insert(other.support.end(), support.begin(), support.end());
  }
  const int index = static_cast<int>(sides.size());
  sides.push_back(other);
  BandCandidate candidate;
  const bool seen_is_lo = seen.contrast > 0.0;
  candidate.lo = seen_is_lo ? k : index;
  candidate.hi = seen_is_lo ? index : k;
  candidate.inferred = seen_is_lo ? 1 : 0;
  candidate.inferred_sigma_m = std::hypot(
      pattern.width_sigma,
      seen.lateral_rms_m / std::sqrt(static_cast<double>(
                               std::max<size_t>(1, seen.support.size()))));
  double s0, s1;
  SideExtent(frame, seen, pattern.along, &s0, &s1);
  candidate.begin = s0;
  candidate.end = s1;
  pairs.push_back(candidate);
  bands->crossing_of.push_back(c);
}

// Step 2b, completes the crossings: a long side that no band took, lying
// where the crossing's regular pattern expects a band side (one band width
// from the slot of a missing band, with the polarity of that side), becomes
// a band whose other side is inferred: the same direction, one median band
// width of the crossing away. This recovers bands whose other side is
// hidden by a parked vehicle or merged with a lane line painted across the
// band's end. The transversal sides are still searched in both images, and
// the band still has to pass every check after that; its inferred side
// gets the spread of the crossing's widths as standard deviation.
void CompleteCrossings(const PlaneFrame& frame, const ZebraSpecification& zebra,
                       const BandOptions& options,
                       const std::vector<char>& side_used, BandPairs* bands) {
  const int m = static_cast<int>(bands->pairs.size());
  for (int c = 0; c < bands->crossings; ++c) {
    CrossingPattern pattern;
    if (!MeasureCrossingPattern(*bands, m, c, zebra, options, &pattern)) {
      continue;
    }
    const std::map<int, std::pair<double, int>> best =
        SidesOfEmptySlots(frame, bands->sides, side_used, pattern, options);
    for (const auto& [slot, entry] : best) {
      const int k = entry.second;
      VLOG(2) << "crossing " << c << ": side " << k << " at "
              << bands->sides[k].lateral_m << " completes slot " << slot
              << " (width " << pattern.width << ", period " << pattern.period
              << ")";
      AddCompletedBand(frame, c, k, m, pattern, bands);
    }
  }
}

}  // namespace

BandPairs FindBandPairs(const LongSideDetection& detection,
                        const PlaneFrame& frame,
                        const RoadRectification& rectification,
                        const EdgeMap edges[2], const ZebraSpecification& zebra,
                        const BandOptions& options, BandModelingDebug* debug) {
  BandPairs bands;
  bands.sides = detection.sides;
  const int n = static_cast<int>(bands.sides.size());
  std::vector<char> side_used(n, 0);
  bands.pairs = DropLoneBandsWithEdges(
      bands.sides,
      TakeCheapestPairs(SidePairCandidates(detection, frame, rectification,
                                           edges, bands.sides, zebra, options),
                        &side_used),
      zebra, options);
  if (debug != nullptr) {
    for (const BandCandidate& c : bands.pairs) {
      for (int s : {c.lo, c.hi}) {
        Eigen::Vector2d a, b;
        if (rectification.ProjectToRectified(0, bands.sides[s].Begin(), &a) &&
            rectification.ProjectToRectified(0, bands.sides[s].End(), &b)) {
          debug->band_pairs.push_back({a, b});
        }
      }
    }
  }
  bands.crossing_of = GroupCrossings(bands.sides, bands.pairs, options);
  bands.seen = static_cast<int>(bands.pairs.size());
  bands.crossings = bands.seen == 0
                        ? 0
                        : *std::max_element(bands.crossing_of.begin(),
                                            bands.crossing_of.end()) +
                              1;
  if (options.complete_crossings) {
    CompleteCrossings(frame, zebra, options, side_used, &bands);
  }
  return bands;
}

}  // namespace zebrageo
