#include "campaign/block_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace zebrageo {
namespace {

// [start - view, end + margin]: where a block boundary would see the
// crossing only in part (the cameras look forward).
struct Zone {
  double lo = 0.0;
  double hi = 0.0;
};
Zone ViewZone(const CrossingSpan& span, const PlanOptions& options) {
  return {span.start_m - options.crossing_view_m - options.crossing_margin_m,
          span.end_m + options.crossing_margin_m};
}

int CentresInside(const std::vector<CrossingSpan>& spans, double lo,
                  double hi) {
  int n = 0;
  for (const CrossingSpan& s : spans)
    n += s.centre_m() >= lo && s.centre_m() <= hi;
  return n;
}

// Moves lo back and hi forward out of every crossing's view zone.
void CutOutsideCrossings(const std::vector<CrossingSpan>& spans,
                         const PlanOptions& options, double* lo, double* hi) {
  for (int pass = 0; pass < 100; ++pass) {
    bool moved = false;
    for (const CrossingSpan& s : spans) {
      const Zone z = ViewZone(s, options);
      if (*lo > z.lo && *lo < z.hi) {
        *lo = z.lo;
        moved = true;
      }
      if (*hi > z.lo && *hi < z.hi) {
        *hi = z.hi;
        moved = true;
      }
    }
    if (!moved) return;
  }
}

// The overlap around boundary k of n, or false when it cannot be placed.
BlockRange PlaceOverlap(double length_m, int k, int n,
                        const std::vector<CrossingSpan>& spans,
                        const PlanOptions& options) {
  const double step = length_m / n;
  const double nominal = k * step;
  const double half = 0.5 * options.overlap_m;
  // The centre where the crossings are densest, the nominal one on ties.
  double best = nominal;
  int best_count = -1;
  const double reach = options.boundary_search_share * step;
  for (double c = nominal - reach; c <= nominal + reach + 1e-9; c += 1.0) {
    const int count = CentresInside(spans, c - half, c + half);
    if (count > best_count ||
        (count == best_count &&
         std::abs(c - nominal) < std::abs(best - nominal))) {
      best = c;
      best_count = count;
    }
  }
  BlockRange overlap{best - half, best + half};
  CutOutsideCrossings(spans, options, &overlap.start_m, &overlap.end_m);
  // Widen to the nearest crossings until min_overlap_crossings are inside.
  std::vector<const CrossingSpan*> nearest;
  for (const CrossingSpan& s : spans) nearest.push_back(&s);
  std::sort(nearest.begin(), nearest.end(),
            [best](const CrossingSpan* a, const CrossingSpan* b) {
              return std::abs(a->centre_m() - best) <
                     std::abs(b->centre_m() - best);
            });
  for (const CrossingSpan* s : nearest) {
    if (static_cast<int>(
            CrossingsInside(spans, overlap.start_m, overlap.end_m, options)
                .size()) >= options.min_overlap_crossings) {
      break;
    }
    const Zone z = ViewZone(*s, options);
    BlockRange wider{std::min(overlap.start_m, z.lo),
                     std::max(overlap.end_m, z.hi)};
    CutOutsideCrossings(spans, options, &wider.start_m, &wider.end_m);
    if (wider.end_m - wider.start_m > options.max_overlap_m) break;
    overlap = wider;
  }
  return overlap;
}

}  // namespace

std::vector<double> ArcLengths(const Trajectory& trajectory) {
  std::vector<double> arc(trajectory.size(), 0.0);
  for (int i = 1; i < trajectory.size(); ++i) {
    arc[i] = arc[i - 1] +
             (trajectory.poses()[i].p_enu - trajectory.poses()[i - 1].p_enu)
                 .head<2>()
                 .norm();
  }
  return arc;
}

std::vector<CrossingSpan> CrossingSpansAlong(const Trajectory& trajectory,
                                             const std::vector<double>& arc,
                                             const RoadmarkDatabase& database,
                                             const LocalFrame& frame,
                                             double max_offset_m) {
  // The samples about every metre: the search for the nearest one.
  std::vector<int> coarse;
  for (int i = 0; i < trajectory.size(); ++i) {
    if (coarse.empty() || arc[i] - arc[coarse.back()] >= 1.0 ||
        i + 1 == trajectory.size()) {
      coarse.push_back(i);
    }
  }
  std::map<std::string, CrossingSpan> by_id;
  std::map<std::string, bool> off_road;
  for (const RoadmarkBand& band : database.bands) {
    for (const Geodetic& corner : band.corners) {
      const Eigen::Vector2d p = frame.EnuFromGeodetic(corner).head<2>();
      double best = std::numeric_limits<double>::infinity();
      int best_i = 0;
      for (int i : coarse) {
        const double d = (trajectory.poses()[i].p_enu.head<2>() - p).norm();
        if (d < best) {
          best = d;
          best_i = i;
        }
      }
      if (best > max_offset_m) {
        off_road[band.crossing_id] = true;
        continue;
      }
      auto [it, inserted] = by_id.try_emplace(band.crossing_id);
      CrossingSpan& span = it->second;
      if (inserted) {
        span.crossing_id = band.crossing_id;
        span.start_m = span.end_m = arc[best_i];
      }
      span.start_m = std::min(span.start_m, arc[best_i]);
      span.end_m = std::max(span.end_m, arc[best_i]);
    }
  }
  std::vector<CrossingSpan> spans;
  for (const auto& [id, span] : by_id) {
    if (!off_road.count(id)) spans.push_back(span);
  }
  std::sort(spans.begin(), spans.end(),
            [](const CrossingSpan& a, const CrossingSpan& b) {
              return a.start_m < b.start_m;
            });
  return spans;
}

std::vector<std::string> CrossingsInside(const std::vector<CrossingSpan>& spans,
                                         double start_m, double end_m,
                                         const PlanOptions& options) {
  std::vector<std::string> ids;
  for (const CrossingSpan& s : spans) {
    const Zone z = ViewZone(s, options);
    if (z.lo >= start_m - 1e-6 && z.hi <= end_m + 1e-6) {
      ids.push_back(s.crossing_id);
    }
  }
  return ids;
}

std::vector<BlockRange> PlanBlockRanges(double length_m,
                                        const std::vector<CrossingSpan>& spans,
                                        const PlanOptions& options) {
  int n = std::max(
      1, static_cast<int>(std::lround(length_m / options.block_length_m)));
  for (; n > 1; --n) {
    std::vector<BlockRange> overlaps;
    for (int k = 1; k < n; ++k) {
      overlaps.push_back(PlaceOverlap(length_m, k, n, spans, options));
    }
    // Each block keeps a part of its own between its overlaps.
    bool valid =
        overlaps.front().start_m > 0.0 && overlaps.back().end_m < length_m;
    for (size_t k = 1; k < overlaps.size(); ++k) {
      valid = valid && overlaps[k].start_m > overlaps[k - 1].end_m;
    }
    if (!valid) continue;
    std::vector<BlockRange> blocks;
    for (int k = 0; k < n; ++k) {
      blocks.push_back({k == 0 ? 0.0 : overlaps[k - 1].start_m,
                        k + 1 == n ? length_m : overlaps[k].end_m});
    }
    return blocks;
  }
  return {BlockRange{0.0, length_m}};
}

}  // namespace zebrageo
