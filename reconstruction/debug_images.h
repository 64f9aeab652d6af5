// Debug images of band modelling, for a person to check a stereo pair:
// the rectified left image with edges, 3D points, long sides, band side
// pairs, transversal search areas, Hough candidates and final bands, and
// the original left image with the final bands.
#ifndef ZEBRAGEO_RECONSTRUCTION_DEBUG_IMAGES_H_
#define ZEBRAGEO_RECONSTRUCTION_DEBUG_IMAGES_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "reconstruction/band_modeling.h"
#include "reconstruction/long_sides.h"
#include "reconstruction/reconstruction.h"
#include "reconstruction/subpixel_edges.h"

namespace zebrageo {

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
                      const StereoPairReconstructor& pair);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_DEBUG_IMAGES_H_
