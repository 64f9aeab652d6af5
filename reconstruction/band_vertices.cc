#include "reconstruction/band_vertices.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "reconstruction/band_ends.h"
#include "reconstruction/band_plane.h"
#include "reconstruction/ladder_ends.h"
#include "reconstruction/transversal_sides.h"

namespace zebrageo {
namespace {

// The band's long sides along the band, its plane and its search areas;
// false when the plane cannot be fitted.
bool SetUpBand(const BandContext& context, int i, BandSetup* setup) {
  const BandCandidate& pair = context.bands.pairs[i];
  const BandOptions& options = context.options;
  const PlaneFrame& frame = context.frame;
  // A seen side that runs on beyond the band (into a lane line, a
  // vehicle's shadow edge, within the grouping's 3 cm) is fitted again
  // on its points along the band: what it runs on to tilts its line.
  setup->lo = context.bands.sides[pair.lo];
  setup->hi = context.bands.sides[pair.hi];
  const LongSide& lo = setup->lo;
  const LongSide& hi = setup->hi;
  if (pair.inferred < 0) {
    setup->lo = SideAlongBand(context.detection.points, frame, lo, pair.begin,
                              pair.end, options.transversal_search_m);
    setup->hi = SideAlongBand(context.detection.points, frame, hi, pair.begin,
                              pair.end, options.transversal_search_m);
  }
  setup->along = lo.direction_2d;
  setup->across = lo.Normal2d();
  if (!FitPlaneOfBand(context.detection.points, frame, lo, hi, pair.begin,
                      pair.end, options.transversal_search_m,
                      options.min_sigma_m, &setup->plane_fit)) {
    return false;
  }
  const RoadPlane& plane = setup->plane_fit.plane;
  VLOG(2) << "band " << i << ": plane normal " << plane.normal_body.transpose()
          << " rms " << setup->plane_fit.rms_m << " n "
          << setup->plane_fit.count << " side height rms " << lo.height_rms_m
          << " " << hi.height_rms_m << " lateral rms " << lo.lateral_rms_m
          << " " << hi.lateral_rms_m;
  double lateral_lo = lo.lateral_m + options.side_margin_m;
  double lateral_hi = hi.lateral_m - options.side_margin_m;
  // A completed band's transversal sides are searched on its seen half:
  // what hides the other side (a vehicle) must not vote.
  const double seen_share = 0.55 * (hi.lateral_m - lo.lateral_m);
  if (pair.inferred == 1) lateral_hi = lo.lateral_m + seen_share;
  if (pair.inferred == 0) lateral_lo = hi.lateral_m - seen_share;
  const int crossing = context.bands.crossing_of[i];
  for (int e = 0; e < 2; ++e) {
    const PlaneLine& line = e == 0 ? context.search.begin_lines[crossing]
                                   : context.search.end_lines[crossing];
    const double s = options.transversal_search_m;
    const Eigen::Vector2d& along = setup->along;
    const Eigen::Vector2d& across = setup->across;
    const Eigen::Vector2d corners[4] = {
        AtLateral(line, along, across, lateral_lo, -s),
        AtLateral(line, along, across, lateral_hi, -s),
        AtLateral(line, along, across, lateral_hi, s),
        AtLateral(line, along, across, lateral_lo, s)};
    for (int k = 0; k < 4; ++k) {
      setup->areas_3d[e][k] = OnBandPlane(frame, plane, corners[k]);
    }
    const double reach = options.ladder_gap_reach_m;
    const Eigen::Vector2d wide[4] = {
        AtLateral(line, along, across, lo.lateral_m - reach, -s),
        AtLateral(line, along, across, hi.lateral_m + reach, -s),
        AtLateral(line, along, across, hi.lateral_m + reach, s),
        AtLateral(line, along, across, lo.lateral_m - reach, s)};
    for (int k = 0; k < 4; ++k) {
      setup->ladder_areas_3d[e][k] = OnBandPlane(frame, plane, wide[k]);
    }
  }
  // The band direction and the expected transversal normal in the image.
  setup->band_centre =
      0.5 * (OnBandPlane(frame, plane, frame.To2d(lo.point_body)) +
             OnBandPlane(frame, plane, frame.To2d(hi.point_body)));
  return true;
}

// The two images' measurements of a band, image by image.
struct BandViews {
  std::array<Eigen::Vector3d, 4> vertex_sum;
  std::array<std::array<Eigen::Vector3d, 4>, 2> vertex_side;
  BandEndFits ends;
  int views = 0;
};

// The band's search areas in image `side`, and its directions there; false
// when the band's approximate corners are not seen (the band must be fully
// visible; its search areas may run out of the image) or do not project.
bool ViewBand(const BandContext& context, int i, const BandSetup& setup,
              int side, BandImage* image) {
  const RoadRectification& rectification = context.rectification;
  std::array<Eigen::Vector2d, 4>* areas = image->areas;
  image->side = side;
  bool visible = true;
  for (int e = 0; e < 2; ++e) {
    for (int k = 0; k < 4; ++k) {
      if (!rectification.ProjectToRectified(side, setup.areas_3d[e][k],
                                            &areas[e][k])) {
        visible = false;
      }
    }
    for (int k : {0, 1}) {
      const Eigen::Vector2d corner = 0.5 * (areas[e][k] + areas[e][3 - k]);
      // (The valid mask holds for both images: a road point has the
      // same pixel in both.)
      visible = visible && rectification.IsValid(corner.x(), corner.y());
    }
  }
  for (int e = 0; e < 2; ++e) {
    for (int k = 0; k < 4; ++k) {
      // Out of view, the gaps beside the band: the band's own area (no
      // ladder edge is found there).
      if (!rectification.ProjectToRectified(side, setup.ladder_areas_3d[e][k],
                                            &image->ladder_areas[e][k])) {
        image->ladder_areas[e] = areas[e];
        break;
      }
    }
  }
  if (!visible) {
    VLOG(2) << "band " << i << " side " << side << ": band corners not visible "
            << areas[0][0].transpose() << " / " << areas[0][1].transpose()
            << " / " << areas[1][0].transpose() << " / "
            << areas[1][1].transpose();
    return false;
  }
  Eigen::Vector2d c0, c1, t0, t1;
  const Eigen::Vector3d dir3 = setup.plane_fit.x_axis;
  if (!rectification.ProjectToRectified(side, setup.band_centre, &c0) ||
      !rectification.ProjectToRectified(side, setup.band_centre + dir3, &c1) ||
      !rectification.ProjectToRectified(side, setup.areas_3d[0][0], &t0) ||
      !rectification.ProjectToRectified(side, setup.areas_3d[0][1], &t1)) {
    VLOG(2) << "band " << i << " side " << side << ": projection";
    return false;
  }
  image->band_direction = (c1 - c0).normalized();
  const Eigen::Vector2d transversal = (t1 - t0).normalized();
  image->expected_normal = Eigen::Vector2d(-transversal.y(), transversal.x());
  // At the begin side the image brightens into the band (along the band
  // direction), at the end side against it.
  if (image->expected_normal.dot(image->band_direction) < 0.0) {
    image->expected_normal = -image->expected_normal;
  }
  return true;
}

// The band's long sides in image `side`; false when they do not project.
bool LongSideLines(const BandContext& context, int i, const BandSetup& setup,
                   int side, ImageLine lines[2]) {
  for (int k = 0; k < 2; ++k) {
    const LongSide& s = k == 0 ? setup.lo : setup.hi;
    Eigen::Vector2d a, b;
    if (!context.rectification.ProjectToRectified(side, s.Begin(), &a) ||
        !context.rectification.ProjectToRectified(side, s.End(), &b)) {
      VLOG(2) << "band " << i << " side " << side << ": long side projection";
      return false;
    }
    lines[k] = LineThrough(a, b);
  }
  return true;
}

// A seen transversal edge stops at the long sides: a shadow boundary
// across a lane line runs on over the road. False when one runs on.
bool EndsStopAtTheLongSides(const BandContext& context, int i,
                            const KnownEnd known[2], int side,
                            const ImageLine long_lines[2],
                            const ImageLine transversal_lines[2]) {
  const BandCandidate& pair = context.bands.pairs[i];
  bool failed = false;
  for (int e = 0; e < 2 && !failed; ++e) {
    // A ladder bar's inner edge runs on into the gaps (ladder_ends.h).
    if (known[e].line != nullptr || known[e].ladder) continue;
    Eigen::Vector2d ends[2];
    if (!Intersect(long_lines[0], transversal_lines[e], &ends[0]) ||
        !Intersect(long_lines[1], transversal_lines[e], &ends[1])) {
      failed = true;
      break;
    }
    // Beyond a hidden long side, what hides it may have edges.
    const bool check[2] = {pair.inferred != 0, pair.inferred != 1};
    const double run_on = TransversalRunOn(context.edges[side],
                                           transversal_lines[e], ends, check);
    VLOG(2) << "band " << i << " side " << side << " end " << e << ": run-on "
            << run_on;
    failed = run_on > context.options.max_transversal_run_on;
  }
  if (failed) {
    VLOG(2) << "band " << i << " side " << side
            << ": a transversal edge runs on beyond the band";
  }
  return !failed;
}

// A seen end is the paint ending against the road: its grey-level step is
// of the order of the long sides'. A weak Hough maximum in plain paint
// (the band running on out of view, under the vehicle) is not an end.
// `corner`: the band's vertices in this image. False when an end fails.
bool EndsStepLikeThePaint(const BandContext& context, int i,
                          const KnownEnd known[2], int side,
                          const ImageLine long_lines[2],
                          const ImageLine transversal_lines[2],
                          const Eigen::Vector2d corner[4]) {
  const BandOptions& options = context.options;
  const EdgeMap& edges = context.edges[side];
  bool failed = false;
  for (int e = 0; e < 2 && !failed; ++e) {
    if (known[e].line != nullptr || known[e].ladder) continue;
    // The long sides' step near this end (a shadow across the band
    // lowers both alike).
    const double long_step =
        LongSideStep(context, i, edges, long_lines, corner, e);
    if (!std::isfinite(long_step)) continue;
    const double step =
        EdgeStep(edges, transversal_lines[e], corner[e == 0 ? 0 : 3],
                 corner[e == 0 ? 1 : 2], options.end_step_profile_px);
    const double ratio = step / long_step;
    VLOG(2) << "band " << i << " side " << side << " end " << e << ": step "
            << ratio << " of the long sides'";
    failed = !(ratio >= options.min_end_step_fraction);
  }
  if (failed) {
    VLOG(2) << "band " << i << " side " << side
            << ": a transversal side without the paint's step";
  }
  return !failed;
}

// The band in rectified image `side`: its transversal sides, and its
// vertices, intersections of long and transversal sides projected onto the
// band plane, added to `views` when every check passes.
ViewResult ModelBandInImage(const BandContext& context, int i,
                            const KnownEnd known[2], const BandSetup& setup,
                            int side, BandViews* views) {
  BandImage image;
  if (!ViewBand(context, i, setup, side, &image)) return ViewResult::kFailed;
  ImageLine transversal_lines[2];
  const ViewResult result = FindBandEnds(context, i, known, setup, image,
                                         transversal_lines, &views->ends);
  if (result != ViewResult::kOk) return result;
  ImageLine long_lines[2];
  if (!LongSideLines(context, i, setup, side, long_lines)) {
    return ViewResult::kFailed;
  }
  // Vertices: 0 = lo x begin, 1 = hi x begin, 2 = hi x end, 3 = lo x end.
  const RoadRectification& rectification = context.rectification;
  const int long_of[4] = {0, 1, 1, 0};
  const int end_of[4] = {0, 0, 1, 1};
  const Eigen::Vector3d centre = side == 0 ? rectification.left_centre_body()
                                           : rectification.right_centre_body();
  Eigen::Vector2d corner[4];  // the vertices in this rectified image
  for (int v = 0; v < 4; ++v) {
    if (!Intersect(long_lines[long_of[v]], transversal_lines[end_of[v]],
                   &corner[v]) ||
        !setup.plane_fit.plane.IntersectRay(
            centre, rectification.RayBody(side, corner[v]),
            &views->vertex_side[side][v])) {
      VLOG(2) << "band " << i << " side " << side << ": vertex intersection";
      return ViewResult::kFailed;
    }
  }
  if (!EndsStopAtTheLongSides(context, i, known, side, long_lines,
                              transversal_lines) ||
      !EndsStepLikeThePaint(context, i, known, side, long_lines,
                            transversal_lines, corner) ||
      !LadderEndsJoinBars(context, i, known, image, long_lines,
                          transversal_lines, corner,
                          views->vertex_side[side])) {
    return ViewResult::kFailed;
  }
  for (int v = 0; v < 4; ++v) {
    views->vertex_sum[v] += views->vertex_side[side][v];
  }
  ++views->views;
  return ViewResult::kOk;
}

// The monoplotted point of `side` nearest to `p` (its sigmas grow with the
// range: those at the vertex's end hold for it); null when the side was
// triangulated.
const EdgePoint3d* NearestMonoplotted(const LongSideDetection& detection,
                                      const LongSide& side,
                                      const Eigen::Vector3d& p) {
  const EdgePoint3d* nearest = nullptr;
  double best = 0.0;
  for (int k : side.support) {
    const EdgePoint3d& q = detection.points[k];
    if (q.monoplot_height_sigma_m <= 0.0) continue;
    const double d = (q.p_body - p).squaredNorm();
    if (nearest == nullptr || d < best) {
      nearest = &q;
      best = d;
    }
  }
  return nearest;
}

// Covariance of each vertex: along the band from the transversal line
// fits, across from the long side regression, and the band plane's height
// error, which moves a vertex along its viewing ray.
void VertexCovariances(const BandContext& context, int i,
                       const KnownEnd known[2], const BandSetup& setup,
                       const BandViews& views, Band* band) {
  const RoadRectification& rectification = context.rectification;
  const BandOptions& options = context.options;
  const BandCandidate& pair = context.bands.pairs[i];
  const BandPlaneFit& plane_fit = setup.plane_fit;
  const Eigen::Vector3d plane_normal = plane_fit.plane.normal_body;
  const Eigen::Vector3d x_axis = plane_fit.x_axis;
  const Eigen::Vector3d y_axis = plane_fit.y_axis;
  for (int v = 0; v < 4; ++v) {
    const Eigen::Vector3d& p = band->vertices_body[v];
    const int e = v == 0 || v == 1 ? 0 : 1;
    const LongSide& s = v == 0 || v == 3 ? setup.lo : setup.hi;
    const Eigen::Vector3d ray =
        (p - rectification.left_centre_body()).normalized();
    const double depth = (rectification.R_body_virt().transpose() *
                          (p - rectification.left_centre_body()))
                             .z();
    const double metres_per_px = depth / rectification.focal_px();
    // The two images' lines are independent estimates.
    const double sigma_px = 0.5 * std::hypot(views.ends.line_sigma_px[0][e],
                                             views.ends.line_sigma_px[1][e]);
    // A ladder end's edge is measured in the gaps beside the band and
    // carried across it (band.h, ladder_end_sigma_m).
    const double sigma_along =
        known[e].line != nullptr ? known[e].sigma_m
        : known[e].ladder
            ? std::hypot(sigma_px * metres_per_px, options.ladder_end_sigma_m)
            : sigma_px * metres_per_px;
    const bool inferred = pair.inferred == (v == 0 || v == 3 ? 0 : 1);
    // A monoplotted long side (monoplot.h) is placed by its edge in one
    // image, whose localisation error grows on the road with the range and
    // the grazing angle, and by the height of the local surface it was cut
    // with, whose error moves the side along the ray.
    const EdgePoint3d* monoplotted =
        NearestMonoplotted(context.detection, s, p);
    double sigma_across =
        inferred
            ? pair.inferred_sigma_m
            : std::max(options.min_sigma_m,
                       s.lateral_rms_m /
                           std::sqrt(static_cast<double>(s.support.size())));
    if (!inferred && monoplotted != nullptr) {
      sigma_across =
          std::hypot(sigma_across, monoplotted->monoplot_across_sigma_m);
    }
    const double sigma_height = std::max(
        {options.min_sigma_m, std::sqrt(plane_fit.HeightVariance(p)),
         monoplotted != nullptr ? monoplotted->monoplot_height_sigma_m : 0.0});
    const Eigen::Vector3d along_ray = ray / std::abs(plane_normal.dot(ray));
    band->covariances_body[v] =
        sigma_along * sigma_along * x_axis * x_axis.transpose() +
        sigma_across * sigma_across * y_axis * y_axis.transpose() +
        sigma_height * sigma_height * along_ray * along_ray.transpose();
  }
}

// Score: width as specified, stereo agreement, contrast, flatness; an
// inferred side or end is an inference, not a measurement.
void ScoreBand(const BandContext& context, int i, const KnownEnd known[2],
               const BandSetup& setup, const BandViews& views, Band* band) {
  const ZebraSpecification& zebra = context.zebra;
  const BandOptions& options = context.options;
  const BandCandidate& pair = context.bands.pairs[i];
  const double width_term =
      std::exp(-0.5 * std::pow((band->width_m - zebra.band_width_m) / 0.05, 2));
  const double stereo_term =
      std::exp(-0.5 * std::pow(band->stereo_disagreement_m / 0.02, 2));
  const double contrast_term =
      std::min(1.0, views.ends.contrast / (4.0 * 10.0));
  const double flat_term =
      std::exp(-0.5 * std::pow(setup.plane_fit.rms_m / 0.02, 2));
  band->score = std::clamp(width_term * stereo_term * contrast_term * flat_term,
                           0.0, 1.0);
  // A completed band's hidden side is an inference, not a measurement.
  if (pair.inferred >= 0) band->score *= options.inferred_score_factor;
  band->inferred_side = pair.inferred;
  for (int e = 0; e < 2; ++e) {
    if (known[e].line != nullptr) {
      band->score *= options.inferred_score_factor;
      band->inferred_end = e;
    }
  }
}

// A painted end is parallel to its crossing's (a stain's slanted edge
// cutting the paint is not): each end's own direction, averaged over the
// two images (a far end's angle is noisy in each), within
// max_end_angle_rad of the crossing's (less near); and the two images
// agree on it within max_end_disagreement_rad_per_m times the band's range.
bool EndsAlongTheCrossing(const BandContext& context, int i,
                          const KnownEnd known[2], const BandViews& views) {
  const BandOptions& options = context.options;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int v = 0; v < 4; ++v) centre += views.vertex_sum[v];
  centre /= 4.0 * std::max(1, views.views);
  const double range =
      (centre - context.rectification.left_centre_body()).norm();
  const double max_disagreement =
      options.max_end_disagreement_rad_per_m * range;
  // The mean direction is measured better near: its limit shrinks in
  // proportion to the range below end_angle_full_range_m.
  const double max_angle = options.max_end_angle_rad *
                           std::clamp(range / options.end_angle_full_range_m,
                                      options.end_angle_min_share, 1.0);
  for (int e = 0; e < 2; ++e) {
    if (known[e].direction == nullptr || known[e].line != nullptr) continue;
    const double angle =
        0.5 * (views.ends.free_angle[0][e] + views.ends.free_angle[1][e]);
    // Both images are orthoimages of the road: a painted end has one
    // direction in both (a stain's edge, or a shadow's, need not).
    const double disagreement =
        std::abs(views.ends.free_angle[0][e] - views.ends.free_angle[1][e]);
    if (!(std::abs(angle) <= max_angle) ||
        !(disagreement <= max_disagreement)) {
      VLOG(2) << "band " << i << " end " << e << ": " << angle
              << " rad from the crossing's ends, the images " << disagreement
              << " rad apart";
      return false;
    }
  }
  return true;
}

// Each image's two ends, weighted by their angular precision: the
// along-band error of an end grows with the square of its range.
void ObserveEndDirections(const BandContext& context, int crossing,
                          const BandViews& views,
                          std::vector<EndDirectionObservation>* out) {
  const RoadRectification& rectification = context.rectification;
  for (int side = 0; side < 2; ++side) {
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector3d& a = views.vertex_side[side][e == 0 ? 0 : 3];
      const Eigen::Vector3d& b = views.vertex_side[side][e == 0 ? 1 : 2];
      const double r =
          (0.5 * (a + b) - rectification.left_centre_body()).norm();
      out->push_back(
          {crossing,
           (context.frame.To2d(b) - context.frame.To2d(a)).normalized(),
           1.0 / std::pow(std::max(r, 1.0), 4)});
    }
  }
}

