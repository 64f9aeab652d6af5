#include "reconstruction/reconstruction.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "reconstruction/debug_images.h"
#include "survey/image_io.h"
#include "survey/input_error.h"
#include "survey/option_check.h"
#include "survey/threads.h"

namespace zebrageo {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Triangulates the matches: 3D points grouped by left chain, with their
// index along it; `points`: all of them.
void TriangulateMatches(
    const RoadRectification& rect, const EdgeMap& left,
    const std::vector<EdgeMatch>& matches,
    std::vector<std::vector<std::pair<int, EdgePoint3d>>>* by_chain,
    std::vector<Eigen::Vector3d>* points) {
  for (const EdgeMatch& m : matches) {
    EdgePoint3d p;
    if (!rect.Triangulate(m.x_left, m.x_right, m.y, &p.p_body)) continue;
    const EdgePoint& e = left.points[m.left];
    p.xy_left = Eigen::Vector2d(e.x, e.y);
    p.gradient = Eigen::Vector2d(e.gx, e.gy);
    p.index_in_chain = e.index_in_chain;
    (*by_chain)[e.chain].push_back({e.index_in_chain, p});
    points->push_back(p.p_body);
  }
}

// The 3D chains near the road plane `fit` (none when it failed), ordered
// along the left chains (`by_chain` is sorted), their heights regularised.
// `road_xy`, `off_road_xy` (may be null): the left pixels of the points on
// and off the road.
std::vector<EdgeChain3d> ChainsNearRoad(
    const RoadPlaneFit& fit, const Eigen::Vector3d& centre,
    const ReconstructionOptions& options,
    std::vector<std::vector<std::pair<int, EdgePoint3d>>>* by_chain,
    std::vector<Eigen::Vector2d>* road_xy,
    std::vector<Eigen::Vector2d>* off_road_xy) {
  std::vector<EdgeChain3d> chains;
  for (auto& chain : *by_chain) {
    if (chain.empty()) continue;
    std::sort(chain.begin(), chain.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    EdgeChain3d kept;
    for (const auto& [index, p] : chain) {
      const bool near =
          fit.ok && std::abs(fit.plane.SignedDistance(p.p_body)) <=
                        options.road_plane.keep_distance_m;
      if (near) {
        kept.points.push_back(p);
        if (road_xy != nullptr) road_xy->push_back(p.xy_left);
      } else if (off_road_xy != nullptr) {
        off_road_xy->push_back(p.xy_left);
      }
    }
    if (kept.points.size() < 2) continue;
    RegulariseChainHeights(fit.plane, centre,
                           options.long_sides.height_smoothing_half_window,
                           &kept);
    chains.push_back(std::move(kept));
  }
  return chains;
}

}  // namespace

std::string ReconstructionOptions::Check() const {
  OptionCheck check;
  OPTION_NESTED(check, rectification);
  OPTION_NESTED(check, edges);
  OPTION_NESTED(check, matching);
  OPTION_NESTED(check, search);
  OPTION_NESTED(check, road_plane);
  OPTION_NESTED(check, monoplot);
  OPTION_NESTED(check, zebra);
  OPTION_NESTED(check, long_sides);
  OPTION_NESTED(check, bands);
  OPTION_GE(check, threads, 0);
  OPTION_GE(check, batch_exposures, 1);
  return check.problem();
}

double StepTimings::Total() const {
  return read_images_s + rectify_s + edges_s + matching_s + road_plane_s +
         monoplot_s + long_sides_s + bands_s + debug_images_s;
}

void StepTimings::Add(const StepTimings& other) {
  read_images_s += other.read_images_s;
  rectify_s += other.rectify_s;
  edges_s += other.edges_s;
  matching_s += other.matching_s;
  road_plane_s += other.road_plane_s;
  monoplot_s += other.monoplot_s;
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
      << " ms, road plane " << 1e3 * road_plane_s << " ms, monoplot "
      << 1e3 * monoplot_s << " ms, long sides " << 1e3 * long_sides_s
      << " ms, bands " << 1e3 * bands_s << " ms";
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
  if (rectification_.Build(left, right, rectification_plane,
                           options.rectification, &error_)) {
    usable_ = UsableMask(rectification_.valid_mask(), options.edges);
  }
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
  PairWorkspace workspace;
  return Reconstruct(left_image, right_image, prior, slab_half_thickness_m,
                     tolerance_angle_rad, seed, stop_after_road_plane,
                     debug_prefix, &workspace);
}

PairReconstruction StereoPairReconstructor::Reconstruct(
    const cv::Mat& left_image, const cv::Mat& right_image,
    const RoadPlane& prior, double slab_half_thickness_m,
    double tolerance_angle_rad, uint64_t seed, bool stop_after_road_plane,
    const std::string& debug_prefix, PairWorkspace* workspace) const {
  PairReconstruction result;
  const RoadRectification& rect = rectification_;

  double start = ThreadCpuSeconds();
  cv::Mat* const rectified = workspace->rectified;
  rect.Rectify(left_image, right_image, &rectified[0], &rectified[1]);
  result.timings.rectify_s = ThreadCpuSeconds() - start;

  start = ThreadCpuSeconds();
  const EdgeMap* const edges = workspace->edges;
  for (int side = 0; side < 2; ++side) {
    DetectSubpixelEdges(rectified[side], usable_, options_.edges,
                        &workspace->edge_scratch, &workspace->edges[side]);
    result.edge_points[side] = static_cast<int>(edges[side].points.size());
  }
  result.timings.edges_s = ThreadCpuSeconds() - start;

  // Search volume: the residual disparities of the slab around `prior`.
  start = ThreadCpuSeconds();
  const Eigen::Vector3d centre = rect.left_centre_body();
  const DisparityRange range =
      SlabDisparities(rect, prior, slab_half_thickness_m, tolerance_angle_rad);
  const std::vector<EdgeMatch> matches = MatchEdges(
      rectified[0], rectified[1], edges[0], edges[1], range, options_.matching);
  result.matches = static_cast<int>(matches.size());

  // Triangulation into 3D chains (ordered along the left chains).
  std::vector<std::vector<std::pair<int, EdgePoint3d>>> by_chain(
      edges[0].chains.size());
  std::vector<Eigen::Vector3d> points;
  TriangulateMatches(rect, edges[0], matches, &by_chain, &points);
  result.timings.matching_s = ThreadCpuSeconds() - start;

  // Road plane, and the 3D chains near it.
  start = ThreadCpuSeconds();
  const RoadPlaneFit fit =
      FitRoadPlane(points, prior.normal_body, options_.road_plane, seed);
  result.road_plane_ok = fit.ok;
  result.road_plane = fit.ok ? fit.plane : prior;
  result.road_points = static_cast<int>(fit.inliers.size());
  std::vector<Eigen::Vector2d> road_xy, off_road_xy;
  std::vector<EdgeChain3d> chains =
      ChainsNearRoad(fit, centre, options_, &by_chain,
                     debug_prefix.empty() ? nullptr : &road_xy,
                     debug_prefix.empty() ? nullptr : &off_road_xy);
  result.timings.road_plane_s = ThreadCpuSeconds() - start;
  if (stop_after_road_plane || !fit.ok) return result;

  // The edges along the epipolar lines, monoplotted (issue 51).
  start = ThreadCpuSeconds();
  std::vector<EdgeChain3d> monoplotted = MonoplotRowEdges(
      rect, edges[0], by_chain, fit.plane, options_.road_plane.keep_distance_m,
      1.0 / cameras_[0].camera.fx(), options_.monoplot);
  result.monoplotted_chains = static_cast<int>(monoplotted.size());
  for (EdgeChain3d& chain : monoplotted) chains.push_back(std::move(chain));
  result.timings.monoplot_s = ThreadCpuSeconds() - start;
  VLOG(2) << "monoplot: " << result.monoplotted_chains << " chains";

  start = ThreadCpuSeconds();
  const PlaneFrame frame =
      PlaneFrame::Make(fit.plane, rect.R_body_virt().col(0), centre);
  const LongSideDetection detection =
      DetectLongSides(chains, frame, options_.zebra, options_.long_sides);
  result.long_sides = static_cast<int>(detection.sides.size());
  VLOG(2) << "long sides: " << result.long_sides << " in "
          << detection.directions.size() << " directions";
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

// The workspaces of the workers, handed out one per exposure in work and
// taken back after it: a survey's pairs reuse a few workspaces, whichever
// thread runs them.
class WorkspacePool {
 public:
  std::unique_ptr<PairWorkspace> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) return std::make_unique<PairWorkspace>();
    std::unique_ptr<PairWorkspace> workspace = std::move(free_.back());
    free_.pop_back();
    return workspace;
  }
  void Give(std::unique_ptr<PairWorkspace> workspace) {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(std::move(workspace));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<PairWorkspace>> free_;
};

ExposureResult ProcessExposure(
    const Survey& survey, const Exposure& exposure,
    const std::vector<std::unique_ptr<StereoPairReconstructor>>& pairs,
    const ReconstructionOptions& options, const RoadPlane& prior,
    double slab_half_thickness_m, double tolerance_angle_rad,
    bool stop_after_road_plane, bool write_debug, WorkspacePool* pool) {
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
  std::unique_ptr<PairWorkspace> workspace = pool->Take();
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
        debug_prefix, workspace.get());
    result.pair_ran[p] = true;
    result.timings.Add(result.pairs[p].timings);
  }
  pool->Give(std::move(workspace));
  return result;
}

