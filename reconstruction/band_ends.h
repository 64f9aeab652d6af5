// The transversal sides of a band being modelled (band_vertices.h), in one
// rectified image (Soheilian et al., section 5.1): Hough candidates in the
// search areas, the pair with the most opposite gradients (or the seen end
// of a band whose other end its crossing gives), and their sub-pixel
// refinement, along the crossing's direction of the ends when known.
//
// Frames: body (FRD) for 3D, metres; the plane frame of long_sides.h;
// rectified image pixels for 2D.
#ifndef ZEBRAGEO_RECONSTRUCTION_BAND_ENDS_H_
#define ZEBRAGEO_RECONSTRUCTION_BAND_ENDS_H_

#include <Eigen/Core>
#include <array>

#include "reconstruction/band_plane.h"
#include "reconstruction/band_vertices.h"
#include "reconstruction/transversal_sides.h"

namespace zebrageo {

// What a band's long sides give before its ends are searched.
struct BandSetup {
  LongSide lo, hi;  // along the band only
  Eigen::Vector2d along, across;
  BandPlaneFit plane_fit;
  // Search areas of the transversal sides (3D corners on the band plane),
  // begin then end.
  std::array<std::array<Eigen::Vector3d, 4>, 2> areas_3d;
  // The same widened by BandOptions::ladder_gap_reach_m beyond the long
  // sides: where a ladder bar's inner edge shows in the gaps (issue 52).
  std::array<std::array<Eigen::Vector3d, 4>, 2> ladder_areas_3d;
  Eigen::Vector3d band_centre;
};

// One rectified image's view of a band being modelled.
struct BandImage {
  int side = 0;                             // 0 left, 1 right
  std::array<Eigen::Vector2d, 4> areas[2];  // search areas, begin and end
  std::array<Eigen::Vector2d, 4> ladder_areas[2];  // widened (ladder ends)
  // The band direction, and the expected normal of its begin side (the
  // image brightens into the band along the band direction).
  Eigen::Vector2d band_direction, expected_normal;
};

// What the transversal line fits of both images give the band.
struct BandEndFits {
  double line_sigma_px[2][2] = {{0, 0}, {0, 0}};  // [image][end]
  // Signed angle of each image's own end (free fit) from the crossing's
  // direction of the ends, when it is known.
  double free_angle[2][2] = {{0, 0}, {0, 0}};
  double contrast = 0.0;  // summed over the ends' fits
};

// How a band fared in one image: kNoTransversal when a transversal side
// was not found there.
enum class ViewResult { kOk, kFailed, kNoTransversal };

// The band's two transversal lines in `image` (a known end's taken from its
// crossing, not searched), refined; `fits` gets the searched lines'
// standard deviations, angles and contrast.
ViewResult FindBandEnds(const BandContext& context, int i,
                        const KnownEnd known[2], const BandSetup& setup,
                        const BandImage& image, ImageLine lines[2],
                        BandEndFits* fits);

}  // namespace zebrageo

#endif  // ZEBRAGEO_RECONSTRUCTION_BAND_ENDS_H_
