// Image evidence for the 1 m periodicity of zebra bands (issue 6).
//
// A database band predicted in view but not reconstructed is evidence
// against the hypothesis that predicts it only if the street there is bare
// road: a band the reconstruction missed (worn paint, a vehicle hiding it,
// an edge lost at range) says nothing. Without this, an end band hidden in
// every view looks exactly like a one-band shift of the whole crossing, and
// the hypothesis whose extra band falls outside the images wins.
//
// The probe looks at the left image of the stereo pair where the band would
// be, projected with the hypothesis' corrected pose, and compares it with
// the paint of the bands matched in the same image and the asphalt between
// them: paint-bright is kPaint, asphalt-dark and as even as the asphalt is
// kBareRoad, anything else (a vehicle, a shadow edge, too little contrast,
// out of the image) is kUnknown.
//
// Known limit: an even, dark occluder (the plain side of a dark vehicle)
// looks like bare road; the continuity check between crossings and the
// adjustment's blunder test remain behind it.
#ifndef ZEBRAGEO_REGISTRATION_PAINT_PROBE_H_
#define ZEBRAGEO_REGISTRATION_PAINT_PROBE_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <list>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "survey/survey.h"
#include "survey/trajectory.h"

namespace zebrageo {

// kOccluded: something stands above the road at the place (issue 52): the
// stereo pair's right image matches the left one there in front of the
// road surface, not on it.
enum class PaintEvidence { kUnknown, kPaint, kBareRoad, kOccluded };

const char* PaintEvidenceName(PaintEvidence evidence);

using BandCornersEnu = std::array<Eigen::Vector3d, 4>;

struct PaintProbeOptions {
  // Samples are taken in the middle part of the band (this share of its
  // length and width): the database is 5-15 cm off.
  double sample_share = 0.5;
  // Paint minus asphalt (grey levels) below this: cannot tell.
  double min_contrast = 15.0;
  // The band's median against the surface right beside it (the gaps half a
  // period either way), as a share of the paint/asphalt ratio of the seen
  // bands (ratios: a cast shadow darkens paint and asphalt alike): above
  // paint_level it is paint; within +-bare_level of the surface beside it,
  // and as even, it is bare (asphalt, or the sidewalk beyond the crossing).
  double paint_level = 0.6;
  double bare_level = 0.3;
  // Evenness: the spread (interquartile range) of the band's samples at
  // most the spread beside it plus this share of the paint contrast.
  double max_bare_spread = 0.35;
  // Share of the samples that must fall inside the image.
  double min_inside_share = 0.8;
  // Without seen bands (a database crossing nothing was matched to: is it
  // gone from the street?) the paint contrast is not measured but assumed
  // at least this (paint / asphalt - 1; road paint is 2-4 times as bright
  // as asphalt), and the surface beside the band must look like the road
  // right ahead of the vehicle (level within this share of it): a vehicle
  // or a shadow over the crossing is not bare road.
  double assumed_paint_contrast = 0.5;
  double max_road_level_change = 0.25;
  // Occlusion by stereo (issue 52): at grid points of the place seen in
  // the left image, windows of occlusion_window_px (odd) are compared with
  // the right image's where the road surface puts them and where a surface
  // at least occlusion_min_height_m above it would (swept along the left
  // ray, one pixel of disparity a step). A point with texture (window sd
  // at least occlusion_min_texture grey levels) stands above the road when
  // its best match above beats the road's by occlusion_ncc_margin at
  // correlation occlusion_min_ncc, on the road when the road's match
  // reaches occlusion_min_ncc (else it does not vote); the place is
  // occluded when at least occlusion_min_points and occlusion_min_share of
  // the votes are above the road (docs/results.md, issue 52).
  int occlusion_window_px = 5;
  double occlusion_min_height_m = 0.5;
  double occlusion_min_texture = 4.0;
  double occlusion_min_ncc = 0.7;
  double occlusion_ncc_margin = 0.25;
  int occlusion_min_points = 6;
  double occlusion_min_share = 0.4;
  // Decoded images kept in memory.
  int cached_images = 16;

