// Whether four corners make a usable zebra band: no repeated corners, no
// self-intersection, an area that is not about zero. Every reader of a
// road-mark database (survey/roadmarks.h, survey/roadmark_layer.h) checks
// each band with it.
#ifndef ZEBRAGEO_SURVEY_BAND_DEGENERACY_H_
#define ZEBRAGEO_SURVEY_BAND_DEGENERACY_H_

#include <array>
#include <string>

#include "survey/geodesy.h"

namespace zebrageo {

// "" or why four corners (degrees, in ring order) make no usable band:
// corners closer than 1 mm, a self-intersecting ring, or an area under
// 0.01 m^2.
std::string BandDegeneracy(const std::array<Geodetic, 4>& corners);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_BAND_DEGENERACY_H_
