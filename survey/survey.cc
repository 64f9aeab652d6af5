#include "survey/survey.h"

#include <glog/logging.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/math_util.h"
#include "survey/option_check.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr char kManifestFile[] = "survey.yaml";

}  // namespace

std::string SurveyLoadOptions::Check() const {
  OptionCheck check;
  OPTION_IN(check, max_missing_image_fraction, "[", 0.0, 1.0, "]");
  OPTION_NESTED(check, plausibility);
  return check.problem();
}

std::string Survey::PathOf(const std::string& relative) const {
  return (fs::path(folder) / relative).string();
}

CrsOptions SurveyCrsOptions(const std::string& survey_folder,
                            const SurveyManifest& manifest) {
  CrsOptions options;
  for (const std::string& folder_name : manifest.crs_grid_dirs) {
    options.grid_dirs.push_back(
        fs::absolute(fs::path(survey_folder) / folder_name).string());
  }
  return options;
}

CrsTransformer MakeSurveyCrsTransformer(const std::string& survey_folder,
                                        const SurveyManifest& manifest,
                                        const SurveyCrs& crs,
                                        const std::string& key) {
  try {
    return CrsTransformer(Crs(crs.definition),
                          SurveyCrsOptions(survey_folder, manifest));
  } catch (const CrsError& error) {
    throw InputError(kManifestFile, crs.line, key + ": " + error.what());
  }
}

std::vector<TrajectorySample> ReadSurveyTrajectory(
    const std::string& survey_folder, const SurveyManifest& manifest) {
  const std::string path =
      (fs::path(survey_folder) / manifest.trajectory).string();
  if (!manifest.trajectory_crs.is_set()) {
    return ReadTrajectorySamples(path, manifest.trajectory);
  }
  return ReadTrajectorySamplesInCrs(
      path, manifest.trajectory,
      MakeSurveyCrsTransformer(survey_folder, manifest, manifest.trajectory_crs,
                               "trajectory_crs"));
}