  std::string Check() const;
  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("sample_share", sample_share);
    v("min_contrast", min_contrast);
    v("paint_level", paint_level);
    v("bare_level", bare_level);
    v("max_bare_spread", max_bare_spread);
    v("min_inside_share", min_inside_share);
    v("assumed_paint_contrast", assumed_paint_contrast);
    v("max_road_level_change", max_road_level_change);
    v("occlusion_window_px", occlusion_window_px);
    v("occlusion_min_height_m", occlusion_min_height_m);
    v("occlusion_min_texture", occlusion_min_texture);
    v("occlusion_min_ncc", occlusion_min_ncc);
    v("occlusion_ncc_margin", occlusion_ncc_margin);
    v("occlusion_min_points", occlusion_min_points);
    v("occlusion_min_share", occlusion_min_share);
    v("cached_images", cached_images);
  }
};

class ImagePaintProbe {
 public:
  // `survey` must outlive the probe.
  explicit ImagePaintProbe(const Survey& survey,
                           PaintProbeOptions options = PaintProbeOptions());

  // What the left image of the first stereo pair of `exposure_id` shows
  // inside `band`, seen from the body pose `pose`, given `seen` (database
  // bands matched in that image: their paint, and the asphalt between
  // neighbours). Never throws: an unreadable image is kUnknown. With no
  // `seen` band the paint contrast is assumed (assumed_paint_contrast) and
  // kBareRoad needs the surface beside the band to look like the road
  // ahead of the vehicle (max_road_level_change).
  PaintEvidence Classify(int64_t exposure_id, const Pose& pose,
                         const BandCornersEnu& band,
                         const std::vector<BandCornersEnu>& seen);

  // Images decoded so far (for the bench).
  int images_read() const { return images_read_; }

 private:
  // Grey values at a grid over the middle of `quad` (ENU), those inside the
  // image; false when too few are.
  bool Sample(const cv::Mat& image, const Eigen::Isometry3d& T_cam_enu,
              const BandCornersEnu& quad, std::vector<float>* values) const;
  const cv::Mat* LeftImage(int64_t exposure_id);
  // The image of `camera` of the exposure (cached), or null.
  const cv::Mat* CameraImage(int64_t exposure_id, int camera);
  // True when the stereo pair shows something standing above the road at
  // `band`'s place (see the occlusion options).
  bool StandsAboveRoad(int64_t exposure_id, const Pose& pose,
                       const BandCornersEnu& band);
  bool MeasureStandsAboveRoad(int64_t exposure_id, const Pose& pose,
                              const BandCornersEnu& band);
  // The verdict on `band` given the paint contrast (paint / asphalt - 1)
  // and, when positive, the road's level ahead of the vehicle.
  PaintEvidence Verdict(const cv::Mat& image,
                        const Eigen::Isometry3d& T_cam_enu,
                        const BandCornersEnu& band, double contrast,
                        double road_ahead_level, int64_t exposure_id) const;
  // The median grey level of the road 5-8 m ahead of the camera at the
  // height of `band`, or 0 when not in view.
  double RoadAheadLevel(const cv::Mat& image,
                        const Eigen::Isometry3d& T_cam_enu,
                        const BandCornersEnu& band) const;

  const Survey& survey_;
  // False when a band of the database has no height (a 2D layer).
  bool heights_known_ = true;
  PaintProbeOptions options_;
  int camera_ = -1;  // the left camera of the first stereo pair
  int right_camera_ = -1;
  std::unordered_map<int64_t, std::string> image_of_exposure_;
  std::unordered_map<int64_t, std::string> right_image_of_exposure_;
  // Keyed by exposure * 2 + (0 left, 1 right), most recent first.
  std::list<std::pair<int64_t, cv::Mat>> cache_;
  int images_read_ = 0;
  // StandsAboveRoad's answers by exposure and quarter-metre cell.
  std::unordered_map<uint64_t, bool> occlusion_cache_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_PAINT_PROBE_H_
