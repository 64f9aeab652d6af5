#include "reconstruction/reconstruction.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>
#include <tuple>

#include "survey/image_io.h"
#include "survey/input_error.h"
#include "survey/threads.h"

namespace zebrageo {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Median(std::vector<double> values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// Component-wise median of plane normals and offsets: robust to a few
// wrong per-pair fits.
RoadPlane MedianPlane(const std::vector<RoadPlane>& planes) {
  std::vector<double> x, y, z, offset;
  for (const RoadPlane& p : planes) {
    x.push_back(p.normal_body.x());
    y.push_back(p.normal_body.y());
    z.push_back(p.normal_body.z());
    offset.push_back(p.offset_m);
  }
  RoadPlane plane;
  plane.normal_body =
      Eigen::Vector3d(Median(x), Median(y), Median(z)).normalized();
  plane.offset_m = Median(offset);
  return plane;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0));
}

cv::Point ToPoint(const Eigen::Vector2d& p) {
  // 4 fractional bits for sub-pixel drawing.
  return cv::Point(static_cast<int>(std::lround(p.x() * 16.0)),
                   static_cast<int>(std::lround(p.y() * 16.0)));
}

cv::Mat ToBgr(const cv::Mat& gray32) {
  cv::Mat gray8, bgr;
  gray32.convertTo(gray8, CV_8U);
  cv::cvtColor(gray8, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

// Debug images: the rectified left image with edges (grey: unmatched,
// green: 3D points near the road, red: off the road), long sides (yellow),
// band side pairs (orange), transversal search areas (cyan), Hough
// candidates (magenta) and final bands (blue); and the original left image
// with the final bands' vertices.
void WriteDebugImages(const std::string& prefix, const cv::Mat& rectified,
                      const cv::Mat& original, const EdgeMap& edges,
                      const std::vector<Eigen::Vector2d>& road_points,
                      const std::vector<Eigen::Vector2d>& off_road_points,
                      const LongSideDetection& detection,
                      const BandModelingDebug& band_debug,
                      const std::vector<Band>& bands,
                      const StereoPairReconstructor& pair) {
  const RoadRectification& rectification = pair.rectification();
  cv::Mat image = ToBgr(rectified);
  // Pixels outside the valid area are tinted red.
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      if (!rectification.IsValid(x, y)) {
        image.at<cv::Vec3b>(y, x)[2] = static_cast<uint8_t>(
            std::min(255, image.at<cv::Vec3b>(y, x)[2] + 60));
      }
    }
  }
  for (const EdgePoint& e : edges.points) {
    image.at<cv::Vec3b>(e.py, e.px) = cv::Vec3b(128, 128, 128);
  }
  auto dot = [&](const Eigen::Vector2d& p, const cv::Vec3b& colour) {
    const int x = static_cast<int>(std::lround(p.x()));
    const int y = static_cast<int>(std::lround(p.y()));
    if (x >= 0 && y >= 0 && x < image.cols && y < image.rows) {
      image.at<cv::Vec3b>(y, x) = colour;
    }
  };
  for (const Eigen::Vector2d& p : off_road_points) dot(p, {0, 0, 255});
  for (const Eigen::Vector2d& p : road_points) dot(p, {0, 255, 0});
  auto line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                  const cv::Scalar& colour, int thickness) {
    cv::line(image, ToPoint(a), ToPoint(b), colour, thickness, cv::LINE_AA, 4);
  };
  for (const LongSide& side : detection.sides) {
    Eigen::Vector2d a, b;
    if (rectification.ProjectToRectified(0, side.Begin(), &a) &&
        rectification.ProjectToRectified(0, side.End(), &b)) {
      line(a, b, cv::Scalar(0, 255, 255), 1);
    }
  }
  for (const auto& segment : band_debug.band_pairs) {
    line(segment[0], segment[1], cv::Scalar(0, 128, 255), 2);
  }
  for (const auto& area : band_debug.search_areas) {
    for (int k = 0; k < 4; ++k) {
      line(area[k], area[(k + 1) % 4], cv::Scalar(255, 255, 0), 1);
    }
  }
  for (const auto& segment : band_debug.candidate_lines) {
    line(segment[0], segment[1], cv::Scalar(255, 0, 255), 1);
  }
  cv::Mat original_bgr = ToBgr(original);
  for (const Band& band : bands) {
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d a, b, ua, ub;
      if (rectification.ProjectToRectified(0, band.vertices_body[k], &a) &&
          rectification.ProjectToRectified(0, band.vertices_body[(k + 1) % 4],
                                           &b)) {
        line(a, b, cv::Scalar(255, 0, 0), 2);
      }
      if (pair.ProjectToOriginal(0, band.vertices_body[k], &ua) &&
          pair.ProjectToOriginal(0, band.vertices_body[(k + 1) % 4], &ub)) {
        cv::line(original_bgr, ToPoint(ua), ToPoint(ub), cv::Scalar(255, 0, 0),
                 1, cv::LINE_AA, 4);
      }
    }
  }
  cv::imwrite(prefix + "_rectified.png", image);
  cv::imwrite(prefix + "_left.png", original_bgr);
}

}  // namespace

