#include "survey/output_crs.h"

#include <utility>

#include "survey/csv.h"
#include "survey/input_error.h"
#include "survey/survey.h"

namespace zebrageo {

std::unique_ptr<OutputCrs> OutputCrs::Of(const Survey& survey) {
  if (!survey.manifest.output_crs.is_set()) return nullptr;
  std::unique_ptr<OutputCrs> crs(new OutputCrs(
      MakeSurveyCrsTransformer(survey.folder, survey.manifest,
                               survey.manifest.output_crs, "output_crs"),
      survey.manifest.output_crs.line, survey.frame));
  for (const RoadmarkBand& band : survey.roadmarks.bands) {
    for (int k = 0; k < 4; ++k) {
      crs->vertices_[{band.crossing_id, band.band, k}] = band.corners[k];
    }
  }
  return crs;
}

OutputCrs::OutputCrs(CrsTransformer transformer, int line, LocalFrame frame)
    : transformer_(std::move(transformer)), line_(line), frame_(frame) {}

void OutputCrs::AddHeader(CsvWriter* csv,
                          std::vector<std::string>* columns) const {
  const Crs& crs = transformer_.crs();
  csv->Comment("output_crs: " + (crs.identifier().empty() ? crs.definition()
                                                          : crs.identifier()));
  csv->Comment("crs_x,crs_y,crs_z: " + crs.Description());
  csv->Comment("output_crs_wkt: " + crs.wkt());
  columns->insert(columns->end(), {"crs_x", "crs_y", "crs_z"});
}

Eigen::Vector3d OutputCrs::FromWgs84(const Geodetic& wgs84) const {
  try {
    return transformer_.FromWgs84(wgs84);
  } catch (const CrsError& error) {
    throw InputError("survey.yaml", line_,
                     std::string("output_crs: ") + error.what());
  }
}

void OutputCrs::AddColumns(const Geodetic& wgs84, CsvWriter* csv) const {
  const Eigen::Vector3d xyz = FromWgs84(wgs84);
  csv->Add(xyz.x()).Add(xyz.y()).Add(xyz.z());
}

Geodetic OutputCrs::DatabaseVertex(const std::string& crossing_id, int band,
                                   int vertex, const std::string& file) const {
  const auto it = vertices_.find({crossing_id, band, vertex});
  if (it == vertices_.end()) {
    throw InputError(file, 0,
                     "crossing " + crossing_id + " band " +
                         std::to_string(band) +
                         " is not in the road-mark database");
  }
  return it->second;
}

// GeoJSON 2008's named CRS: an OGC URN GDAL and PROJ read, compound CRSs
// included; WKT for a CRS without a code.
nlohmann::json OutputCrs::GeoJsonMember() const {
  const Crs& crs = transformer_.crs();
  std::string name = crs.wkt();
  const std::string& id = crs.identifier();
  const std::size_t colon = id.find(':');
  if (colon != std::string::npos) {
    const std::string authority = id.substr(0, colon);
    const std::string codes = id.substr(colon + 1);
    const std::size_t plus = codes.find('+');
    name = plus == std::string::npos
               ? "urn:ogc:def:crs:" + authority + "::" + codes
               : "urn:ogc:def:crs,crs:" + authority +
                     "::" + codes.substr(0, plus) + ",crs:" + authority +
                     "::" + codes.substr(plus + 1);
  }
  return {{"type", "name"}, {"properties", {{"name", name}}}};
}

std::string OutputCrs::Description() const {
  return transformer_.crs().Description() + " (" +
         transformer_.LastOperationName() + ")";
}

}  // namespace zebrageo
