#include "survey/crs.h"

#include <proj.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "survey/option_check.h"

namespace zebrageo {
namespace {

constexpr char kWgs84Definition[] = "EPSG:4979";

// A PROJ context of our own: no network (a grid is installed or it is an
// error, never a download in the middle of a run), no log on stderr (errors
// reach the user through CrsError).
struct ContextDeleter {
  void operator()(PJ_CONTEXT* context) const { proj_context_destroy(context); }
};
struct PjDeleter {
  void operator()(PJ* pj) const { proj_destroy(pj); }
};
using ContextPtr = std::unique_ptr<PJ_CONTEXT, ContextDeleter>;
using PjPtr = std::unique_ptr<PJ, PjDeleter>;

std::vector<std::string> SplitSearchPath(const std::string& path) {
  std::vector<std::string> folders;
  std::stringstream stream(path);
  std::string folder;
  while (std::getline(stream, folder, ':')) {
    if (!folder.empty()) folders.push_back(folder);
  }
  return folders;
}

std::string DefaultSearchPath() {
  const char* path = proj_info().searchpath;
  return path == nullptr ? std::string() : std::string(path);
}

ContextPtr MakeContext(const CrsOptions& options) {
  ContextPtr context(proj_context_create());
  if (!context) throw CrsError("PROJ: cannot create a context");
  proj_log_level(context.get(), PJ_LOG_NONE);
  proj_context_set_enable_network(context.get(), 0);
  if (!options.grid_dirs.empty()) {
    std::vector<std::string> folders = options.grid_dirs;
    for (const std::string& folder : SplitSearchPath(DefaultSearchPath())) {
      folders.push_back(folder);
    }
    std::vector<const char*> c_folders;
    for (const std::string& folder : folders)
      c_folders.push_back(folder.c_str());
    proj_context_set_search_paths(
        context.get(), static_cast<int>(c_folders.size()), c_folders.data());
  }
  return context;
}

std::string LastError(PJ_CONTEXT* context) {
  const int code = proj_context_errno(context);
  const char* text =
      code == 0 ? nullptr : proj_context_errno_string(context, code);
  return text == nullptr ? std::string("unknown PROJ error") : text;
}

// A PROJ string names a CRS only with +type=crs; users leave it out.
std::string ProjInput(const std::string& definition) {
  const bool is_proj_string =
      !definition.empty() && definition.find("+proj=") != std::string::npos &&
      definition.find_first_not_of(" \t") == definition.find('+');
  if (is_proj_string && definition.find("type=crs") == std::string::npos) {
    return definition + " +type=crs";
  }
  return definition;
}

PjPtr CreateCrs(PJ_CONTEXT* context, const std::string& definition) {
  if (definition.find_first_not_of(" \t\r\n") == std::string::npos) {
    throw CrsError("empty CRS definition");
  }
  PjPtr crs(proj_create(context, ProjInput(definition).c_str()));
  if (!crs) {
    throw CrsError("PROJ does not know the CRS \"" + definition +
                   "\": " + LastError(context));
  }
  if (!proj_is_crs(crs.get())) {
    throw CrsError("\"" + definition + "\" is not a CRS for PROJ (a " +
                   "coordinate operation or a datum?)");
  }
  return crs;
}

// The CRS without its bound transformation (a PROJ string with +towgs84 or
// +geoidgrids is a BoundCRS around the CRS proper).
PjPtr UnboundCrs(PJ_CONTEXT* context, const PJ* crs) {
  if (crs == nullptr) return nullptr;
  if (proj_get_type(crs) == PJ_TYPE_BOUND_CRS) {
    return PjPtr(proj_get_source_crs(context, crs));
  }
  return PjPtr(proj_clone(context, crs));
}

// Horizontal and vertical parts: a compound CRS's first and second; any
// other CRS is its own horizontal part and has no vertical part.
std::pair<PjPtr, PjPtr> SplitCrs(PJ_CONTEXT* context, const PJ* crs) {
  PjPtr unbound = UnboundCrs(context, crs);
  if (unbound && proj_get_type(unbound.get()) == PJ_TYPE_COMPOUND_CRS) {
    PjPtr horizontal = UnboundCrs(
        context, PjPtr(proj_crs_get_sub_crs(context, unbound.get(), 0)).get());
    PjPtr vertical = UnboundCrs(
        context, PjPtr(proj_crs_get_sub_crs(context, unbound.get(), 1)).get());
    return {std::move(horizontal), std::move(vertical)};
  }
  return {std::move(unbound), nullptr};
}

std::string FirstAxisUnit(PJ_CONTEXT* context, const PJ* crs) {
  PjPtr cs(proj_crs_get_coordinate_system(context, crs));
  const char* unit = nullptr;
  if (!cs ||
      !proj_cs_get_axis_info(context, cs.get(), 0, nullptr, nullptr, nullptr,
                             nullptr, &unit, nullptr, nullptr) ||
      unit == nullptr) {
    return "unknown";
  }
  return unit;
}

std::string Identifier(const PJ* crs) {
  const char* authority = proj_get_id_auth_name(crs, 0);
  const char* code = proj_get_id_code(crs, 0);
  if (authority == nullptr || code == nullptr) return "";
  return std::string(authority) + ":" + code;
}

// "EPSG:2154+5720" for a compound CRS of two coded parts.
std::string CompoundIdentifier(const PJ* horizontal, const PJ* vertical) {
  const std::string h = Identifier(horizontal);
  const std::string v = Identifier(vertical);
  const std::size_t colon = v.find(':');
  if (h.empty() || v.empty() ||
      h.substr(0, h.find(':')) != v.substr(0, colon)) {
    return "";
  }
  return h + "+" + v.substr(colon + 1);
}

bool IsGeographicType(PJ_TYPE type) {
  return type == PJ_TYPE_GEOGRAPHIC_2D_CRS ||
         type == PJ_TYPE_GEOGRAPHIC_3D_CRS || type == PJ_TYPE_GEOGRAPHIC_CRS;
}

struct AreaOfUse {
  bool known = false;
  double west = -180.0, south = -90.0, east = 180.0, north = 90.0;

