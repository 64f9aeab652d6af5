// A camera's distortion checked against its own image (issue 48): a
// coefficient in the wrong unit or place (k1 = 1e6) passes every reader
// and leaves the reconstruction with nothing, "no zebra band".
#ifndef ZEBRAGEO_SURVEY_DISTORTION_CHECK_H_
#define ZEBRAGEO_SURVEY_DISTORTION_CHECK_H_

#include <string>

#include "survey/camera.h"

namespace zebrageo {

// What is wrong with the camera's radial distortion inside its image, ""
// when nothing: the distorted radius must grow with the undistorted one
// until it reaches the image's farthest corner (else the map folds: two
// rays on one pixel), and there scale it by 1/4 to 4 (a lens's barrel or
// pincushion stays far inside; k1 = 1e6 would squeeze 60 degrees of view
// into one). Names the coefficients and the corner's radius.
std::string RadialDistortionProblem(const Camera& camera);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_DISTORTION_CHECK_H_