// The band from its two views, once it passes the checks of a painted band
// within range.
BandOutcome FinishBand(const BandContext& context, int i,
                       const KnownEnd known[2], const BandSetup& setup,
                       const BandViews& views,
                       std::vector<EndDirectionObservation>* end_directions,
                       Band* out) {
  const BandOptions& options = context.options;
  const ZebraSpecification& zebra = context.zebra;
  const BandCandidate& pair = context.bands.pairs[i];
  if (!EndsAlongTheCrossing(context, i, known, views)) {
    return BandOutcome::kRejected;
  }
  Band band;
  band.plane = setup.plane_fit.plane;
  band.crossing = context.bands.crossing_of[i];
  band.sides[0] = pair.lo;
  band.sides[1] = pair.hi;
  double disagreement = 0.0;
  for (int v = 0; v < 4; ++v) {
    band.vertices_body[v] = views.vertex_sum[v] / views.views;
    disagreement =
        std::max(disagreement,
                 (views.vertex_side[0][v] - views.vertex_side[1][v]).norm());
  }
  band.stereo_disagreement_m = disagreement;
  for (int v = 0; v < 4; ++v) {
    VLOG(3) << "band " << i << " vertex " << v << " left "
            << views.vertex_side[0][v].transpose() << " right "
            << views.vertex_side[1][v].transpose();
  }
  const Eigen::Vector3d band_middle =
      0.25 * (band.vertices_body[0] + band.vertices_body[1] +
              band.vertices_body[2] + band.vertices_body[3]);
  const double range =
      (band_middle - context.rectification.left_centre_body()).norm();
  if (range > options.max_band_range_m) {
    VLOG(2) << "band " << i << ": range " << range;
    return BandOutcome::kRejected;
  }
  // An inferred side or end is extrapolated: far away, its error grows
  // past what a control point may carry (a closer exposure sees it).
  const bool extrapolated = pair.inferred >= 0 || known[0].line != nullptr ||
                            known[1].line != nullptr;
  if (extrapolated && range > options.max_inferred_range_m) {
    VLOG(2) << "band " << i << ": extrapolated at range " << range;
    return BandOutcome::kRejected;
  }
  if (end_directions != nullptr && !extrapolated) {
    ObserveEndDirections(context, band.crossing, views, end_directions);
  }
  if (disagreement > options.max_stereo_disagreement_m) {
    VLOG(2) << "band " << i << ": stereo disagreement " << disagreement;
    return BandOutcome::kDisagreement;
  }
  const Eigen::Vector3d& v0 = band.vertices_body[0];
  const Eigen::Vector3d& v1 = band.vertices_body[1];
  const Eigen::Vector3d& v2 = band.vertices_body[2];
  const Eigen::Vector3d& v3 = band.vertices_body[3];
  band.length_m = 0.5 * ((v3 - v0).norm() + (v2 - v1).norm());
  band.width_m = 0.5 * ((v1 - v0).norm() + (v2 - v3).norm()) *
                 std::abs(setup.plane_fit.y_axis.dot((v1 - v0).normalized()));
  if (band.length_m < zebra.min_band_length_m - 0.5 ||
      band.length_m > zebra.max_band_length_m + options.max_length_excess_m) {
    VLOG(2) << "band " << i << ": length " << band.length_m;
    return BandOutcome::kRejected;
  }
  // A painted band is a parallelogram: its ends are parallel.
  const double end_angle = EndAngleRad(band.vertices_body);
  if (!(end_angle <= options.max_end_angle_rad)) {
    VLOG(2) << "band " << i << ": ends " << end_angle << " rad from parallel";
    return BandOutcome::kRejected;
  }
  for (int e = 0; e < 2; ++e) {
    band.end_evidence[e] = known[e].line != nullptr ? EndEvidence::kCrossingLine
                           : known[e].ladder        ? EndEvidence::kLadderBar
                                                    : EndEvidence::kPaintEnd;
  }
  VertexCovariances(context, i, known, setup, views, &band);
  ScoreBand(context, i, known, setup, views, &band);
  *out = band;
  return BandOutcome::kBand;
}

}  // namespace