std::string SearchVolumeOptions::Check() const {
  std::ostringstream error;
  if (!(std::abs(nominal_road_normal_body.norm() - 1.0) < 1e-3)) {
    error << "nominal_road_normal_body = ["
          << nominal_road_normal_body.transpose() << "]: must be a unit vector";
  } else if (!(nominal_camera_height_m > 0.0)) {
    error << "nominal_camera_height_m = " << nominal_camera_height_m
          << ": must be > 0";
  } else if (!(initial_slab_half_thickness_m > 0.0 &&
               initial_slab_half_thickness_m < nominal_camera_height_m)) {
    error << "initial_slab_half_thickness_m = " << initial_slab_half_thickness_m
          << ": must be in (0, nominal_camera_height_m)";
  } else if (!(initial_tolerance_angle_rad >= 0.0 &&
               initial_tolerance_angle_rad < 0.5)) {
    error << "initial_tolerance_angle_rad = " << initial_tolerance_angle_rad
          << ": must be in [0, 0.5)";
  } else if (initialization_exposures < 1) {
    error << "initialization_exposures = " << initialization_exposures
          << ": must be >= 1";
  } else if (!(slab_half_thickness_m > 0.0)) {
    error << "slab_half_thickness_m = " << slab_half_thickness_m
          << ": must be > 0";
  } else if (!(tolerance_angle_rad >= 0.0 && tolerance_angle_rad < 0.5)) {
    error << "tolerance_angle_rad = " << tolerance_angle_rad
          << ": must be in [0, 0.5)";
  } else if (running_window < 1) {
    error << "running_window = " << running_window << ": must be >= 1";
  } else if (!(max_plane_change_rad > 0.0)) {
    error << "max_plane_change_rad = " << max_plane_change_rad
          << ": must be > 0";
  } else if (!(max_plane_change_m > 0.0)) {
    error << "max_plane_change_m = " << max_plane_change_m << ": must be > 0";
  }
  return error.str();
}

std::string ReconstructionOptions::Check() const {
  for (const std::string& error :
       {rectification.Check(), edges.Check(), matching.Check(), search.Check(),
        road_plane.Check(), zebra.Check(), long_sides.Check(), bands.Check()}) {
    if (!error.empty()) return error;
  }
  std::ostringstream error;
  if (threads < 0) {
    error << "threads = " << threads << ": must be >= 0";
  } else if (batch_exposures < 1) {
    error << "batch_exposures = " << batch_exposures << ": must be >= 1";
  }
  return error.str();
}

double StepTimings::Total() const {
  return read_images_s + rectify_s + edges_s + matching_s + road_plane_s +
         long_sides_s + bands_s + debug_images_s;
}

