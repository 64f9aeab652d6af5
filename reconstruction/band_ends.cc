#include "reconstruction/band_ends.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace zebrageo {
namespace {

using Area = std::array<Eigen::Vector2d, 4>;

// Unit normal, in rectified image `side`, of the line of the band plane
// through the centre of `area_3d` along `direction_2d` (plane frame),
// oriented like `like`.
Eigen::Vector2d ImageNormalOf(const RoadRectification& rectification, int side,
                              const PlaneFrame& frame, const RoadPlane& plane,
                              const std::array<Eigen::Vector3d, 4>& area_3d,
                              const Eigen::Vector2d& direction_2d,
                              const Eigen::Vector2d& like) {
  const Eigen::Vector3d centre =
      0.25 * (area_3d[0] + area_3d[1] + area_3d[2] + area_3d[3]);
  const Eigen::Vector3d ahead =
      OnBandPlane(frame, plane, frame.To2d(centre) + 0.5 * direction_2d);
  Eigen::Vector2d a, b;
  if (!rectification.ProjectToRectified(side, centre, &a) ||
      !rectification.ProjectToRectified(side, ahead, &b)) {
    return like;
  }
  const Eigen::Vector2d d = (b - a).normalized();
  Eigen::Vector2d normal(-d.y(), d.x());
  if (normal.dot(like) < 0.0) normal = -normal;
  return normal;
}

// Hough candidates of the searched ends (none for a known end).
void TransversalCandidates(const BandContext& context, const KnownEnd known[2],
                           const BandImage& image,
                           std::vector<ImageLine> candidates[2]) {
  const Area* areas = image.areas;
  for (int e = 0; e < 2; ++e) {
    if (known[e].line != nullptr) continue;
    // A ladder bar's inner edge has the reverse of a band end's polarity
    // (the road brightens into the bar beyond the gaps).
    const double polarity = (e == 0) == !known[e].ladder ? 1.0 : -1.0;
    candidates[e] = HoughTransversalCandidates(
        context.edges[image.side],
        known[e].ladder ? image.ladder_areas[e] : areas[e],
        polarity * image.expected_normal, context.options);
    if (context.debug != nullptr && image.side == 0) {
      context.debug->search_areas.push_back(areas[e]);
      for (const ImageLine& line : candidates[e]) {
        const Eigen::Vector2d d(-line.normal.y(), line.normal.x());
        const Eigen::Vector2d p = line.rho * line.normal;
        const double t_a = (areas[e][0] - p).dot(d);
        const double t_b = (areas[e][1] - p).dot(d);
        context.debug->candidate_lines.push_back({p + t_a * d, p + t_b * d});
      }
    }
  }
}

// The image line of a known (hidden) end: the crossing's line through the
// band's long sides; false when it does not project.
bool KnownEndLine(const BandContext& context, const BandSetup& setup, int side,
                  const PlaneLine& known, ImageLine* line) {
  const PlaneFrame& frame = context.frame;
  const RoadPlane& plane = setup.plane_fit.plane;
  Eigen::Vector2d a, b;
  const bool failed =
      !context.rectification.ProjectToRectified(
          side,
          OnBandPlane(frame, plane,
                      AtLateral(known, setup.along, setup.across,
                                setup.lo.lateral_m, 0.0)),
          &a) ||
      !context.rectification.ProjectToRectified(
          side,
          OnBandPlane(frame, plane,
                      AtLateral(known, setup.along, setup.across,
                                setup.hi.lateral_m, 0.0)),
          &b);
  if (!failed) *line = LineThrough(a, b);
  return !failed;
}

// The seen end e of a band whose other end is known: the candidate of the
// right polarity nearest to the crossing's line there (the strongest
// without one); null when none has that polarity.
const ImageLine* SeenEndLine(const BandContext& context, const BandSetup& setup,
                             const KnownEnd& known, const BandImage& image,
                             int e, const std::vector<ImageLine>& candidates) {
  const double sign = e == 0 ? 1.0 : -1.0;
  Eigen::Vector2d expected_xy = Eigen::Vector2d::Zero();
  const bool has_expected =
      known.expected != nullptr &&
      context.rectification.ProjectToRectified(
          image.side,
          OnBandPlane(
              context.frame, setup.plane_fit.plane,
              AtLateral(*known.expected, setup.along, setup.across,
                        0.5 * (setup.lo.lateral_m + setup.hi.lateral_m), 0.0)),
          &expected_xy);
  const ImageLine* chosen = nullptr;
  double best_distance = 1e30;
  for (const ImageLine& line : candidates) {
    if (sign * line.gamma.dot(image.band_direction) <= 0.0) continue;
    const double distance =
        has_expected ? std::abs(line.Distance(expected_xy)) : 0.0;
    if (distance < best_distance) {
      best_distance = distance;
      chosen = &line;
    }
    if (!has_expected) break;
  }
  return chosen;
}

// A ladder end: the strongest candidate of the bar's inner edge's polarity
// (the image darkens into the band along the band direction at its begin);
// null when none has it.
const ImageLine* LadderEndLine(const BandImage& image, int e,
                               const std::vector<ImageLine>& candidates) {
  const double sign = e == 0 ? 1.0 : -1.0;
  for (const ImageLine& line : candidates) {
    if (sign * line.gamma.dot(image.band_direction) < 0.0) return &line;
  }
  return nullptr;
}

// The band's two transversal lines in one image, before refinement: the
// paper's pair (equations 2 and 3) when both ends are searched, else the
// known end's line and the seen end's candidate.
ViewResult ChooseTransversalLines(const BandContext& context, int i,
                                  const KnownEnd known[2],
                                  const BandSetup& setup,
                                  const BandImage& image,
                                  const std::vector<ImageLine> candidates[2],
                                  ImageLine lines[2]) {
  const int side = image.side;
  if (known[0].line == nullptr && known[1].line == nullptr &&
      !known[0].ladder && !known[1].ladder) {
    int t = -1, l = -1;
    if (!ChooseTransversalPair(candidates[0], candidates[1],
                               image.band_direction, context.options, &t, &l)) {
      VLOG(2) << "band " << i << " side " << side << ": no transversal pair";
      return ViewResult::kNoTransversal;
    }
    lines[0] = candidates[0][t];
    lines[1] = candidates[1][l];
    return ViewResult::kOk;
  }
  ViewResult result = ViewResult::kOk;
  for (int e = 0; e < 2 && result == ViewResult::kOk; ++e) {
    if (known[e].line != nullptr) {
      if (!KnownEndLine(context, setup, side, *known[e].line, &lines[e])) {
        result = ViewResult::kFailed;
      }
      continue;
    }
    VLOG(3) << "band " << i << " side " << side << " end " << e << ": "
            << candidates[e].size() << " candidates"
            << (candidates[e].empty()
                    ? std::string()
                    : ", the first's gamma along the band " +
                          std::to_string(candidates[e][0].gamma.dot(
                              image.band_direction)));
    const ImageLine* chosen =
        known[e].ladder
            ? LadderEndLine(image, e, candidates[e])
            : SeenEndLine(context, setup, known[e], image, e, candidates[e]);
    if (chosen == nullptr) {
      result = ViewResult::kNoTransversal;
    } else {
      lines[e] = *chosen;
    }
  }
  if (result != ViewResult::kOk) {
    VLOG(2) << "band " << i << " side " << side
            << ": no transversal side at the seen end";
  }
  return result;
}

// Sub-pixel refinement of the searched ends' lines (along the crossing's
// direction of the ends when it is known), their standard deviations and
// contrast.
ViewResult RefineTransversalLines(const BandContext& context, int i,
                                  const KnownEnd known[2],
                                  const BandSetup& setup,
                                  const BandImage& image, ImageLine lines[2],
                                  BandEndFits* fits) {
  const BandOptions& options = context.options;
  const int side = image.side;
  const EdgeMap& edges = context.edges[side];
  for (int e = 0; e < 2; ++e) {
    if (known[e].line != nullptr) continue;
    const std::array<Eigen::Vector2d, 4>& area =
        known[e].ladder ? image.ladder_areas[e] : image.areas[e];
    if (!RefineImageLine(edges, area, options, &lines[e])) {
      VLOG(2) << "band " << i << " side " << side << " end " << e
              << ": refinement failed";
      return ViewResult::kNoTransversal;
    }
    if (known[e].direction != nullptr) {
      // The crossing's direction in this image, at this end.
      const Eigen::Vector2d normal = ImageNormalOf(
          context.rectification, side, context.frame, setup.plane_fit.plane,
          setup.areas_3d[e], *known[e].direction, lines[e].normal);
      const Eigen::Vector2d& own = lines[e].normal;
      fits->free_angle[side][e] =
          std::atan2(Cross2d(normal, own), normal.dot(own));
      VLOG(2) << "band " << i << " side " << side << " end " << e << ": "
              << fits->free_angle[side][e] << " rad from the crossing's ends";
      if (!RefineImageLine(edges, area, options, &lines[e], &normal)) {
        return ViewResult::kNoTransversal;
      }
    }
    fits->line_sigma_px[side][e] = std::max(
        options.min_line_sigma_px,
        lines[e].rms_px / std::sqrt(static_cast<double>(lines[e].support)));
    fits->contrast += lines[e].gamma.norm() / std::max(1, lines[e].support);
  }
  return ViewResult::kOk;
}

}  // namespace

ViewResult FindBandEnds(const BandContext& context, int i,
                        const KnownEnd known[2], const BandSetup& setup,
                        const BandImage& image, ImageLine lines[2],
                        BandEndFits* fits) {
  std::vector<ImageLine> candidates[2];
  TransversalCandidates(context, known, image, candidates);
  const ViewResult result = ChooseTransversalLines(context, i, known, setup,
                                                   image, candidates, lines);
  if (result != ViewResult::kOk) return result;
  return RefineTransversalLines(context, i, known, setup, image, lines, fits);
}

}  // namespace zebrageo