using StereoPairs = std::vector<std::unique_ptr<StereoPairReconstructor>>;

// The rig's stereo pairs rectified for `plane`; null for those that cannot
// be (with a warning in `summary`).
StereoPairs MakePairs(const Rig& rig, const RoadPlane& plane,
                      const ReconstructionOptions& options,
                      ReconstructionSummary* summary) {
  const int num_pairs = static_cast<int>(rig.stereo_pairs.size());
  StereoPairs pairs(num_pairs);
  for (int p = 0; p < num_pairs; ++p) {
    auto pair = std::make_unique<StereoPairReconstructor>(
        rig.cameras[rig.stereo_pairs[p][0]],
        rig.cameras[rig.stereo_pairs[p][1]], plane, options);
    if (pair->ok()) {
      pairs[p] = std::move(pair);
    } else {
      summary->warnings.push_back("stereo pair " + std::to_string(p) +
                                  " cannot be rectified: " + pair->error());
      LOG(WARNING) << summary->warnings.back();
    }
  }
  return pairs;
}

// Step 1: the initial road plane from exposures spread over the survey,
// with a wide search volume around the nominal plane (the nominal plane
// when none is found).
RoadPlane InitialRoadPlane(const Survey& survey, const StereoPairs& pairs,
                           const ReconstructionOptions& options, int threads,
                           const RoadPlane& nominal,
                           ReconstructionSummary* summary) {
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  const std::vector<int> init_exposures = InitializationExposures(
      static_cast<int>(exposures.size()), options.search);
  std::vector<ExposureResult> init_results(init_exposures.size());
  WorkspacePool pool;
  ParallelFor(static_cast<int>(init_exposures.size()), threads, [&](int k) {
    init_results[k] = ProcessExposure(
        survey, exposures[init_exposures[k]], pairs, options, nominal,
        options.search.initial_slab_half_thickness_m,
        options.search.initial_tolerance_angle_rad, true, false, &pool);
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
    summary->warnings.push_back(
        "no road plane found on the initialisation exposures: using the "
        "nominal plane (nominal_camera_height_m)");
    LOG(WARNING) << summary->warnings.back();
  } else {
    running = MedianPlane(init_planes);
  }
  LOG(INFO) << "reconstruct: road plane in the body frame: normal ["
            << running.normal_body.transpose() << "], offset "
            << running.offset_m << " m (from " << init_planes.size()
            << " stereo pairs)";
  return running;
}

// The pairs rectified over the initial road plane `*initial`; when that
// plane leaves fewer pairs usable than the nominal one did (`nominal_pairs`:
// e.g. a plane fitted to left and right images exchanged, tilted so that
// it passes above a camera), it is no road: the nominal plane and its
// pairs are kept, `*initial` set to it, and a warning says so.
StereoPairs PairsOnInitialPlane(const Rig& rig, const RoadPlane& nominal,
                                const ReconstructionOptions& options,
                                StereoPairs nominal_pairs, RoadPlane* initial,
                                ReconstructionSummary* summary) {
  const auto usable = [](const StereoPairs& pairs) {
    return std::count_if(pairs.begin(), pairs.end(),
                         [](const auto& p) { return p != nullptr; });
  };
  ReconstructionSummary trial;
  StereoPairs pairs = MakePairs(rig, *initial, options, &trial);
  if (usable(pairs) >= usable(nominal_pairs)) {
    summary->warnings.insert(summary->warnings.end(), trial.warnings.begin(),
                             trial.warnings.end());
    return pairs;
  }
  summary->warnings.push_back(
      "the road plane found on the initialisation exposures leaves " +
      std::to_string(usable(nominal_pairs) - usable(pairs)) +
      " stereo pair(s) without a road to rectify over (" +
      trial.warnings.front() +
      "): using the nominal plane (nominal_camera_height_m)");
  LOG(WARNING) << summary->warnings.back();
  *initial = nominal;
  return nominal_pairs;
}

// Step 2: all exposures, in time order, batch by batch, each batch with
// the running road plane of the batches before it.
std::vector<ExposureResult> ProcessExposures(
    const Survey& survey, const StereoPairs& pairs,
    const ReconstructionOptions& options, int threads,
    const ProgressCallback& progress, const CancellationToken& cancel,
    RoadPlaneTracker* running) {
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  std::vector<ExposureResult> results(exposures.size());
  std::mutex progress_mutex;
  int done = 0;
  const int total = static_cast<int>(exposures.size());
  WorkspacePool pool;
  for (int begin = 0; begin < total; begin += options.batch_exposures) {
    const int end = std::min(total, begin + options.batch_exposures);
    const RoadPlane prior = running->plane();
    ParallelFor(end - begin, threads, [&](int k) {
      cancel.ThrowIfCancelled();  // between exposures
      results[begin + k] =
          ProcessExposure(survey, exposures[begin + k], pairs, options, prior,
                          options.search.slab_half_thickness_m,
                          options.search.tolerance_angle_rad, false,
                          !options.debug_image_folder.empty(), &pool);
      if (progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        progress(++done, total);
      }
    });
    for (int e = begin; e < end; ++e) {
      const ExposureResult& r = results[e];
      for (size_t p = 0; p < r.pairs.size(); ++p) {
        if (!r.pair_ran[p] || !r.pairs[p].road_plane_ok) continue;
        running->Add(r.pairs[p].road_plane);
      }
    }
    running->Update();
  }
  return results;
}

// The vertices of the bands of one stereo pair, band_id and group_id
// continuing from the given ones.
void AppendPairVertices(const StereoPairReconstructor& reconstructor,
                        const PairReconstruction& pair, int64_t exposure_id,
                        int p, int64_t* band_id, int64_t* group_id,
                        ReconstructionSummary* summary,
                        std::vector<ReconstructedVertex>* vertices) {
  std::map<int, int64_t> group_of_crossing;
  for (const Band& band : pair.bands) {
    std::array<Eigen::Vector2d, 4> uv[2];
    bool projected = true;
    for (int v = 0; v < 4; ++v) {
      for (int side = 0; side < 2; ++side) {
        projected = projected && reconstructor.ProjectToOriginal(
                                     side, band.vertices_body[v], &uv[side][v]);
      }
    }
    if (!projected) continue;  // cannot happen for a band on the road
    if (!group_of_crossing.count(band.crossing)) {
      group_of_crossing[band.crossing] = ++*group_id;
    }
    ++*band_id;
    ++summary->bands;
    for (int v = 0; v < 4; ++v) {
      ReconstructedVertex vertex;
      vertex.exposure_id = exposure_id;
      vertex.pair = p;
      vertex.band_id = *band_id;
      vertex.group_id = group_of_crossing[band.crossing];
      vertex.vertex = v;
      vertex.p_body = band.vertices_body[v];
      vertex.covariance_body = band.covariances_body[v];
      vertex.uv_left = uv[0][v];
      vertex.uv_right = uv[1][v];
      vertex.score = band.score;
      vertex.end_evidence =
          EndEvidenceName(band.end_evidence[v == 0 || v == 1 ? 0 : 1]);
      vertices->push_back(vertex);
    }
  }
}

// Step 3: the output, in a deterministic order, and the counts.
void AppendVertices(const std::vector<Exposure>& exposures,
                    const std::vector<ExposureResult>& results,
                    const StereoPairs& pairs, ReconstructionSummary* summary,
                    std::vector<ReconstructedVertex>* vertices) {
  int64_t band_id = 0;
  int64_t group_id = 0;
  const int num_pairs = static_cast<int>(pairs.size());
  for (size_t e = 0; e < exposures.size(); ++e) {
    const ExposureResult& r = results[e];
    if (r.skipped) {
      ++summary->exposures_skipped;
      summary->skipped_exposures.emplace_back(exposures[e].exposure_id,
                                              r.warning);
      summary->warnings.push_back(r.warning);
      LOG(WARNING) << r.warning;
      continue;
    }
    ++summary->exposures_processed;
    summary->timings.Add(r.timings);
    for (int p = 0; p < num_pairs; ++p) {
      if (!r.pair_ran[p]) continue;
      ++summary->pairs_processed;
      const PairReconstruction& pair = r.pairs[p];
      if (!pair.road_plane_ok) ++summary->pairs_without_road;
      AppendPairVertices(*pairs[p], pair, exposures[e].exposure_id, p, &band_id,
                         &group_id, summary, vertices);
    }
  }
  summary->crossings = static_cast<int>(group_id);
}

}  // namespace