void StepTimings::Add(const StepTimings& other) {
  read_images_s += other.read_images_s;
  rectify_s += other.rectify_s;
  edges_s += other.edges_s;
  matching_s += other.matching_s;
  road_plane_s += other.road_plane_s;
  long_sides_s += other.long_sides_s;
  bands_s += other.bands_s;
  debug_images_s += other.debug_images_s;
}

std::string StepTimings::Report() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "read " << 1e3 * read_images_s << " ms, rectify " << 1e3 * rectify_s
      << " ms, edges " << 1e3 * edges_s << " ms, matching " << 1e3 * matching_s
      << " ms, road plane " << 1e3 * road_plane_s << " ms, long sides "
      << 1e3 * long_sides_s << " ms, bands " << 1e3 * bands_s << " ms";
  if (debug_images_s > 0.0) {
    out << ", debug images " << 1e3 * debug_images_s << " ms";
  }
  out << " (total " << 1e3 * Total() << " ms)";
  return out.str();
}

StereoPairReconstructor::StereoPairReconstructor(
    const RigCamera& left, const RigCamera& right,
    const RoadPlane& rectification_plane, const ReconstructionOptions& options)
    : cameras_{left, right}, options_(options) {
  rectification_.Build(left, right, rectification_plane, options.rectification,
                       &error_);
}

bool StereoPairReconstructor::ProjectToOriginal(int side,
                                                const Eigen::Vector3d& p_body,
                                                Eigen::Vector2d* uv) const {
  const Eigen::Vector3d p_cam = cameras_[side].T_body_cam.inverse() * p_body;
  return cameras_[side].camera.Project(p_cam, uv);
}

