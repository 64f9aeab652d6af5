#include "geodata/gcp_export.h"

#include <glog/logging.h>

#include <GeographicLib/UTMUPS.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tuple>

#include "survey/atomic_file.h"
#include "survey/crs.h"
#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/results_survey.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;

using VertexKey = std::tuple<int64_t, int64_t, int>;  // exposure, band, vertex
using GcpKey = std::tuple<std::string, int, int>;  // crossing, band, db_vertex

std::string NameOf(const GcpKey& key) {
  return std::get<0>(key) + "/" + std::to_string(std::get<1>(key)) + "/" +
         std::to_string(std::get<2>(key));
}

// Image names as the export writes them; two images of different folders
// with one base name would be one image to ODM: refused.
std::map<std::string, std::string> ExportedImageNames(
    const Survey& survey, const GcpExportOptions& options) {
  std::map<std::string, std::string> names;
  std::map<std::string, std::string> image_of_base_name;
  for (const ExposureImage& image : survey.exposures.images) {
    std::string name = image.image;
    if (options.image_names == GcpImageNames::kBaseName) {
      name = fs::path(image.image).filename().string();
      const auto [it, inserted] = image_of_base_name.emplace(name, image.image);
      if (!inserted && it->second != image.image) {
        throw InputError(survey.manifest.exposures, image.line,
                         "images '" + it->second + "' and '" + image.image +
                             "' share the name '" + name +
                             "': export with image paths (--image-paths)");
      }
    }
    names[image.image] = name;
  }
  return names;
}

// The image of `camera` at exposure `exposure_id`, or nullptr.
const ExposureImage* ImageOf(const Survey& survey, int64_t exposure_id,
                             int camera) {
  for (const Exposure& exposure : survey.exposures.exposures) {
    if (exposure.exposure_id != exposure_id) continue;
    const int index = exposure.image_of_camera[camera];
    return index < 0 ? nullptr : &survey.exposures.images[index];
  }
  return nullptr;
}

// Decimals for x, y of a CRS: degrees need 9 (0.1 mm), metres or feet 4.
int HorizontalDecimals(const Eigen::Vector3d& xyz) {
  return std::abs(xyz.x()) <= 360.0 && std::abs(xyz.y()) <= 90.0 ? 9 : 4;
}

}  // namespace

