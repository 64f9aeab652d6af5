#include "reconstruction/ladder_ends.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace zebrageo {
namespace {

// The larger step across `line` in the gaps on either side of the band
// (from near_m to far_m beyond its long sides, `px_per_m` across); 0 when
// neither can be measured (beside an end band only one gap has a bar).
double GapStep(const EdgeMap& edges, const ImageLine& line,
               const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
               double px_per_m, double step_profile_px) {
  const Eigen::Vector2d u = (hi - lo).normalized();
  double best = 0.0;
  for (const auto& [from, dir] :
       {std::make_pair(lo, Eigen::Vector2d(-u)), std::make_pair(hi, u)}) {
    const double step = EdgeStep(edges, line, from + 0.08 * px_per_m * dir,
                                 from + 0.4 * px_per_m * dir, step_profile_px);
    if (std::isfinite(step)) best = std::max(best, step);
  }
  return best;
}

// The strongest step of a paint end's polarity across a line beyond the
// ladder end (the bar's outer edge), between ladder_min_bar_width_m and
// ladder_max_bar_width_m beyond `lo`-`hi` along `out` (`px_per_m` along
// the band); 0 when there is none.
double OuterEdgeStep(const BandContext& context, const BandImage& image, int e,
                     const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                     const Eigen::Vector2d& out, double px_per_m) {
  const BandOptions& options = context.options;
  const EdgeMap& edges = context.edges[image.side];
  const Eigen::Vector2d inset = 0.15 * (hi - lo);
  const double near_px = options.ladder_min_bar_width_m * px_per_m;
  const double far_px = options.ladder_max_bar_width_m * px_per_m;
  const std::array<Eigen::Vector2d, 4> area = {
      lo + inset + near_px * out, hi - inset + near_px * out,
      hi - inset + far_px * out, lo + inset + far_px * out};
  const double sign = e == 0 ? 1.0 : -1.0;
  const std::vector<ImageLine> candidates = HoughTransversalCandidates(
      edges, area, sign * image.expected_normal, options);
  for (const ImageLine& line : candidates) {
    if (sign * line.gamma.dot(image.band_direction) <= 0.0) continue;
    const Eigen::Vector2d a = lo - line.Distance(lo) * line.normal;
    const Eigen::Vector2d b = hi - line.Distance(hi) * line.normal;
    const double step =
        EdgeStep(edges, line, a, b, options.end_step_profile_px);
    if (std::isfinite(step)) return step;
  }
  return 0.0;
}

}  // namespace

bool LadderEndsJoinBars(const BandContext& context, int i,
                        const KnownEnd known[2], const BandImage& image,
                        const ImageLine long_lines[2],
                        const ImageLine transversal_lines[2],
                        const Eigen::Vector2d corner[4],
                        const std::array<Eigen::Vector3d, 4>& vertices) {
  const BandOptions& options = context.options;
  const EdgeMap& edges = context.edges[image.side];
  const double length_px = (corner[3] - corner[0]).norm();
  const double length_m = (vertices[3] - vertices[0]).norm();
  for (int e = 0; e < 2; ++e) {
    if (!known[e].ladder) continue;
    const double long_step =
        LongSideStep(context, i, edges, long_lines, corner, e);
    const Eigen::Vector2d& lo = corner[e == 0 ? 0 : 3];
    const Eigen::Vector2d& hi = corner[e == 0 ? 1 : 2];
    const double width_m =
        (vertices[e == 0 ? 1 : 2] - vertices[e == 0 ? 0 : 3]).norm();
    if (!std::isfinite(long_step) || !(long_step > 0.0) || !(length_m > 0.0) ||
        !(width_m > 0.0)) {
      return false;
    }
    const ImageLine& line = transversal_lines[e];
    // The steps are summed over less than the narrowest bar: a far bar a
    // few pixels wide puts its outer edge within end_step_profile_px.
    const double profile_px =
        std::clamp(0.8 * options.ladder_min_bar_width_m * length_px / length_m,
                   3.0, options.end_step_profile_px);
    // The band runs on into the bar: no step between its corners.
    const double join = EdgeStep(edges, line, lo, hi, profile_px);
    // The gaps beside it end on the bar's paint.
    const double gap =
        GapStep(edges, line, lo, hi, (hi - lo).norm() / width_m, profile_px);
    // The bar's outer edge beyond.
    const Eigen::Vector2d out =
        (e == 0 ? corner[0] - corner[3] : corner[3] - corner[0]).normalized();
    const double outer =
        OuterEdgeStep(context, image, e, lo, hi, out, length_px / length_m);
    VLOG(2) << "band " << i << " side " << image.side << " ladder end " << e
            << ": join " << join / long_step << " gap " << gap / long_step
            << " outer " << outer / long_step << " of the long sides' step";
    if (!(join <= options.max_ladder_join_step_fraction * long_step) ||
        !(gap >= options.min_end_step_fraction * long_step) ||
        !(outer >= options.min_end_step_fraction * long_step)) {
      return false;
    }
  }
  return true;
}

}  // namespace zebrageo