  bool Contains(double lon_deg, double lat_deg) const {
    if (!known) return true;
    // A small margin: a survey that starts a few metres outside an area of
    // use (a zone boundary, a border) still gets that area's operation.
    constexpr double kMarginDeg = 0.01;
    if (lat_deg < south - kMarginDeg || lat_deg > north + kMarginDeg) {
      return false;
    }
    if (west <= east) {
      return lon_deg >= west - kMarginDeg && lon_deg <= east + kMarginDeg;
    }
    return lon_deg >= west - kMarginDeg || lon_deg <= east + kMarginDeg;
  }
};

AreaOfUse AreaOf(PJ_CONTEXT* context, const PJ* operation) {
  AreaOfUse area;
  area.known = proj_get_area_of_use(context, operation, &area.west, &area.south,
                                    &area.east, &area.north,
                                    nullptr) != 0 &&
               area.west > -1000.0;  // PROJ writes -1000 when unknown
  return area;
}

// The grids of `operation` PROJ cannot find, with the package PROJ's
// database says ships them.
std::vector<std::string> MissingGrids(PJ_CONTEXT* context,
                                      const PJ* operation) {
  std::vector<std::string> grids;
  const int count = proj_coordoperation_get_grid_used_count(context, operation);
  for (int i = 0; i < count; ++i) {
    const char* short_name = nullptr;
    const char* package = nullptr;
    int available = 0;
    if (!proj_coordoperation_get_grid_used(context, operation, i, &short_name,
                                           nullptr, &package, nullptr, nullptr,
                                           nullptr, &available) ||
        available || short_name == nullptr) {
      continue;
    }
    std::string grid = short_name;
    if (package != nullptr && *package != '\0') {
      grid += std::string(" (PROJ package ") + package + ")";
    }
    grids.push_back(grid);
  }
  return grids;
}

std::string JoinGrids(const std::vector<std::string>& grids) {
  std::string text;
  for (std::size_t i = 0; i < grids.size(); ++i) {
    if (i > 0) text += i + 1 == grids.size() ? " or " : ", ";
    text += grids[i];
  }
  return text;
}

}  // namespace

std::string CrsOptions::Check() const {
  OptionCheck check;
  for (const std::string& folder : grid_dirs) {
    check.Require(!folder.empty(), "grid_dirs[]", std::string("\"\""),
                  "must not be an empty folder name");
  }
  return check.problem();
}

Crs::Crs(const std::string& definition) : definition_(definition) {
  ContextPtr context = MakeContext(CrsOptions());
  PjPtr crs = CreateCrs(context.get(), definition);
  const char* name = proj_get_name(crs.get());
  name_ = name == nullptr ? definition : name;
  const char* const options[] = {"MULTILINE=NO", nullptr};
  const char* wkt =
      proj_as_wkt(context.get(), crs.get(), PJ_WKT2_2019, options);
  wkt_ = wkt == nullptr ? std::string() : wkt;

  auto [horizontal, vertical] = SplitCrs(context.get(), crs.get());
  identifier_ = Identifier(crs.get());
  if (identifier_.empty() && horizontal && vertical) {
    identifier_ = CompoundIdentifier(horizontal.get(), vertical.get());
  }
  if (horizontal) {
    is_geographic_ = IsGeographicType(proj_get_type(horizontal.get()));
    horizontal_unit_ = FirstAxisUnit(context.get(), horizontal.get());
  }
  has_vertical_ = vertical != nullptr;
  vertical_unit_ =
      vertical ? FirstAxisUnit(context.get(), vertical.get()) : "metre";
  if (has_vertical_) {
    const char* vertical_name = proj_get_name(vertical.get());
    vertical_name_ = vertical_name == nullptr ? "" : vertical_name;
  }
}

std::string Crs::Description() const {
  std::string text = name_;
  if (!identifier_.empty()) text += " [" + identifier_ + "]";
  text += is_geographic_
              ? "; x,y: longitude,latitude (" + horizontal_unit_ + ")"
              : "; x,y: easting,northing (" + horizontal_unit_ + ")";
  text += has_vertical_
              ? "; height: " + vertical_name_ + " (" + vertical_unit_ + ")"
              : "; height: ellipsoidal (metre)";
  return text;
}

struct CrsTransformer::Impl {
  struct Operation {
    PjPtr pj;  // normalised: lon, lat, h in; x (east), y (north), z out
    AreaOfUse area;
    std::string name;
  };