BandOutcome ModelBand(const BandContext& context, int i,
                      const KnownEnd known[2],
                      std::vector<EndDirectionObservation>* end_directions,
                      Band* out) {
  BandSetup setup;
  if (!SetUpBand(context, i, &setup)) return BandOutcome::kRejected;
  BandViews views;
  views.vertex_sum.fill(Eigen::Vector3d::Zero());
  for (int side = 0; side < 2; ++side) {
    const ViewResult result =
        ModelBandInImage(context, i, known, setup, side, &views);
    if (result == ViewResult::kNoTransversal) {
      return BandOutcome::kNoTransversal;
    }
    if (result == ViewResult::kFailed) return BandOutcome::kRejected;
  }
  return FinishBand(context, i, known, setup, views, end_directions, out);
}

double LongSideStep(const BandContext& context, int i, const EdgeMap& edges,
                    const ImageLine long_lines[2],
                    const Eigen::Vector2d corner[4], int e) {
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < 2; ++k) {
    if (context.bands.pairs[i].inferred == k) continue;
    const Eigen::Vector2d at_end = corner[e == 0 ? k : 3 - k];
    const Eigen::Vector2d other_end = corner[e == 0 ? 3 - k : k];
    const double step = EdgeStep(edges, long_lines[k], at_end,
                                 at_end + 0.4 * (other_end - at_end),
                                 context.options.end_step_profile_px);
    if (std::isfinite(step)) {
      sum += step;
      ++count;
    }
  }
  return count > 0 ? sum / count : std::nan("");
}

double EndAngleRad(const std::array<Eigen::Vector3d, 4>& vertices) {
  const Eigen::Vector3d begin = vertices[1] - vertices[0];
  const Eigen::Vector3d end = vertices[2] - vertices[3];
  return std::atan2(begin.cross(end).norm(), std::abs(begin.dot(end)));
}

}  // namespace zebrageo
