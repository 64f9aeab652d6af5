// Diagnosis (pipeline/diagnosis.h) when no zebra band was reconstructed:
// are the two cameras of a stereo pair exchanged in exposures.csv (every
// row's left image taken by the right camera)? The pair is rectified over
// the nominal road plane (reconstruction/road_rectification.h), where a
// road point has the same pixel in both images: the two rectified images
// of the road agree (a high normalised cross-correlation) with the images
// as given, and disagree (shifted by twice the baseline) with them
// exchanged. Exchanged cameras show the opposite.
#ifndef ZEBRAGEO_PIPELINE_STEREO_ORDER_H_
#define ZEBRAGEO_PIPELINE_STEREO_ORDER_H_

#include <optional>
#include <string>

#include "pipeline/diagnosis.h"
#include "reconstruction/reconstruction.h"
#include "survey/survey.h"

namespace zebrageo {

struct StereoOrderOptions {
  // Exposures looked at, spread over the survey.
  int exposures = 6;
  // Exchanged if, in at least min_fraction of those read, the exchanged
  // images correlate better by min_gain and reach min_correlation.
  double min_gain = 0.15;
  double min_correlation = 0.3;
  double min_fraction = 0.67;

  std::string Check() const;
};

// The diagnosis naming the pair, the cameras and what to change, or
// nullopt (the order fits, or too little to tell).
std::optional<Diagnosis> DiagnoseStereoOrder(
    const Survey& survey, const ReconstructionOptions& reconstruction,
    const StereoOrderOptions& options);

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_STEREO_ORDER_H_
