#include "pipeline/stereo_order.h"

#include <glog/logging.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "reconstruction/road_rectification.h"
#include "reconstruction/search_volume.h"
#include "survey/csv.h"
#include "survey/image_io.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

// Normalised cross-correlation of two images over `mask`; 0 when flat.
double Correlation(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Scalar mean_a, sd_a, mean_b, sd_b;
  cv::meanStdDev(a, mean_a, sd_a, mask);
  cv::meanStdDev(b, mean_b, sd_b, mask);
  if (sd_a[0] < 1e-6 || sd_b[0] < 1e-6) return 0.0;
  cv::Mat product;
  cv::multiply(a - mean_a[0], b - mean_b[0], product);
  return cv::mean(product, mask)[0] / (sd_a[0] * sd_b[0]);
}

// The correlation of the rectified road with the images as given and
// exchanged; false when an image cannot be read.
bool CorrelationsOf(const Survey& survey, const RoadRectification& pair,
                    const std::string& left_image,
                    const std::string& right_image, double* given,
                    double* exchanged) {
  cv::Mat left, right;
  try {
    left = ReadGrayImage(survey.PathOf(left_image), left_image);
    right = ReadGrayImage(survey.PathOf(right_image), right_image);
  } catch (const std::exception&) {
    return false;
  }
  if (left.size() != right.size()) return false;
  cv::Mat a, b;
  pair.Rectify(left, right, &a, &b);
  *given = Correlation(a, b, pair.valid_mask());
  pair.Rectify(right, left, &a, &b);
  *exchanged = Correlation(a, b, pair.valid_mask());
  return true;
}

}  // namespace

std::string StereoOrderOptions::Check() const {
  OptionCheck check;
  OPTION_GE(check, exposures, 1);
  OPTION_GT(check, min_gain, 0.0);
  OPTION_GT(check, min_correlation, 0.0);
  OPTION_GT(check, min_fraction, 0.0);
  return check.problem();
}

std::optional<Diagnosis> DiagnoseStereoOrder(
    const Survey& survey, const ReconstructionOptions& reconstruction,
    const StereoOrderOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("StereoOrderOptions: " + problem);
  }
  const Rig& rig = survey.rig;
  const RoadPlane plane = NominalRoadPlane(rig, reconstruction.search);
  const std::vector<Exposure>& exposures = survey.exposures.exposures;
  for (size_t p = 0; p < rig.stereo_pairs.size(); ++p) {
    const int l = rig.stereo_pairs[p][0], r = rig.stereo_pairs[p][1];
    RoadRectification pair;
    std::string error;
    if (!pair.Build(rig.cameras[l], rig.cameras[r], plane,
                    reconstruction.rectification, &error)) {
      continue;
    }
    int read = 0, exchanged_better = 0;
    std::vector<double> given_all, exchanged_all;
    const int n = static_cast<int>(exposures.size());
    const int step = std::max(1, n / options.exposures);
    for (int e = 0; e < n && read < options.exposures; e += step) {
      const int li = exposures[e].image_of_camera[l];
      const int ri = exposures[e].image_of_camera[r];
      if (li < 0 || ri < 0) continue;
      double given = 0.0, exchanged = 0.0;
      if (!CorrelationsOf(survey, pair, survey.exposures.images[li].image,
                          survey.exposures.images[ri].image, &given,
                          &exchanged)) {
        continue;
      }
      ++read;
      given_all.push_back(given);
      exchanged_all.push_back(exchanged);
      if (exchanged > given + options.min_gain &&
          exchanged > options.min_correlation) {
        ++exchanged_better;
      }
    }
    VLOG(1) << "stereo order of pair " << p << ": " << exchanged_better
            << " of " << read << " exposures fit exchanged";
    if (read < 2 || exchanged_better < options.min_fraction * read) continue;
    std::sort(given_all.begin(), given_all.end());
    std::sort(exchanged_all.begin(), exchanged_all.end());
    const std::string left = rig.cameras[l].camera.name();
    const std::string right = rig.cameras[r].camera.name();
    Diagnosis diagnosis;
    diagnosis.cause = "stereo_pair_exchanged";
    diagnosis.message =
        "diagnosis: " + survey.manifest.exposures +
        ": the images of cameras '" + left + "' and '" + right +
        "' look exchanged: rectified over the " + "road, " +
        std::to_string(exchanged_better) + " of " + std::to_string(read) +
        " exposures' images match as a stereo pair only with left and right "
        "exchanged (median correlation " +
        FormatFixed(exchanged_all[exchanged_all.size() / 2], 2) +
        " exchanged, " + FormatFixed(given_all[given_all.size() / 2], 2) +
        " as given), so no band could be reconstructed: exchange '" + left +
        "' and '" + right + "' in the camera column of " +
        survey.manifest.exposures + " (or the cameras of " +
        survey.manifest.rig + ")";
    return diagnosis;
  }
  return std::nullopt;
}

}  // namespace zebrageo