ReconstructionSummary ReconstructSurvey(
    const Survey& survey, const ReconstructionOptions& options,
    std::vector<ReconstructedVertex>* vertices,
    const ProgressCallback& progress, const CancellationToken& cancel) {
  const Clock::time_point wall_start = Clock::now();
  ReconstructionSummary summary;
  summary.message = options.Check();
  if (!summary.message.empty()) return summary;
  PrepareImageCodecs();  // before the worker threads read images
  const Rig& rig = survey.rig;
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  summary.exposures = static_cast<int>(exposures.size());
  const int threads =
      options.threads > 0
          ? options.threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (rig.stereo_pairs.empty()) {
    summary.message = "the rig has no stereo pair";
    return summary;
  }
  if (!options.debug_image_folder.empty()) {
    std::filesystem::create_directories(options.debug_image_folder);
  }
  const RoadPlane nominal = NominalRoadPlane(rig, options.search);
  StereoPairs pairs = MakePairs(rig, nominal, options, &summary);
  if (std::none_of(pairs.begin(), pairs.end(),
                   [](const auto& p) { return p != nullptr; })) {
    summary.message =
        "no stereo pair of the rig can be rectified over the "
        "road: " +
        summary.warnings.front();
    return summary;
  }
  RoadPlane initial =
      InitialRoadPlane(survey, pairs, options, threads, nominal, &summary);
  pairs = PairsOnInitialPlane(rig, nominal, options, std::move(pairs), &initial,
                              &summary);
  summary.initial_road_plane = initial;
  RoadPlaneTracker running(initial, options.search);
  const std::vector<ExposureResult> results = ProcessExposures(
      survey, pairs, options, threads, progress, cancel, &running);
  summary.final_road_plane = running.plane();
  AppendVertices(exposures, results, pairs, &summary, vertices);
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