  explicit Impl(const Crs& crs_in) : crs(crs_in) {}

  Crs crs;
  ContextPtr context;
  std::vector<Operation> usable;  // PROJ's order, best first
  // Operations PROJ ranks but that cannot run here, with their missing
  // grids: named when a point needs one of them.
  std::vector<std::pair<AreaOfUse, std::vector<std::string>>> unusable;
  mutable std::string last_operation;

  std::string GridsMissingAt(double lon_deg, double lat_deg) const {
    std::vector<std::string> grids;
    for (const auto& [area, missing] : unusable) {
      if (!area.Contains(lon_deg, lat_deg)) continue;
      for (const std::string& grid : missing) {
        if (std::find(grids.begin(), grids.end(), grid) == grids.end()) {
          grids.push_back(grid);
        }
      }
    }
    return JoinGrids(grids);
  }

  std::string Title() const {
    return "WGS 84 (EPSG:4979) to " + crs.name() +
           (crs.identifier().empty() ? "" : " (" + crs.identifier() + ")");
  }

  std::string MissingGridError(const std::string& grids) const {
    return "no usable transformation from " + Title() + ": grid " + grids +
           " is missing (searched in " + SearchPathText() +
           "; install the Debian package that ships it, or name the folder "
           "holding the file in 'crs_grid_dirs')";
  }