std::vector<GroundControlPoint> CollectGroundControlPoints(
    const Survey& survey, const std::string& results_folder,
    const GcpExportOptions& options) {
  const std::string matches_path =
      (fs::path(results_folder) / kMatchesFile).string();
  const std::string bands_path =
      (fs::path(results_folder) / kReconstructedBandsFile).string();
  const std::string residuals_path =
      (fs::path(results_folder) / kGcpResidualsFile).string();
  for (const std::string* path : {&matches_path, &bands_path}) {
    std::error_code error;
    if (!fs::is_regular_file(*path, error)) {
      throw InputError(*path, 0,
                       "not found: run `zebrageo run SURVEY -o " +
                           results_folder + "` first");
    }
  }
  const std::string identity = SurveyIdentity(survey.exposures);
  CheckStageFileSurvey(matches_path, identity);
  CheckStageFileSurvey(bands_path, identity);
  const std::vector<VertexMatch> matches =
      ReadMatches(matches_path, kMatchesFile);
  std::map<VertexKey, ReconstructedVertex> reconstructed;
  for (const ReconstructedVertex& v :
       ReadReconstructedBands(bands_path, kReconstructedBandsFile)) {
    reconstructed[{v.exposure_id, v.band_id, v.vertex}] = v;
  }
  std::map<GcpKey, GcpResidual> residuals;
  const bool has_residuals = fs::exists(residuals_path);
  if (has_residuals) {
    for (const GcpResidual& r :
         ReadGcpResiduals(residuals_path, kGcpResidualsFile)) {
      residuals[{r.crossing_id, r.band, r.vertex}] = r;
    }
  } else {
    LOG(WARNING) << residuals_path
                 << " is absent (adjust not run?): every point is written as "
                    "control, without residuals";
  }
  std::map<std::pair<std::string, int>, const RoadmarkBand*> database;
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    database[{band.crossing_id, band.band}] = &band;
  }
  const std::map<std::string, std::string> image_names =
      ExportedImageNames(survey, options);

  std::map<GcpKey, GroundControlPoint> points;
  std::set<std::pair<GcpKey, std::string>> observed;  // (point, image)
  for (const VertexMatch& match : matches) {
    std::ostringstream where;
    where << "match of exposure " << match.exposure_id << ", band_id "
          << match.band_id << ", vertex " << match.vertex << ": ";
    const auto vertex =
        reconstructed.find({match.exposure_id, match.band_id, match.vertex});
    if (vertex == reconstructed.end()) {
      throw InputError(
          kMatchesFile, 0,
          where.str() + "no such vertex in " + kReconstructedBandsFile);
    }
    const auto band = database.find({match.crossing_id, match.band});
    if (band == database.end() || match.db_vertex < 0 || match.db_vertex > 3) {
      throw InputError(
          kMatchesFile, 0,
          where.str() + "database vertex " +
              NameOf({match.crossing_id, match.band, match.db_vertex}) +
              " is not in " + survey.manifest.roadmarks);
    }
    const GcpKey key{match.crossing_id, match.band, match.db_vertex};
    const auto residual = residuals.find(key);
    if (has_residuals && residual == residuals.end()) continue;  // rejected
    GroundControlPoint& point = points[key];
    if (point.name.empty()) {
      point.name = NameOf(key);
      point.crossing_id = match.crossing_id;
      point.band = match.band;
      point.db_vertex = match.db_vertex;
      point.position = band->second->corners[match.db_vertex];
      point.sigma_xy_m = band->second->sigma_xy_m;
      point.sigma_z_m = band->second->sigma_z_m;
      if (has_residuals) {
        point.has_residual = true;
        point.role = residual->second.role;
        point.d_enu_m = residual->second.d_enu;
        point.rms_px = residual->second.rms_px;
      }
    }
    const ReconstructedVertex& v = vertex->second;
    if (v.pair < 0 ||
        v.pair >= static_cast<int>(survey.rig.stereo_pairs.size())) {
      throw InputError(kReconstructedBandsFile, 0,
                       where.str() + "stereo pair " + std::to_string(v.pair) +
                           " is not in the rig");
    }
    for (int side = 0; side < 2; ++side) {
      const int camera = survey.rig.stereo_pairs[v.pair][side];
      const ExposureImage* image = ImageOf(survey, v.exposure_id, camera);
      // A second band matched to the same vertex in the same image (two
      // observations of one point in one image) would be contradictory
      // control for the suites: the first is kept.
      if (image == nullptr || !observed.insert({key, image->image}).second) {
        continue;
      }
      GcpObservation observation;
      observation.exposure_id = v.exposure_id;
      observation.camera = survey.rig.cameras[camera].camera.name();
      observation.image = image->image;
      observation.image_name = image_names.at(image->image);
      observation.width = survey.rig.cameras[camera].camera.width();
      observation.height = survey.rig.cameras[camera].camera.height();
      observation.uv = side == 0 ? v.uv_left : v.uv_right;
      point.observations.push_back(observation);
    }
  }
  std::vector<GroundControlPoint> out;
  for (auto& [key, point] : points) {
    if (point.role == GcpRole::kCheck && !options.include_check_points) {
      continue;
    }
    out.push_back(std::move(point));
  }
  return out;
}

GcpCoordinateSystem Wgs84GcpCoordinates() {
  return {"EPSG:4326", [](const Geodetic& g) {
            return Eigen::Vector3d(g.lon_deg, g.lat_deg, g.h_m);
          }};
}

GcpCoordinates GcpCoordinatesFor(const std::string& definition,
                                 const Geodetic& near,
                                 const std::vector<std::string>& grid_dirs) {
  if (definition.empty() || definition == "WGS84" ||
      definition == "EPSG:4326" || definition == "EPSG:4979") {
    return {Wgs84GcpCoordinates(), "EPSG:4979"};
  }
  std::string crs_definition = definition;
  std::string header;
  if (definition == "utm") {
    // The zone is a rule of the UTM grid (GeographicLib); the projection
    // itself is PROJ's, as every CRS.
    const int zone =
        GeographicLib::UTMUPS::StandardZone(near.lat_deg, near.lon_deg);
    const bool north = near.lat_deg >= 0.0;
    if (zone == GeographicLib::UTMUPS::UPS) {
      throw CrsError("utm: the survey is in a polar UPS area; name a CRS");
    }
    crs_definition = "EPSG:" + std::to_string((north ? 32600 : 32700) + zone);
    header = "WGS84 UTM " + std::to_string(zone) + (north ? "N" : "S");
  }
  const Crs crs(crs_definition);
  if (header.empty()) {
    const std::string& id = crs.identifier();
    const bool single_code =
        id.rfind("EPSG:", 0) == 0 && id.find('+') == std::string::npos;
    if (single_code) {
      header = id;
    } else if (definition.find("+proj") != std::string::npos) {
      header = definition;
    }
  }
  CrsOptions options;
  options.grid_dirs = grid_dirs;
  auto transformer = std::make_shared<CrsTransformer>(crs, options);
  return {
      {header,
       [transformer](const Geodetic& g) { return transformer->FromWgs84(g); }},
      crs_definition};
}