bool SurveyManifest::RoadmarksThroughGdal() const {
  std::string extension = fs::path(roadmarks).extension().string();
  for (char& c : extension) {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  const RoadmarkFields& f = roadmarks_fields;
  return roadmarks.rfind("PG:", 0) == 0 || roadmarks_crs.is_set() ||
         !roadmarks_layer.empty() || !f.crossing_id.empty() ||
         !f.band.empty() || !f.sigma_xy.empty() || !f.sigma_z.empty() ||
         !f.type.empty() || (extension != ".geojson" && extension != ".json");
}

namespace {

// The road's height below the trajectory, for 2D layers: the nearest
// sample's height less a nominal IMU height over the road. A guess: such
// bands get a sigma_z of metres, and the adjustment takes their heights
// from the reconstruction.
constexpr double kNominalImuHeightM = 1.5;

double RoadHeightBelow(const std::vector<TrajectorySample>& trajectory,
                       double lat_deg, double lon_deg) {
  double best = std::numeric_limits<double>::infinity();
  double height = 0.0;
  const double scale = std::cos(DegToRad(lat_deg));
  for (const TrajectorySample& s : trajectory) {
    const double dlat = s.position.lat_deg - lat_deg;
    const double dlon = (s.position.lon_deg - lon_deg) * scale;
    const double d2 = dlat * dlat + dlon * dlon;
    if (d2 < best) {
      best = d2;
      height = s.position.h_m - kNominalImuHeightM;
    }
  }
  return height;
}

}  // namespace

RoadmarkDatabase ReadSurveyRoadmarks(
    const std::string& survey_folder, const SurveyManifest& manifest,
    const std::vector<TrajectorySample>& trajectory) {
  if (!manifest.RoadmarksThroughGdal()) {
    return ReadRoadmarks(
        (fs::path(survey_folder) / manifest.roadmarks).string(),
        manifest.roadmarks);
  }
  RoadmarkLayerOptions options;
  const bool database = manifest.roadmarks.rfind("PG:", 0) == 0;
  options.source =
      database ? manifest.roadmarks
               : (fs::path(survey_folder) / manifest.roadmarks).string();
  options.layer = manifest.roadmarks_layer;
  options.crs = manifest.roadmarks_crs.definition;
  options.crs_options = SurveyCrsOptions(survey_folder, manifest);
  options.fields = manifest.roadmarks_fields;
  std::vector<Geodetic> positions;
  for (const TrajectorySample& s : trajectory) positions.push_back(s.position);
  if (!positions.empty()) {
    options.area = BoxAround(positions, manifest.roadmarks_margin_m);
  }
  options.height_guess = [&trajectory](double lat_deg, double lon_deg) {
    return RoadHeightBelow(trajectory, lat_deg, lon_deg);
  };
  return ReadRoadmarkLayer(options, manifest.roadmarks);
}

namespace {

// Poses are interpolated, never extrapolated: an INS drifts fastest
// exactly where it has no solution.
void CheckExposuresInsideTrajectory(const Survey& survey) {
  const SurveyManifest& manifest = survey.manifest;
  for (const ExposureImage& image : survey.exposures.images) {
    if (!survey.trajectory.Covers(image.time)) {
      throw InputError(manifest.exposures, image.line,
                       "exposure " + std::to_string(image.exposure_id) +
                           " at time " + FormatDouble(image.time) +
                           " is outside the trajectory's span [" +
                           FormatDouble(survey.trajectory.start_time()) + ", " +
                           FormatDouble(survey.trajectory.end_time()) +
                           "] of " + manifest.trajectory);
    }
  }
}

// Which images of the exposure table exist, each missing one warned about
// in *survey. Missing images: a few are warnings (the survey stays usable),
// many mean a wrong folder or a broken copy. A path out of the folder is
// refused outright, never read.
std::vector<bool> ImagesPresent(const std::string& folder,
                                const SurveyLoadOptions& options,
                                Survey* survey) {
  const SurveyManifest& manifest = survey->manifest;
  const std::vector<ExposureImage>& images = survey->exposures.images;
  const SurveyPaths paths(folder, options.paths);
  std::vector<bool> present(images.size(), true);
  int missing = 0;
  std::string first_missing;
  for (size_t i = 0; i < images.size(); ++i) {
    const ExposureImage& image = images[i];
    const SurveyFile file = paths.Resolve(image.image);
    if (file.escapes()) {
      throw InputError(manifest.exposures, image.line,
                       "image " + image.image + " " + file.Problem());
    }
    if (!file.ok()) {
      present[i] = false;
      ++missing;
      const std::string warning = manifest.exposures + ":" +
                                  std::to_string(image.line) + ": image " +
                                  image.image + " " + file.Problem();
      if (first_missing.empty()) first_missing = warning;
      LOG(WARNING) << warning;
      survey->warnings.push_back(warning);
    }
  }
  const int total = static_cast<int>(images.size());
  if (options.require_images &&
      missing > options.max_missing_image_fraction * total) {
    std::ostringstream message;
    message << missing << " of " << total
            << " images are missing (more than max_missing_image_fraction = "
            << options.max_missing_image_fraction
            << "); first: " << first_missing;
    throw InputError(manifest.exposures, 0, message.str());
  }
  return present;
}

// Every stereo pair needs one exposure with both its images present.
void CheckStereoPairsHaveImages(const Survey& survey,
                                const std::vector<bool>& present) {
  for (size_t p = 0; p < survey.rig.stereo_pairs.size(); ++p) {
    const std::array<int, 2>& pair = survey.rig.stereo_pairs[p];
    bool usable = false;
    for (const Exposure& exposure : survey.exposures.exposures) {
      const int left = exposure.image_of_camera[pair[0]];
      const int right = exposure.image_of_camera[pair[1]];
      if (left >= 0 && right >= 0 && present[left] && present[right]) {
        usable = true;
        break;
      }
    }
    if (!usable) {
      throw InputError(
          survey.manifest.exposures, 0,
          "stereo pair " + std::to_string(p) + " (" +
              survey.rig.cameras[pair[0]].camera.name() + ", " +
              survey.rig.cameras[pair[1]].camera.name() +
              "): no exposure has existing images of both cameras");
    }
  }
}

// "" or the warning for the bands of a 2D layer, whose heights are a guess.
std::string FlatBandsWarning(const Survey& survey) {
  const long flat = std::count_if(
      survey.roadmarks.bands.begin(), survey.roadmarks.bands.end(),
      [](const RoadmarkBand& band) { return !band.height_known; });
  if (flat == 0) return "";
  return survey.manifest.roadmarks + ": " + std::to_string(flat) +
         " bands without heights (a 2D layer): given the trajectory's "
         "height less 1.5 m with sigma_z " +
         FormatDouble(RoadmarkLayerOptions().sigma_z_without_height_m) +
         " m, so their heights come from the reconstruction and the "
         "database controls no height";
}

// What CheckPlausibility finds wrong with the loaded survey.
std::vector<std::string> PlausibilityWarnings(
    const Survey& survey, const SurveyLoadOptions& options) {
  const SurveyManifest& manifest = survey.manifest;
  PlausibilityInput plausibility;
  plausibility.trajectory = &survey.trajectory;
  plausibility.trajectory_file = manifest.trajectory;
  plausibility.exposures = &survey.exposures;
  plausibility.exposures_file = manifest.exposures;
  if (options.load_roadmarks) plausibility.roadmarks = &survey.roadmarks;
  plausibility.roadmarks_file = manifest.roadmarks;
  plausibility.origin = manifest.origin;
  plausibility.origin_line = manifest.origin_line;
  plausibility.manifest_file = kManifestFile;
  plausibility.frame = &survey.frame;
  return CheckPlausibility(plausibility, options.plausibility);
}

}  // namespace

Survey LoadSurvey(const std::string& folder, const SurveyLoadOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) {
    throw std::invalid_argument("SurveyLoadOptions: " + problem);
  }
  Survey survey;
  survey.folder = folder;
  survey.paths = options.paths;
  survey.manifest = ReadManifest(folder, options.paths);
  const SurveyManifest& manifest = survey.manifest;

  survey.rig = ReadRig(survey.PathOf(manifest.rig), manifest.rig);
  if (survey.rig.stereo_pairs.empty()) {
    throw InputError(manifest.rig, 0,
                     "no stereo_pairs: zebrageo needs at least one stereo "
                     "pair to reconstruct road marks");
  }
  // Every CRS is checked here, output_crs included: a missing grid stops
  // the survey before hours of processing, not at the last file written.
  for (const auto& [key, crs] :
       {std::pair{"roadmarks_crs", &manifest.roadmarks_crs},
        std::pair{"output_crs", &manifest.output_crs}}) {
    if (crs->is_set()) MakeSurveyCrsTransformer(folder, manifest, *crs, key);
  }
  std::vector<TrajectorySample> samples =
      ReadSurveyTrajectory(folder, manifest);
  const Geodetic origin = manifest.origin.value_or(samples.front().position);
  survey.frame = LocalFrame(origin);
  survey.trajectory = Trajectory(std::move(samples), survey.frame);

  survey.exposures = ReadExposures(survey.PathOf(manifest.exposures),
                                   manifest.exposures, survey.rig);
  CheckExposuresInsideTrajectory(survey);
  const std::vector<bool> present = ImagesPresent(folder, options, &survey);
  if (options.require_images) CheckStereoPairsHaveImages(survey, present);

  if (options.load_roadmarks) {
    survey.roadmarks =
        ReadSurveyRoadmarks(folder, manifest, survey.trajectory.samples());
    const std::string warning = FlatBandsWarning(survey);
    if (!warning.empty()) {
      LOG(WARNING) << warning;
      survey.warnings.push_back(warning);
    }
  }
  for (const std::string& warning : PlausibilityWarnings(survey, options)) {
    LOG(WARNING) << warning;
    survey.warnings.push_back(warning);
  }
  return survey;
}

}  // namespace zebrageo