  std::string SearchPathText() const {
    std::string text;
    for (const std::string& folder : extra_dirs) text += folder + ":";
    return text + DefaultSearchPath();
  }

  // The operation for a WGS84 position: the first usable one whose area
  // holds it; a missing grid PROJ would use there is an error; outside
  // every area, PROJ's best usable operation (a projection a little beyond
  // its zone is still exact).
  const Operation& OperationAt(double lon_deg, double lat_deg) const {
    for (const Operation& operation : usable) {
      if (operation.area.known && operation.area.Contains(lon_deg, lat_deg)) {
        return operation;
      }
    }
    const std::string grids = GridsMissingAt(lon_deg, lat_deg);
    if (!grids.empty()) throw CrsError(MissingGridError(grids));
    for (const Operation& operation : usable) {
      if (operation.area.Contains(lon_deg, lat_deg)) return operation;
    }
    return usable.front();
  }

  std::vector<std::string> extra_dirs;
};

CrsTransformer::CrsTransformer(const Crs& crs, const CrsOptions& options)
    : impl_(std::make_unique<Impl>(crs)) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw std::invalid_argument(problem);
  Impl& impl = *impl_;
  impl.extra_dirs = options.grid_dirs;
  impl.context = MakeContext(options);
  PJ_CONTEXT* context = impl.context.get();
  PjPtr source = CreateCrs(context, kWgs84Definition);
  PjPtr target = CreateCrs(context, crs.definition());

  std::unique_ptr<PJ_OPERATION_FACTORY_CONTEXT,
                  decltype(&proj_operation_factory_context_destroy)>
      factory(proj_create_operation_factory_context(context, nullptr),
              &proj_operation_factory_context_destroy);
  proj_operation_factory_context_set_spatial_criterion(
      context, factory.get(), PROJ_SPATIAL_CRITERION_PARTIAL_INTERSECTION);
  // Keep operations whose grids are missing, to name those grids.
  proj_operation_factory_context_set_grid_availability_use(
      context, factory.get(), PROJ_GRID_AVAILABILITY_USED_FOR_SORTING);
  std::unique_ptr<PJ_OBJ_LIST, decltype(&proj_list_destroy)> operations(
      proj_create_operations(context, source.get(), target.get(),
                             factory.get()),
      &proj_list_destroy);
  const int count = operations ? proj_list_get_count(operations.get()) : 0;
  bool any_ballpark = false;
  for (int i = 0; i < count; ++i) {
    PjPtr operation(proj_list_get(context, operations.get(), i));
    if (!operation) continue;
    const AreaOfUse area = AreaOf(context, operation.get());
    if (proj_coordoperation_has_ballpark_transformation(context,
                                                        operation.get())) {
      any_ballpark = true;
      continue;
    }
    if (!proj_coordoperation_is_instantiable(context, operation.get())) {
      impl.unusable.emplace_back(area, MissingGrids(context, operation.get()));
      continue;
    }
    PjPtr normalised(
        proj_normalize_for_visualization(context, operation.get()));
    if (!normalised) continue;
    const char* name = proj_get_name(operation.get());
    impl.usable.push_back(
        {std::move(normalised), area, name == nullptr ? "" : name});
  }
  if (!impl.usable.empty()) return;
  std::vector<std::string> grids;
  for (const auto& entry : impl.unusable) {
    for (const std::string& grid : entry.second) {
      if (std::find(grids.begin(), grids.end(), grid) == grids.end()) {
        grids.push_back(grid);
      }
    }
  }
  if (!grids.empty()) throw CrsError(impl.MissingGridError(JoinGrids(grids)));
  throw CrsError("no usable transformation from " + impl.Title() +
                 (any_ballpark ? ": PROJ knows only a ballpark one (a datum "
                                 "shift or a geoid left out), which zebrageo "
                                 "refuses; give the datum shift (+towgs84) "
                                 "or the geoid grid (+geoidgrids) in a PROJ "
                                 "string"
                               : ": " + LastError(context)));
}

