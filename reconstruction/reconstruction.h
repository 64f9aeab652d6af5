// 3D zebra-crossing reconstruction from the stereo pairs of a survey
// (Soheilian, Paparoditis, Boldo, Rudant: "3D zebra-crossing reconstruction
// from stereo rig images of a ground-based mobile mapping system", ISPRS
// 2006), GitHub issue 5.
//
// For each stereo pair of each exposure:
//   1. rectification to road-plane ("vertical") epipolar geometry,
//      distortion removed (road_rectification.h);
//   2. sub-pixel Canny/Devernay edges and chains (subpixel_edges.h);
//   3. edge matching by dynamic programming inside the search volume (a
//      slab around the road plane), sub-pixel disparity, triangulation to
//      3D edge chains (edge_matching.h);
//   4. road plane by RANSAC + least squares, edges near it (road_plane.h);
//      the edges along the epipolar lines, which no disparity measures,
//      monoplotted on the local road surface (monoplot.h, issue 51);
//   5. long sides: polygonisation, accumulator, grouping (long_sides.h);
//   6. bands: side pairs, band planes, Hough transversal sides, vertices and
//      covariances (band_modeling.h).
//
// The rig height over the road is not in the survey: the road plane in the
// body frame is first estimated on a few exposures spread over the survey
// with a wide search volume around a nominal plane, then tracked (median of
// the latest per-pair fits) while exposures are processed in time order.
//
// Frames: body (FRD) metres for every 3D output; image coordinates of the
// outputs are pixels of the ORIGINAL (distorted) images, (0, 0) the centre
// of the top-left pixel.
#ifndef ZEBRAGEO_RECONSTRUCTION_RECONSTRUCTION_H_
#define ZEBRAGEO_RECONSTRUCTION_RECONSTRUCTION_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "reconstruction/band_modeling.h"
#include "reconstruction/edge_matching.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/monoplot.h"
#include "reconstruction/road_plane.h"
#include "reconstruction/road_rectification.h"
#include "reconstruction/search_volume.h"
#include "reconstruction/subpixel_edges.h"
#include "survey/cancellation.h"
#include "survey/results.h"
#include "survey/rig.h"
#include "survey/survey.h"

namespace zebrageo {

struct ReconstructionOptions {
  RectificationOptions rectification;
  EdgeOptions edges;
  MatchingOptions matching;
  SearchVolumeOptions search;
  RoadPlaneOptions road_plane;
  MonoplotOptions monoplot;
  ZebraSpecification zebra;
  LongSideOptions long_sides;
  BandOptions bands;
  // Worker threads over exposures; 0: one per hardware thread. The output
  // does not depend on it.
  int threads = 0;
  // Exposures are processed in batches of this size, in time order; the
  // running road plane is updated between batches (so results do not
  // depend on the number of threads).
  int batch_exposures = 16;
  // When not empty, images with edges, candidates and final bands are
  // written there for a person to check.
  std::string debug_image_folder;
  uint64_t seed = 1;  // RANSAC

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("rectification", rectification);
    v("edges", edges);
    v("matching", matching);
    v("search", search);
    v("road_plane", road_plane);
    v("monoplot", monoplot);
    v("zebra", zebra);
    v("long_sides", long_sides);
    v("bands", bands);
    v("threads", threads);
    v("batch_exposures", batch_exposures);
    v("debug_image_folder", debug_image_folder);
    v("seed", seed);
  }
};

// Seconds spent in each step, summed over stereo pairs (CPU time of the
// workers, not wall time).
struct StepTimings {
  double read_images_s = 0.0;
  double rectify_s = 0.0;
  double edges_s = 0.0;
  double matching_s = 0.0;
  double road_plane_s = 0.0;
  double monoplot_s = 0.0;  // issue 51: edges along the epipolar lines
  double long_sides_s = 0.0;
  double bands_s = 0.0;
  double debug_images_s = 0.0;

  double Total() const;
  void Add(const StepTimings& other);
  std::string Report() const;  // "rectify 12.3 ms, edges ..." per pair
};

