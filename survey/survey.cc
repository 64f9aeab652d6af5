#include "survey/survey.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/yaml_document.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

constexpr char kManifestFile[] = "survey.yaml";

int LineOf(const YAML::Node& node) { return YamlLine(node); }

[[noreturn]] void Fail(const YAML::Node& node, const std::string& problem) {
  throw InputError(kManifestFile, LineOf(node), problem);
}

// A file key: required, a non-empty string naming a regular file inside
// the survey folder (unless outside paths are allowed).
std::string FileKey(const YAML::Node& root, const char* key,
                    const SurveyPaths& paths) {
  const YAML::Node node = root[key];
  if (!node || node.IsNull()) {
    Fail(root, std::string("missing key '") + key + "'");
  }
  if (!node.IsScalar() || node.Scalar().empty()) {
    Fail(node, std::string("'") + key + "' must be a file name");
  }
  const std::string name = node.Scalar();
  const SurveyFile file = paths.Resolve(name);
  if (!file.ok()) {
    Fail(node, std::string("'") + key + "' names " + name + ", which " +
                   file.Problem());
  }
  return name;
}

// An optional CRS key: PROJ must know it (the grids are checked when the
// survey is loaded, with the grid folders).
SurveyCrs CrsKey(const YAML::Node& root, const char* key) {
  SurveyCrs crs;
  const YAML::Node node = root[key];
  if (!node || node.IsNull()) return crs;
  if (!node.IsScalar() || node.Scalar().empty()) {
    Fail(node, std::string("'") + key +
                   "' must be a CRS: an EPSG code (\"EPSG:2154\", "
                   "\"EPSG:2154+5720\"), a PROJ string or WKT");
  }
  crs.definition = node.Scalar();
  crs.line = LineOf(node);
  try {
    Crs parsed(crs.definition);
  } catch (const CrsError& error) {
    Fail(node, std::string("'") + key + "': " + error.what());
  }
  return crs;
}

std::vector<std::string> GridDirsKey(const YAML::Node& root,
                                     const SurveyPaths& paths) {
  std::vector<std::string> folders;
  const YAML::Node node = root["crs_grid_dirs"];
  if (!node || node.IsNull()) return folders;
  if (!node.IsSequence()) {
    Fail(node, "'crs_grid_dirs' must be a list of folders");
  }
  for (const YAML::Node& item : node) {
    if (!item.IsScalar() || item.Scalar().empty()) {
      Fail(item, "'crs_grid_dirs' must be a list of folder names");
    }
    const SurveyFile folder = paths.Resolve(item.Scalar());
    if (folder.escapes()) {
      Fail(item, "'crs_grid_dirs' names " + item.Scalar() + ", which " +
                     folder.Problem());
    }
    if (!fs::is_directory(folder.path)) {
      Fail(item, "'crs_grid_dirs' names " + item.Scalar() +
                     ", which is not a folder");
    }
    folders.push_back(item.Scalar());
  }
  return folders;
}

// "PG:dbname=..." names a PostGIS database, not a file.
bool IsDatabaseConnection(const YAML::Node& node) {
  return node && node.IsScalar() && node.Scalar().rfind("PG:", 0) == 0;
}

std::string StringKey(const YAML::Node& node, const std::string& key) {
  if (!node || node.IsNull()) return "";
  if (!node.IsScalar() || node.Scalar().empty()) {
    Fail(node, "'" + key + "' must be a non-empty string");
  }
  return node.Scalar();
}

void ReadRoadmarkLayerKeys(const YAML::Node& root, SurveyManifest* manifest) {
  manifest->roadmarks_layer =
      StringKey(root["roadmarks_layer"], "roadmarks_layer");
  const YAML::Node fields = root["roadmarks_fields"];
  if (fields && !fields.IsNull()) {
    if (!fields.IsMap()) {
      Fail(fields,
           "'roadmarks_fields' must map crossing_id, band, sigma_xy, "
           "sigma_z, type to the layer's attribute names");
    }
    RoadmarkFields& f = manifest->roadmarks_fields;
    const std::pair<const char*, std::string*> known[] = {
        {"crossing_id", &f.crossing_id},
        {"band", &f.band},
        {"sigma_xy", &f.sigma_xy},
        {"sigma_z", &f.sigma_z},
        {"type", &f.type}};
    for (const auto& entry : fields) {
      const std::string key = entry.first.Scalar();
      bool found = false;
      for (const auto& [name, target] : known) {
        if (key != name) continue;
        *target = StringKey(entry.second, "roadmarks_fields." + key);
        found = true;
      }
      if (!found) {
        Fail(entry.first, "'roadmarks_fields' has no key '" + key +
                              "' (crossing_id, band, sigma_xy, sigma_z, "
                              "type)");
      }
    }
  }
  const YAML::Node margin = root["roadmarks_margin_m"];
  if (margin && !margin.IsNull()) {
    double value = 0.0;
    if (!margin.IsScalar() || !YAML::convert<double>::decode(margin, value) ||
        !std::isfinite(value) || value <= 0.0) {
      Fail(margin, "'roadmarks_margin_m' must be a number of metres > 0");
    }
    manifest->roadmarks_margin_m = value;
  }
}

