// The GeoPackage export of ground control points, through GDAL/OGR's C API
// (geodata/gcp_export.h).
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "geodata/gcp_export.h"

namespace zebrageo {
namespace {

constexpr char kLayerName[] = "ground_control_points";

[[noreturn]] void FailGdal(const std::string& what) {
  throw std::runtime_error(what + ": " + CPLGetLastErrorMsg());
}

struct DatasetCloser {
  void operator()(void* dataset) const { GDALClose(dataset); }
};
struct SrsReleaser {
  void operator()(void* srs) const { OSRRelease(srs); }
};
struct FeatureDestroyer {
  void operator()(void* feature) const { OGR_F_Destroy(feature); }
};

void AddField(OGRLayerH layer, const char* name, OGRFieldType type) {
  OGRFieldDefnH field = OGR_Fld_Create(name, type);
  const OGRErr error = OGR_L_CreateField(layer, field, TRUE);
  OGR_Fld_Destroy(field);
  if (error != OGRERR_NONE) FailGdal(std::string("field ") + name);
}

void WriteFeatures(OGRLayerH layer, const std::vector<GroundControlPoint>& gcps,
                   const GcpCoordinateSystem& crs) {
  for (const GroundControlPoint& gcp : gcps) {
    std::unique_ptr<void, FeatureDestroyer> feature(
        OGR_F_Create(OGR_L_GetLayerDefn(layer)));
    OGRFeatureH f = feature.get();
    OGR_F_SetFieldString(f, OGR_F_GetFieldIndex(f, "name"), gcp.name.c_str());
    OGR_F_SetFieldString(f, OGR_F_GetFieldIndex(f, "crossing_id"),
                         gcp.crossing_id.c_str());
    OGR_F_SetFieldInteger(f, OGR_F_GetFieldIndex(f, "band"), gcp.band);
    OGR_F_SetFieldInteger(f, OGR_F_GetFieldIndex(f, "db_vertex"),
                          gcp.db_vertex);
    OGR_F_SetFieldString(f, OGR_F_GetFieldIndex(f, "role"),
                         gcp.role == GcpRole::kControl ? "control" : "check");
    OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "sigma_xy_m"),
                         gcp.sigma_xy_m);
    OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "sigma_z_m"), gcp.sigma_z_m);
    OGR_F_SetFieldInteger(f, OGR_F_GetFieldIndex(f, "n_images"),
                          static_cast<int>(gcp.observations.size()));
    // Residuals stay NULL (not 0) when the folder has none.
    if (gcp.has_residual) {
      OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "de_m"), gcp.d_enu_m.x());
      OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "dn_m"), gcp.d_enu_m.y());
      OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "du_m"), gcp.d_enu_m.z());
      OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "d3d_m"),
                           gcp.d_enu_m.norm());
      OGR_F_SetFieldDouble(f, OGR_F_GetFieldIndex(f, "rms_px"), gcp.rms_px);
    }
    const Eigen::Vector3d xyz = crs.from_wgs84(gcp.position);
    OGRGeometryH point = OGR_G_CreateGeometry(wkbPoint25D);
    OGR_G_SetPoint(point, 0, xyz.x(), xyz.y(), xyz.z());
    OGR_F_SetGeometryDirectly(f, point);
    if (OGR_L_CreateFeature(layer, f) != OGRERR_NONE) {
      FailGdal("point " + gcp.name);
    }
  }
}

}  // namespace

void WriteGcpGeoPackage(const std::vector<GroundControlPoint>& gcps,
                        const GcpCoordinateSystem& crs,
                        const std::string& srs_definition,
                        const std::string& path) {
  GDALAllRegister();
  GDALDriverH driver = GDALGetDriverByName("GPKG");
  if (driver == nullptr) FailGdal("GDAL has no GPKG driver");
  // Written under a temporary name in the same folder, renamed when
  // complete: a GeoPackage is an SQLite file, never seen half-written.
  const std::string temporary =
      path + ".tmp-" + std::to_string(::getpid()) + ".gpkg";
  std::error_code ignored;
  std::filesystem::remove(temporary, ignored);
  try {
    std::unique_ptr<void, SrsReleaser> srs(OSRNewSpatialReference(nullptr));
    if (OSRSetFromUserInput(srs.get(), srs_definition.c_str()) != OGRERR_NONE) {
      FailGdal("spatial reference '" + srs_definition + "'");
    }
    // x = longitude / easting, whatever the authority's axis order.
    OSRSetAxisMappingStrategy(srs.get(), OAMS_TRADITIONAL_GIS_ORDER);
    {
      std::unique_ptr<void, DatasetCloser> dataset(
          GDALCreate(driver, temporary.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
      if (!dataset) FailGdal("cannot create " + temporary);
      OGRLayerH layer = GDALDatasetCreateLayer(dataset.get(), kLayerName,
                                               srs.get(), wkbPoint25D, nullptr);
      if (layer == nullptr) FailGdal("layer");
      AddField(layer, "name", OFTString);
      AddField(layer, "crossing_id", OFTString);
      AddField(layer, "band", OFTInteger);
      AddField(layer, "db_vertex", OFTInteger);
      AddField(layer, "role", OFTString);
      AddField(layer, "sigma_xy_m", OFTReal);
      AddField(layer, "sigma_z_m", OFTReal);
      AddField(layer, "n_images", OFTInteger);
      AddField(layer, "de_m", OFTReal);
      AddField(layer, "dn_m", OFTReal);
      AddField(layer, "du_m", OFTReal);
      AddField(layer, "d3d_m", OFTReal);
      AddField(layer, "rms_px", OFTReal);
      if (GDALDatasetStartTransaction(dataset.get(), FALSE) != OGRERR_NONE) {
        FailGdal("transaction");
      }
      WriteFeatures(layer, gcps, crs);
      if (GDALDatasetCommitTransaction(dataset.get()) != OGRERR_NONE) {
        FailGdal("commit");
      }
    }  // closed: everything is on disk
    std::filesystem::rename(temporary, path);
  } catch (...) {
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

}  // namespace zebrageo