PairReconstruction StereoPairReconstructor::Reconstruct(
    const cv::Mat& left_image, const cv::Mat& right_image,
    const RoadPlane& prior, double slab_half_thickness_m,
    double tolerance_angle_rad, uint64_t seed, bool stop_after_road_plane,
    const std::string& debug_prefix) const {
  PairReconstruction result;
  const RoadRectification& rect = rectification_;

  double start = ThreadCpuSeconds();
  cv::Mat rectified[2];
  rect.Rectify(left_image, right_image, &rectified[0], &rectified[1]);
  result.timings.rectify_s = ThreadCpuSeconds() - start;

  start = ThreadCpuSeconds();
  EdgeMap edges[2];
  for (int side = 0; side < 2; ++side) {
    edges[side] =
        DetectSubpixelEdges(rectified[side], rect.valid_mask(), options_.edges);
    result.edge_points[side] = static_cast<int>(edges[side].points.size());
  }
  result.timings.edges_s = ThreadCpuSeconds() - start;

  // Search volume: the residual disparities of the slab around `prior`.
  start = ThreadCpuSeconds();
  const Eigen::Vector3d centre = rect.left_centre_body();
  const Eigen::Vector3d nadir = prior.Project(centre);
  const double fb = rect.focal_px() * rect.baseline_m();
  const double tan_theta = std::tan(tolerance_angle_rad);
  const DisparityRange range = [&](double x, double y, double* d_min,
                                   double* d_max) {
    // The virtual z component of RayBody is 1, so the ray parameter of a
    // plane crossing is the depth Z, and the disparity is fB / Z.
    const Eigen::Vector3d ray = rect.RayBody(0, Eigen::Vector2d(x, y));
    const double denominator = prior.normal_body.dot(ray);
    if (!(denominator > 1e-9)) return false;
    const double depth =
        (prior.offset_m - prior.normal_body.dot(centre)) / denominator;
    if (!(depth > 0.0)) return false;
    const double distance = (centre + depth * ray - nadir).norm();
    const double half = slab_half_thickness_m + distance * tan_theta;
    const double near =
        (prior.offset_m - half - prior.normal_body.dot(centre)) / denominator;
    const double far =
        (prior.offset_m + half - prior.normal_body.dot(centre)) / denominator;
    if (!(far > 0.0)) return false;
    *d_min = fb / far - rect.disparity_offset_px();
    *d_max = (near > 0.0 ? fb / near : 1e9) - rect.disparity_offset_px();
    return true;
  };
  const std::vector<EdgeMatch> matches = MatchEdges(
      rectified[0], rectified[1], edges[0], edges[1], range, options_.matching);
  result.matches = static_cast<int>(matches.size());

  // Triangulation into 3D chains (ordered along the left chains).
  std::vector<std::vector<std::pair<int, EdgePoint3d>>> by_chain(
      edges[0].chains.size());
  std::vector<Eigen::Vector3d> points;
  for (const EdgeMatch& m : matches) {
    EdgePoint3d p;
    if (!rect.Triangulate(m.x_left, m.x_right, m.y, &p.p_body)) continue;
    const EdgePoint& e = edges[0].points[m.left];
    p.xy_left = Eigen::Vector2d(e.x, e.y);
    p.gradient = Eigen::Vector2d(e.gx, e.gy);
    p.index_in_chain = e.index_in_chain;
    by_chain[e.chain].push_back({e.index_in_chain, p});
    points.push_back(p.p_body);
  }
  result.timings.matching_s = ThreadCpuSeconds() - start;

  // Road plane, and the 3D chains near it.
  start = ThreadCpuSeconds();
  const RoadPlaneFit fit =
      FitRoadPlane(points, prior.normal_body, options_.road_plane, seed);
  result.road_plane_ok = fit.ok;
  result.road_plane = fit.ok ? fit.plane : prior;
  result.road_points = static_cast<int>(fit.inliers.size());
  std::vector<EdgeChain3d> chains;
  std::vector<Eigen::Vector2d> road_xy, off_road_xy;
  for (auto& chain : by_chain) {
    if (chain.empty()) continue;
    std::sort(chain.begin(), chain.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    EdgeChain3d kept;
    for (const auto& [index, p] : chain) {
      const bool near =
          fit.ok && std::abs(fit.plane.SignedDistance(p.p_body)) <=
                        options_.road_plane.keep_distance_m;
      if (near) {
        kept.points.push_back(p);
        if (!debug_prefix.empty()) road_xy.push_back(p.xy_left);
      } else if (!debug_prefix.empty()) {
        off_road_xy.push_back(p.xy_left);
      }
    }
    if (kept.points.size() < 2) continue;
    RegulariseChainHeights(fit.plane, centre,
                           options_.long_sides.height_smoothing_half_window,
                           &kept);
    chains.push_back(std::move(kept));
  }
  result.timings.road_plane_s = ThreadCpuSeconds() - start;
  if (stop_after_road_plane || !fit.ok) return result;

  start = ThreadCpuSeconds();
  const PlaneFrame frame =
      PlaneFrame::Make(fit.plane, rect.R_body_virt().col(0), centre);
  const LongSideDetection detection =
      DetectLongSides(chains, frame, options_.zebra, options_.long_sides);
  result.long_sides = static_cast<int>(detection.sides.size());
  result.timings.long_sides_s = ThreadCpuSeconds() - start;

  start = ThreadCpuSeconds();
  BandModelingDebug band_debug;
  result.bands =
      ModelBands(detection, frame, rect, edges, options_.zebra, options_.bands,
                 debug_prefix.empty() ? nullptr : &band_debug);
  result.timings.bands_s = ThreadCpuSeconds() - start;

  if (!debug_prefix.empty()) {
    start = ThreadCpuSeconds();
    WriteDebugImages(debug_prefix, rectified[0], left_image, edges[0], road_xy,
                     off_road_xy, detection, band_debug, result.bands, *this);
    result.timings.debug_images_s = ThreadCpuSeconds() - start;
  }
  return result;
}

std::string ReconstructionSummary::BriefReport() const {
  std::ostringstream out;
  out << bands << " bands in " << crossings << " crossing groups from "
      << pairs_processed << " stereo pairs (" << exposures_processed << " of "
      << exposures << " exposures";
  if (exposures_skipped > 0) out << ", " << exposures_skipped << " skipped";
  out << "), " << pairs_without_road << " pairs without a road plane";
  return out.str();
}

namespace {

// One unit of work: all stereo pairs of one exposure.
struct ExposureResult {
  bool skipped = false;
  std::string warning;
  std::vector<PairReconstruction> pairs;  // one per rig stereo pair, or empty
  std::vector<bool> pair_ran;
  StepTimings timings;
};

ExposureResult ProcessExposure(
    const Survey& survey, const Exposure& exposure,
    const std::vector<std::unique_ptr<StereoPairReconstructor>>& pairs,
    const ReconstructionOptions& options, const RoadPlane& prior,
    double slab_half_thickness_m, double tolerance_angle_rad,
    bool stop_after_road_plane, bool write_debug) {
  ExposureResult result;
  const Rig& rig = survey.rig;
  const int num_pairs = static_cast<int>(rig.stereo_pairs.size());
  result.pairs.resize(num_pairs);
  result.pair_ran.assign(num_pairs, false);
  // Read each needed camera's image once; any failure skips the exposure.
  const double start = ThreadCpuSeconds();
  std::map<int, cv::Mat> images;
  for (int p = 0; p < num_pairs; ++p) {
    for (int camera : rig.stereo_pairs[p]) {
      if (images.count(camera)) continue;
      const int index = exposure.image_of_camera[camera];
      if (index < 0) {
        result.skipped = true;
        result.warning = "exposure " + std::to_string(exposure.exposure_id) +
                         " has no image of camera " +
                         rig.cameras[camera].camera.name() +
                         ": exposure skipped";
        return result;
      }
      const ExposureImage& image = survey.exposures.images[index];
      try {
        images[camera] = ReadGrayImage(survey.PathOf(image.image), image.image,
                                       rig.cameras[camera].camera.width(),
                                       rig.cameras[camera].camera.height());
      } catch (const std::exception& error) {
        result.skipped = true;
        result.warning = "exposure " + std::to_string(exposure.exposure_id) +
                         ": " + error.what() + ": exposure skipped";
        return result;
      }
    }
  }
  result.timings.read_images_s = ThreadCpuSeconds() - start;
  for (int p = 0; p < num_pairs; ++p) {
    if (!pairs[p]) continue;
    const uint64_t seed =
        options.seed * 0x9E3779B97F4A7C15ull +
        static_cast<uint64_t>(exposure.exposure_id) * 1000003ull +
        static_cast<uint64_t>(p);
    std::string debug_prefix;
    if (write_debug) {
      debug_prefix = (std::filesystem::path(options.debug_image_folder) /
                      ("exposure" + std::to_string(exposure.exposure_id) +
                       "_pair" + std::to_string(p)))
                         .string();
    }
    VLOG(2) << "exposure " << exposure.exposure_id << " pair " << p;
    result.pairs[p] = pairs[p]->Reconstruct(
        images[rig.stereo_pairs[p][0]], images[rig.stereo_pairs[p][1]], prior,
        slab_half_thickness_m, tolerance_angle_rad, seed, stop_after_road_plane,
        debug_prefix);
    result.pair_ran[p] = true;
    result.timings.Add(result.pairs[p].timings);
  }
  return result;
}

}  // namespace

ReconstructionSummary ReconstructSurvey(
    const Survey& survey, const ReconstructionOptions& options,
    std::vector<ReconstructedVertex>* vertices,
    const ProgressCallback& progress) {
  const Clock::time_point wall_start = Clock::now();
  ReconstructionSummary summary;
  summary.message = options.Check();
  if (!summary.message.empty()) return summary;
  const Rig& rig = survey.rig;
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  summary.exposures = static_cast<int>(exposures.size());
  const int threads =
      options.threads > 0
          ? options.threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int num_pairs = static_cast<int>(rig.stereo_pairs.size());
  if (num_pairs == 0) {
    summary.message = "the rig has no stereo pair";
    return summary;
  }
  if (!options.debug_image_folder.empty()) {
    std::filesystem::create_directories(options.debug_image_folder);
  }

  // Nominal plane: nominal_camera_height_m below the stereo cameras.
  RoadPlane nominal;
  nominal.normal_body = options.search.nominal_road_normal_body.normalized();
  {
    double mean_depth = 0.0;
    int count = 0;
    for (const auto& pair : rig.stereo_pairs) {
      for (int camera : pair) {
        mean_depth += nominal.normal_body.dot(
            rig.cameras[camera].T_body_cam.translation());
        ++count;
      }
    }
    nominal.offset_m =
        mean_depth / count + options.search.nominal_camera_height_m;
  }
  auto make_pairs = [&](const RoadPlane& plane) {
    std::vector<std::unique_ptr<StereoPairReconstructor>> pairs(num_pairs);
    for (int p = 0; p < num_pairs; ++p) {
      auto pair = std::make_unique<StereoPairReconstructor>(
          rig.cameras[rig.stereo_pairs[p][0]],
          rig.cameras[rig.stereo_pairs[p][1]], plane, options);
      if (pair->ok()) {
        pairs[p] = std::move(pair);
      } else {
        summary.warnings.push_back("stereo pair " + std::to_string(p) +
                                   " cannot be rectified: " + pair->error());
        LOG(WARNING) << summary.warnings.back();
      }
    }
    return pairs;
  };

  // 1. Initial road plane from exposures spread over the survey, with a
  // wide search volume around the nominal plane.
  std::vector<std::unique_ptr<StereoPairReconstructor>> pairs =
      make_pairs(nominal);
  if (std::none_of(pairs.begin(), pairs.end(),
                   [](const auto& p) { return p != nullptr; })) {
    summary.message =
        "no stereo pair of the rig can be rectified over the "
        "road: " +
        summary.warnings.front();
    return summary;
  }
  std::vector<int> init_exposures;
  {
    const int n = static_cast<int>(exposures.size());
    const int wanted = std::min(n, options.search.initialization_exposures);
    for (int k = 0; k < wanted; ++k) {
      const int index = static_cast<int>((k + 0.5) * n / wanted);
      if (init_exposures.empty() || init_exposures.back() != index) {
        init_exposures.push_back(std::min(index, n - 1));
      }
    }
  }
  std::vector<ExposureResult> init_results(init_exposures.size());
  ParallelFor(static_cast<int>(init_exposures.size()), threads, [&](int k) {
    init_results[k] = ProcessExposure(
        survey, exposures[init_exposures[k]], pairs, options, nominal,
        options.search.initial_slab_half_thickness_m,
        options.search.initial_tolerance_angle_rad, true, false);
  });
  std::vector<RoadPlane> init_planes;
  for (const ExposureResult& r : init_results) {
    for (size_t p = 0; p < r.pairs.size(); ++p) {
      if (r.pair_ran[p] && r.pairs[p].road_plane_ok) {
        init_planes.push_back(r.pairs[p].road_plane);
      }
    }
  }
  RoadPlane running = nominal;
  if (init_planes.empty()) {
    summary.warnings.push_back(
        "no road plane found on the initialisation exposures: using the "
        "nominal plane (nominal_camera_height_m)");
    LOG(WARNING) << summary.warnings.back();
  } else {
    running = MedianPlane(init_planes);
  }
  summary.initial_road_plane = running;
  LOG(INFO) << "reconstruct: road plane in the body frame: normal ["
            << running.normal_body.transpose() << "], offset "
            << running.offset_m << " m (from " << init_planes.size()
            << " stereo pairs)";
  pairs = make_pairs(running);

  // 2. All exposures, in time order, batch by batch.
  std::vector<ExposureResult> results(exposures.size());
  std::deque<RoadPlane> recent;
  std::mutex progress_mutex;
  int done = 0;
  const int total = static_cast<int>(exposures.size());
  for (int begin = 0; begin < total; begin += options.batch_exposures) {
    const int end = std::min(total, begin + options.batch_exposures);
    const RoadPlane prior = running;
    ParallelFor(end - begin, threads, [&](int k) {
      results[begin + k] =
          ProcessExposure(survey, exposures[begin + k], pairs, options, prior,
                          options.search.slab_half_thickness_m,
                          options.search.tolerance_angle_rad, false,
                          !options.debug_image_folder.empty());
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress(++done, total);
      }
    });
    for (int e = begin; e < end; ++e) {
      const ExposureResult& r = results[e];
      for (size_t p = 0; p < r.pairs.size(); ++p) {
        if (!r.pair_ran[p] || !r.pairs[p].road_plane_ok) continue;
        const RoadPlane& plane = r.pairs[p].road_plane;
        if (AngleBetween(plane.normal_body, running.normal_body) >
                options.search.max_plane_change_rad ||
            std::abs(plane.offset_m - running.offset_m) >
                options.search.max_plane_change_m) {
          continue;
        }
        recent.push_back(plane);
        if (static_cast<int>(recent.size()) > options.search.running_window) {
          recent.pop_front();
        }
      }
    }
    if (!recent.empty()) {
      running =
          MedianPlane(std::vector<RoadPlane>(recent.begin(), recent.end()));
    }
  }
  summary.final_road_plane = running;

  // 3. Output, in a deterministic order.
  int64_t band_id = 0;
  int64_t group_id = 0;
  for (size_t e = 0; e < exposures.size(); ++e) {
    const ExposureResult& r = results[e];
    if (r.skipped) {
      ++summary.exposures_skipped;
      summary.skipped_exposures.emplace_back(exposures[e].exposure_id,
                                             r.warning);
      summary.warnings.push_back(r.warning);
      LOG(WARNING) << r.warning;
      continue;
    }
    ++summary.exposures_processed;
    summary.timings.Add(r.timings);
    for (int p = 0; p < num_pairs; ++p) {
      if (!r.pair_ran[p]) continue;
      ++summary.pairs_processed;
      const PairReconstruction& pair = r.pairs[p];
      if (!pair.road_plane_ok) ++summary.pairs_without_road;
      std::map<int, int64_t> group_of_crossing;
      for (const Band& band : pair.bands) {
        std::array<Eigen::Vector2d, 4> uv[2];
        bool projected = true;
        for (int v = 0; v < 4; ++v) {
          for (int side = 0; side < 2; ++side) {
            projected =
                projected && pairs[p]->ProjectToOriginal(
                                 side, band.vertices_body[v], &uv[side][v]);
          }
        }
        if (!projected) continue;  // cannot happen for a band on the road
        if (!group_of_crossing.count(band.crossing)) {
          group_of_crossing[band.crossing] = ++group_id;
        }
        ++band_id;
        ++summary.bands;
        for (int v = 0; v < 4; ++v) {
          ReconstructedVertex vertex;
          vertex.exposure_id = exposures[e].exposure_id;
          vertex.pair = p;
          vertex.band_id = band_id;
          vertex.group_id = group_of_crossing[band.crossing];
          vertex.vertex = v;
          vertex.p_body = band.vertices_body[v];
          vertex.covariance_body = band.covariances_body[v];
          vertex.uv_left = uv[0][v];
          vertex.uv_right = uv[1][v];
          vertex.score = band.score;
          vertices->push_back(vertex);
        }
      }
    }
  }
  summary.crossings = static_cast<int>(group_id);
  summary.wall_time_s = SecondsSince(wall_start);
  if (summary.bands == 0) {
    summary.warnings.push_back("no zebra band was reconstructed");
    LOG(WARNING) << summary.warnings.back();
  }
  if (summary.pairs_processed == 0) {
    summary.message = "no stereo pair could be processed";
    return summary;
  }
  summary.usable = true;
  summary.message = summary.BriefReport();
  return summary;
}

}  // namespace zebrageo