CrsTransformer::~CrsTransformer() = default;
CrsTransformer::CrsTransformer(CrsTransformer&&) noexcept = default;
CrsTransformer& CrsTransformer::operator=(CrsTransformer&&) noexcept = default;

const Crs& CrsTransformer::crs() const { return impl_->crs; }

namespace {

bool AllFinite(const PJ_COORD& coord) {
  return std::isfinite(coord.xyz.x) && std::isfinite(coord.xyz.y) &&
         std::isfinite(coord.xyz.z) && std::abs(coord.xyz.x) < 1e30 &&
         std::abs(coord.xyz.y) < 1e30 && std::abs(coord.xyz.z) < 1e30;
}

std::string PointText(double a, double b, double c) {
  std::ostringstream text;
  text.precision(12);
  text << "(" << a << ", " << b << ", " << c << ")";
  return text.str();
}

}  // namespace

Eigen::Vector3d CrsTransformer::FromWgs84(const Geodetic& wgs84) const {
  const Impl::Operation& operation =
      impl_->OperationAt(wgs84.lon_deg, wgs84.lat_deg);
  PJ_COORD in = proj_coord(wgs84.lon_deg, wgs84.lat_deg, wgs84.h_m, 0.0);
  proj_errno_reset(operation.pj.get());
  const PJ_COORD out = proj_trans(operation.pj.get(), PJ_FWD, in);
  if (!AllFinite(out)) {
    throw CrsError("PROJ cannot transform WGS 84 lat, lon, h " +
                   PointText(wgs84.lat_deg, wgs84.lon_deg, wgs84.h_m) + " to " +
                   impl_->crs.name() + " with \"" + operation.name +
                   "\": " + LastError(impl_->context.get()));
  }
  impl_->last_operation = operation.name;
  return Eigen::Vector3d(out.xyz.x, out.xyz.y, out.xyz.z);
}

Geodetic CrsTransformer::ToWgs84(const Eigen::Vector3d& xyz) const {
  // The area of use is known in WGS84 only: try each usable operation and
  // keep the first whose result lies in its area.
  const PJ_COORD in = proj_coord(xyz.x(), xyz.y(), xyz.z(), 0.0);
  for (const Impl::Operation& operation : impl_->usable) {
    proj_errno_reset(operation.pj.get());
    const PJ_COORD out = proj_trans(operation.pj.get(), PJ_INV, in);
    if (!AllFinite(out)) continue;
    if (&impl_->OperationAt(out.lpz.lam, out.lpz.phi) != &operation) {
      continue;
    }
    impl_->last_operation = operation.name;
    return Geodetic{out.xyz.y, out.xyz.x, out.xyz.z};
  }
  throw CrsError(
      "PROJ cannot transform " + PointText(xyz.x(), xyz.y(), xyz.z()) + " of " +
      impl_->crs.name() + " to WGS 84: " + LastError(impl_->context.get()));
}

std::string CrsTransformer::LastOperationName() const {
  return impl_->last_operation;
}

bool IsContractCrs(const std::string& definition) {
  if (definition.find_first_not_of(" \t\r\n") == std::string::npos) {
    return true;
  }
  ContextPtr context = MakeContext(CrsOptions());
  PjPtr crs = CreateCrs(context.get(), definition);
  PjPtr wgs84 = CreateCrs(context.get(), kWgs84Definition);
  return proj_is_equivalent_to_with_ctx(context.get(), crs.get(), wgs84.get(),
                                        PJ_COMP_EQUIVALENT) != 0;
}

}  // namespace zebrageo
