// survey.yaml, the survey's manifest (survey/survey.h): read with its keys
// checked (InputError naming the key's line), and written back.
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/survey.h"
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
  out << "name: " << YamlScalar(manifest.name, "/") << "\n"
      << "rig: " << YamlScalar(manifest.rig, "/") << "\n"
      << "trajectory: " << YamlScalar(manifest.trajectory, "/") << "\n"
      << "exposures: " << YamlScalar(manifest.exposures, "/") << "\n"
      << "roadmarks: " << YamlScalar(manifest.roadmarks, "/") << "\n";
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
      out << key << ": " << YamlScalar(crs->definition, "/") << "\n";
    }
  }
  if (!manifest.roadmarks_layer.empty()) {
    out << "roadmarks_layer: " << YamlScalar(manifest.roadmarks_layer, "/")
        << "\n";
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
    out << "  " << key << ": " << YamlScalar(*name, "/") << "\n";
  }
  if (manifest.roadmarks_margin_m != SurveyManifest().roadmarks_margin_m) {
    out << "roadmarks_margin_m: " << FormatDouble(manifest.roadmarks_margin_m)
        << "\n";
  }
  if (!manifest.crs_grid_dirs.empty()) {
    out << "crs_grid_dirs:\n";
    for (const std::string& folder : manifest.crs_grid_dirs) {
      out << "  - " << YamlScalar(folder, "/") << "\n";
    }
  }
  file.Commit();
}

}  // namespace zebrageo