Eigen::Vector2d OpenSfmNormalized(const Eigen::Vector2d& uv, int width,
                                  int height) {
  const double size = std::max(width, height);
  return Eigen::Vector2d((uv.x() + 0.5 - width / 2.0) / size,
                         (uv.y() + 0.5 - height / 2.0) / size);
}

// OpenDroneMap, "Ground Control Points" (docs.opendronemap.org/gcp/):
// "The first line should contain the name of the projection used for the
// geo coordinates ... WGS84 UTM <zone><hemisphere>, EPSG:<code>, <proj4>",
// then "geo_x geo_y geo_z im_x im_y image_name [gcp_name] [extra1]
// [extra2]", separated by tabs or spaces.
void WriteOdmGcpList(const std::vector<GroundControlPoint>& gcps,
                     const GcpCoordinateSystem& crs, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << crs.header << "\n";
    for (const GroundControlPoint& gcp : gcps) {
      const Eigen::Vector3d xyz = crs.from_wgs84(gcp.position);
      const int decimals = HorizontalDecimals(xyz);
      for (const GcpObservation& o : gcp.observations) {
        out << FormatFixed(xyz.x(), decimals) << "\t"
            << FormatFixed(xyz.y(), decimals) << "\t" << FormatFixed(xyz.z(), 4)
            << "\t" << FormatFixed(o.uv.x(), 3) << "\t"
            << FormatFixed(o.uv.y(), 3) << "\t" << o.image_name << "\t"
            << gcp.name << "\n";
      }
    }
  });
}

// OpenSfM, "Ground Control Points" (opensfm.org/docs/gcp.html): "points":
// [{"id", "position": {"latitude", "longitude", "altitude"}, "observations":
// [{"shot_id", "projection": [x, y]}]}], projections normalised.
void WriteOpenSfmGroundControlPoints(
    const std::vector<GroundControlPoint>& gcps, const std::string& path) {
  nlohmann::ordered_json points = nlohmann::ordered_json::array();
  for (const GroundControlPoint& gcp : gcps) {
    nlohmann::ordered_json point;
    point["id"] = gcp.name;
    point["role"] = gcp.role == GcpRole::kControl ? "control" : "check";
    point["position"] = {{"latitude", gcp.position.lat_deg},
                         {"longitude", gcp.position.lon_deg},
                         {"altitude", gcp.position.h_m}};
    nlohmann::ordered_json observations = nlohmann::ordered_json::array();
    for (const GcpObservation& o : gcp.observations) {
      const Eigen::Vector2d p = OpenSfmNormalized(o.uv, o.width, o.height);
      observations.push_back(
          {{"shot_id", o.image_name}, {"projection", {p.x(), p.y()}}});
    }
    point["observations"] = observations;
    points.push_back(point);
  }
  const nlohmann::ordered_json root = {{"points", points}};
  WriteFileAtomically(path,
                      [&](std::ostream& out) { out << root.dump(1) << "\n"; });
}

void WriteMetashapeMarkers(const std::vector<GroundControlPoint>& gcps,
                           const GcpCoordinateSystem& crs,
                           const std::string& path,
                           const std::string& projections_path) {
  // Metashape's Reference import reads delimited columns in an order chosen
  // in its dialog; the header comment names them for it. Both files are
  // written before either is renamed into place: a failure leaves neither.
  AtomicFile markers(path);
  std::ostream& out = markers.stream();
  out << "# zebrageo ground control; CRS " << crs.header << "\n";
  out << "# label,x,y,z,x_accuracy,y_accuracy,z_accuracy,enabled\n";
  for (const GroundControlPoint& gcp : gcps) {
    const Eigen::Vector3d xyz = crs.from_wgs84(gcp.position);
    const int decimals = HorizontalDecimals(xyz);
    out << gcp.name << "," << FormatFixed(xyz.x(), decimals) << ","
        << FormatFixed(xyz.y(), decimals) << "," << FormatFixed(xyz.z(), 4)
        << "," << FormatDouble(gcp.sigma_xy_m) << ","
        << FormatDouble(gcp.sigma_xy_m) << "," << FormatDouble(gcp.sigma_z_m)
        << "," << (gcp.role == GcpRole::kControl ? 1 : 0) << "\n";
  }
  AtomicFile projections(projections_path);
  std::ostream& projection_out = projections.stream();
  projection_out << "# marker,image,x,y (pixels, (0,0) the centre of the "
                    "top-left pixel)\n";
  for (const GroundControlPoint& gcp : gcps) {
    for (const GcpObservation& o : gcp.observations) {
      projection_out << gcp.name << "," << o.image_name << ","
                     << FormatFixed(o.uv.x(), 3) << ","
                     << FormatFixed(o.uv.y(), 3) << "\n";
    }
  }
  projections.Commit();
  try {
    markers.Commit();
  } catch (...) {
    std::remove(projections_path.c_str());
    throw;
  }
}

}  // namespace zebrageo
