// The band matcher's input from a survey and its reconstruction: the
// reconstructed bands grouped into observations (one per exposure and
// group) with the measured pose at each exposure.
#ifndef ZEBRAGEO_REGISTRATION_OBSERVATIONS_H_
#define ZEBRAGEO_REGISTRATION_OBSERVATIONS_H_

#include <string>
#include <vector>

#include "registration/band_matcher.h"
#include "survey/results.h"
#include "survey/survey.h"

namespace zebrageo {

// Groups reconstructed vertices into observations (one per exposure and
// group), with the measured pose at each exposure. Bands with fewer than 4
// vertices cannot be matched vertex by vertex: they are left out and
// counted in `incomplete_bands` (may be null). Throws InputError naming
// `display_name` for an exposure_id the survey does not have or a pair index
// the rig does not have.
std::vector<CrossingObservation> BuildObservations(
    const Survey& survey, const std::vector<ReconstructedVertex>& vertices,
    const std::string& display_name, int* incomplete_bands);

// The measured pose of every exposure of the survey.
std::vector<ExposurePose> ExposurePoses(const Survey& survey);

}  // namespace zebrageo

#endif  // ZEBRAGEO_REGISTRATION_OBSERVATIONS_H_