// The result of one stereo pair.
struct PairReconstruction {
  bool road_plane_ok = false;
  RoadPlane road_plane;  // body frame
  std::vector<Band> bands;
  int edge_points[2] = {0, 0};
  int matches = 0;
  int road_points = 0;
  int monoplotted_chains = 0;
  int long_sides = 0;
  StepTimings timings;
};

// The images a stereo pair's reconstruction works on, kept from one pair
// to the next by a worker (one per thread): the rectified images, their
// gradients and the detector's working images are then allocated once
// instead of being faulted in afresh (tens of megabytes) for every pair.
// Nothing in it carries over into a result.
struct PairWorkspace {
  cv::Mat rectified[2];
  EdgeMap edges[2];
  EdgeScratch edge_scratch;
};

// Everything the stages of one stereo pair need that does not change
// between exposures: the cameras, the rectification tables and the mask
// of usable gradients.
class StereoPairReconstructor {
 public:
  // `rectification_plane`: the road plane the rectified geometry is built
  // for. Check ok() before use.
  StereoPairReconstructor(const RigCamera& left, const RigCamera& right,
                          const RoadPlane& rectification_plane,
                          const ReconstructionOptions& options);
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const RoadRectification& rectification() const { return rectification_; }

  // Runs the pipeline on two original CV_32F images. `prior` is the
  // expected road plane (the slab's centre), `slab_half_thickness_m` and
  // `tolerance_angle_rad` the search volume. `stop_after_road_plane`: only
  // estimate the plane (initialisation). `debug_prefix`: when not empty,
  // debug images are written to debug_prefix + "_*.png".
  PairReconstruction Reconstruct(const cv::Mat& left_image,
                                 const cv::Mat& right_image,
                                 const RoadPlane& prior,
                                 double slab_half_thickness_m,
                                 double tolerance_angle_rad, uint64_t seed,
                                 bool stop_after_road_plane,
                                 const std::string& debug_prefix) const;
  // The same, working in `workspace` (one thread's; the result does not
  // depend on what it held before).
  PairReconstruction Reconstruct(
      const cv::Mat& left_image, const cv::Mat& right_image,
      const RoadPlane& prior, double slab_half_thickness_m,
      double tolerance_angle_rad, uint64_t seed, bool stop_after_road_plane,
      const std::string& debug_prefix, PairWorkspace* workspace) const;

  // Pixel of a body point in the original (distorted) image of `side`.
  bool ProjectToOriginal(int side, const Eigen::Vector3d& p_body,
                         Eigen::Vector2d* uv) const;

 private:
  RigCamera cameras_[2];
  ReconstructionOptions options_;
  RoadRectification rectification_;
  cv::Mat usable_;  // UsableMask of the rectification's valid mask
  std::string error_;
};

struct ReconstructionSummary {
  int exposures = 0;            // in the survey
  int exposures_processed = 0;  // all their pairs ran
  int exposures_skipped = 0;    // unreadable or missing images
  // Their ids and why, in time order (their warnings say the same).
  std::vector<std::pair<int64_t, std::string>> skipped_exposures;
  int pairs_processed = 0;
  int pairs_without_road = 0;  // no road plane found
  int bands = 0;
  int crossings = 0;             // distinct group_id
  RoadPlane initial_road_plane;  // body frame, from the initialisation
  RoadPlane final_road_plane;    // the running estimate at the end
  StepTimings timings;           // summed over pairs
  double wall_time_s = 0.0;
  std::vector<std::string> warnings;
  std::string message;  // why the result is unusable, or a one-line summary
  bool usable = false;

  bool IsUsable() const { return usable; }
  std::string BriefReport() const;
};

// Progress: (exposures done, exposures total).
using ProgressCallback = std::function<void(int, int)>;

// Reconstructs the bands of every stereo pair of every exposure. Vertices
// are appended to `vertices` in a deterministic order (exposures by time,
// pairs in rig order, bands in order), band_id and group_id numbered from 1.
ReconstructionSummary ReconstructSurvey(
    const Survey& survey, const ReconstructionOptions& options,
    std::vector<ReconstructedVertex>* vertices,
    const ProgressCallback& progress = nullptr,
    const CancellationToken& cancel = {});

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_RECONSTRUCTION_H_