Geodetic ParseOrigin(const YAML::Node& node) {
  if (!node.IsSequence() || node.size() != 3) {
    Fail(node, "'origin' must be [lat, lon, h] (degrees, degrees, metres)");
  }
  double values[3];
  for (int i = 0; i < 3; ++i) {
    if (!node[i].IsScalar() ||
        !YAML::convert<double>::decode(node[i], values[i]) ||
        !std::isfinite(values[i])) {
      Fail(node[i], "'origin' must be 3 finite numbers [lat, lon, h]");
    }
  }
  if (values[0] < -90.0 || values[0] > 90.0) {
    Fail(node, "'origin' latitude " + FormatDouble(values[0]) +
                   " is outside [-90, 90] (the order is [lat, lon, h])");
  }
  if (values[1] < -180.0 || values[1] > 180.0) {
    Fail(node, "'origin' longitude " + FormatDouble(values[1]) +
                   " is outside [-180, 180]");
  }
  return Geodetic{values[0], values[1], values[2]};
}

// A file name as a YAML scalar: plain when it can only be read as a string
// ("rig.yaml", "data/exposures.csv"), double-quoted otherwise.
std::string YamlString(const std::string& text) {
  bool plain =
      !text.empty() && std::isalpha(static_cast<unsigned char>(text.front()));
  for (char c : text) {
    plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                      c == '-' || c == '.' || c == '/');
  }
  std::string lower;
  for (char c : text) {
    lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  for (const char* keyword :
       {"y", "n", "yes", "no", "true", "false", "on", "off", "null"}) {
    plain = plain && lower != keyword;
  }
  if (plain) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

SurveyManifest ReadManifest(const std::string& survey_folder,
                            const SurveyPathOptions& path_options) {
  const SurveyPaths paths(survey_folder, path_options);
  const SurveyFile manifest_file = paths.Resolve(kManifestFile);
  if (!manifest_file.ok()) {
    throw InputError(kManifestFile, 0,
                     "cannot open " + manifest_file.path + ": it " +
                         manifest_file.Problem() + " (is " + survey_folder +
                         " a survey folder?)");
  }
  std::ifstream in(manifest_file.path, std::ios::binary);
  if (!in) {
    throw InputError(kManifestFile, 0,
                     "cannot open " + manifest_file.path + " (is " +
                         survey_folder + " a survey folder?)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  const YAML::Node root = ParseYamlDocument(text.str(), kManifestFile);
  if (!root.IsMap()) {
    Fail(root,
         "expected a mapping with keys name, rig, trajectory, "
         "exposures, roadmarks");
  }
  SurveyManifest manifest;
  const YAML::Node name = root["name"];
  if (name && name.IsScalar()) {
    manifest.name = name.Scalar();
  } else if (name && !name.IsNull()) {
    Fail(name, "'name' must be a string");
  } else {
    // The name only labels reports: the folder's name will do.
    manifest.name =
        fs::path(survey_folder).lexically_normal().filename().string();
    if (manifest.name.empty()) {
      manifest.name = fs::path(survey_folder)
                          .lexically_normal()
                          .parent_path()
                          .filename()
                          .string();
    }
  }
  manifest.rig = FileKey(root, "rig", paths);
  manifest.trajectory = FileKey(root, "trajectory", paths);
  manifest.exposures = FileKey(root, "exposures", paths);
  // A database is outside the survey folder: like a file there, only for
  // a trusted survey (a survey from someone else must not make zebrageo
  // connect to a server of its choosing).
  if (IsDatabaseConnection(root["roadmarks"]) &&
      !path_options.allow_outside_paths) {
    Fail(root["roadmarks"],
         "'roadmarks' names a PostGIS database, outside the survey folder: "
         "pass --allow-outside-paths for a survey you trust");
  }
  manifest.roadmarks = IsDatabaseConnection(root["roadmarks"])
                           ? root["roadmarks"].Scalar()
                           : FileKey(root, "roadmarks", paths);
  ReadRoadmarkLayerKeys(root, &manifest);
  const YAML::Node origin = root["origin"];
  if (origin && !origin.IsNull()) {
    manifest.origin = ParseOrigin(origin);
    manifest.origin_line = LineOf(origin);
  }
  manifest.roadmarks_crs = CrsKey(root, "roadmarks_crs");
  manifest.trajectory_crs = CrsKey(root, "trajectory_crs");
  manifest.output_crs = CrsKey(root, "output_crs");
  manifest.crs_grid_dirs = GridDirsKey(root, paths);
  return manifest;
}

void WriteManifest(const SurveyManifest& manifest, const std::string& path) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "name: " << YamlString(manifest.name) << "\n"
      << "rig: " << YamlString(manifest.rig) << "\n"
      << "trajectory: " << YamlString(manifest.trajectory) << "\n"
      << "exposures: " << YamlString(manifest.exposures) << "\n"
      << "roadmarks: " << YamlString(manifest.roadmarks) << "\n";
  if (manifest.origin.has_value()) {
    const Geodetic& o = *manifest.origin;
    if (!std::isfinite(o.lat_deg) || !std::isfinite(o.lon_deg) ||
        !std::isfinite(o.h_m)) {
      throw std::invalid_argument("WriteManifest: non-finite origin");
    }
    out << "origin: [" << FormatDouble(o.lat_deg) << ", "
        << FormatDouble(o.lon_deg) << ", " << FormatDouble(o.h_m)
        << "]  # lat, lon, h of the ENU origin\n";
  }
  const std::pair<const char*, const SurveyCrs*> crs_keys[] = {
      {"roadmarks_crs", &manifest.roadmarks_crs},
      {"trajectory_crs", &manifest.trajectory_crs},
      {"output_crs", &manifest.output_crs}};
  for (const auto& [key, crs] : crs_keys) {
    if (crs->is_set()) {
      out << key << ": " << YamlString(crs->definition) << "\n";
    }
  }
  if (!manifest.roadmarks_layer.empty()) {
    out << "roadmarks_layer: " << YamlString(manifest.roadmarks_layer) << "\n";
  }
  const RoadmarkFields& f = manifest.roadmarks_fields;
  const std::pair<const char*, const std::string*> fields[] = {
      {"crossing_id", &f.crossing_id},
      {"band", &f.band},
      {"sigma_xy", &f.sigma_xy},
      {"sigma_z", &f.sigma_z},
      {"type", &f.type}};
  bool fields_header = false;
  for (const auto& [key, name] : fields) {
    if (name->empty()) continue;
    if (!fields_header) out << "roadmarks_fields:\n";
    fields_header = true;
    out << "  " << key << ": " << YamlString(*name) << "\n";
  }
  if (manifest.roadmarks_margin_m != SurveyManifest().roadmarks_margin_m) {
    out << "roadmarks_margin_m: " << FormatDouble(manifest.roadmarks_margin_m)
        << "\n";
  }
  if (!manifest.crs_grid_dirs.empty()) {
    out << "crs_grid_dirs:\n";
    for (const std::string& folder : manifest.crs_grid_dirs) {
      out << "  - " << YamlString(folder) << "\n";
    }
  }
  file.Commit();
}

std::string SurveyLoadOptions::Check() const {
  if (!(max_missing_image_fraction >= 0.0 &&
        max_missing_image_fraction <= 1.0)) {
    std::ostringstream message;
    message << "max_missing_image_fraction = " << max_missing_image_fraction
            << ": must be in [0, 1]";
    return message.str();
  }
  const std::string problem = plausibility.Check();
  if (!problem.empty()) return "plausibility." + problem;
  return "";
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
  const double scale = std::cos(lat_deg * 3.14159265358979323846 / 180.0);
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
  // Poses are interpolated, never extrapolated: an INS drifts fastest
  // exactly where it has no solution.
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

  // Missing images: a few are warnings (the survey stays usable), many mean
  // a wrong folder or a broken copy.
  // A path out of the folder is refused outright, never read.
  const SurveyPaths paths(folder, options.paths);
  std::vector<bool> present(survey.exposures.images.size(), true);
  int missing = 0;
  std::string first_missing;
  for (size_t i = 0; i < survey.exposures.images.size(); ++i) {
    const ExposureImage& image = survey.exposures.images[i];
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
      survey.warnings.push_back(warning);
    }
  }
  const int total = static_cast<int>(survey.exposures.images.size());
  if (options.require_images &&
      missing > options.max_missing_image_fraction * total) {
    std::ostringstream message;
    message << missing << " of " << total
            << " images are missing (more than max_missing_image_fraction = "
            << options.max_missing_image_fraction
            << "); first: " << first_missing;
    throw InputError(manifest.exposures, 0, message.str());
  }

  for (size_t p = 0;
       options.require_images && p < survey.rig.stereo_pairs.size(); ++p) {
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
          manifest.exposures, 0,
          "stereo pair " + std::to_string(p) + " (" +
              survey.rig.cameras[pair[0]].camera.name() + ", " +
              survey.rig.cameras[pair[1]].camera.name() +
              "): no exposure has existing images of both cameras");
    }
  }

  if (options.load_roadmarks) {
    survey.roadmarks =
        ReadSurveyRoadmarks(folder, manifest, survey.trajectory.samples());
  }

  if (options.load_roadmarks) {
    const long flat = std::count_if(
        survey.roadmarks.bands.begin(), survey.roadmarks.bands.end(),
        [](const RoadmarkBand& band) { return !band.height_known; });
    if (flat > 0) {
      const std::string warning =
          manifest.roadmarks + ": " + std::to_string(flat) +
          " bands without heights (a 2D layer): given the trajectory's "
          "height less 1.5 m with sigma_z " +
          FormatDouble(RoadmarkLayerOptions().sigma_z_without_height_m) +
          " m, so their heights come from the reconstruction and the "
          "database controls no height";
      LOG(WARNING) << warning;
      survey.warnings.push_back(warning);
    }
  }

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
  for (const std::string& warning :
       CheckPlausibility(plausibility, options.plausibility)) {
    LOG(WARNING) << warning;
    survey.warnings.push_back(warning);
  }
  return survey;
}

}  // namespace zebrageo
