#include "registration/roadmark_index.h"

#include <glog/logging.h>

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

#include "survey/math_util.h"

namespace zebrageo {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

using BoostPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BoostBox = bg::model::box<BoostPoint>;
using TreeValue = std::pair<BoostBox, int>;
// Quadratic split with 16 entries per node: the packing constructor bulk
// loads (STR-like), so the split algorithm only matters for inserts.
using Tree = bgi::rtree<TreeValue, bgi::quadratic<16>>;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Mean of axes (directions up to sign): average the doubled angles.
Eigen::Vector2d MeanAxis(const std::vector<Eigen::Vector2d>& axes) {
  double c = 0.0;
  double s = 0.0;
  for (const Eigen::Vector2d& a : axes) {
    const double angle = 2.0 * std::atan2(a.y(), a.x());
    c += std::cos(angle);
    s += std::sin(angle);
  }
  const double angle = 0.5 * std::atan2(s, c);
  return Eigen::Vector2d(std::cos(angle), std::sin(angle));
}

IndexedCrossing CrossingGeometry(const std::string& crossing_id,
                                 std::vector<int> members,
                                 const std::vector<IndexedBand>& bands) {
  IndexedCrossing crossing;
  crossing.crossing_id = crossing_id;
  std::sort(members.begin(), members.end(),
            [&](int a, int b) { return bands[a].band < bands[b].band; });
  crossing.bands = members;
  std::vector<Eigen::Vector2d> axes;
  std::vector<double> lengths;
  std::vector<double> widths;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int b : members) {
    axes.push_back(bands[b].axis_enu);
    lengths.push_back(bands[b].length_m);
    widths.push_back(bands[b].width_m);
    sum += bands[b].centre_enu;
  }
  crossing.centre_enu = sum / static_cast<double>(members.size());
  crossing.band_axis = MeanAxis(axes);
  crossing.band_length_m = Median(lengths);
  crossing.band_width_m = Median(widths);
  const IndexedBand& first = bands[members.front()];
  const IndexedBand& last = bands[members.back()];
  crossing.first_band = first.band;
  crossing.last_band = last.band;
  crossing.first_end_enu = first.centre_enu;
  crossing.last_end_enu = last.centre_enu;
  // across_axis: normal to the bands, pointing from the first band to the
  // last (a one-band crossing keeps the left normal).
  Eigen::Vector2d normal(-crossing.band_axis.y(), crossing.band_axis.x());
  const Eigen::Vector2d span = last.centre_enu - first.centre_enu;
  if (span.dot(normal) < 0.0) normal = -normal;
  crossing.across_axis = normal;
  const int numbers = last.band - first.band;
  if (numbers > 0) {
    crossing.spacing_m = span.dot(normal) / numbers;
    crossing.skew_rad =
        std::atan2(span.dot(crossing.band_axis), span.dot(normal));
  }
  for (size_t i = 1; i < members.size(); ++i) {
    const int from = bands[members[i - 1]].band + 1;
    const int to = bands[members[i]].band;
    std::vector<int>& gap = to - from >= 2 ? crossing.island_band_numbers
                                           : crossing.missing_band_numbers;
    for (int n = from; n < to; ++n) gap.push_back(n);
  }
  for (int b : members) {
    for (const Eigen::Vector3d& corner : bands[b].corners_enu) {
      crossing.radius_m = std::max(
          crossing.radius_m, (corner.head<2>() - crossing.centre_enu).norm());
    }
  }
  return crossing;
}

// The bands `crossing`'s numbering implies but the database lacks
// (IndexedBand::implied), appended to `bands` and `values`.
void AddImpliedBands(int index, IndexedCrossing* crossing,
                     std::vector<IndexedBand>* bands,
                     std::vector<TreeValue>* values) {
  const IndexedBand& first = (*bands)[crossing->bands.front()];
  const IndexedBand& last = (*bands)[crossing->bands.back()];
  const int numbers = last.band - first.band;
  if (numbers <= 0) return;  // one band: no period to extrapolate with
  // One band number further, centre to centre (skew included).
  const Eigen::Vector2d period =
      (last.centre_enu - first.centre_enu) / static_cast<double>(numbers);
  std::vector<int> missing = crossing->missing_band_numbers;
  for (int n = 1; n < first.band; ++n) missing.push_back(n);
  std::sort(missing.begin(), missing.end());
  for (int n : missing) {
    // The held band nearest in number lends its shape.
    int nearest = crossing->bands.front();
    for (int b : crossing->bands) {
      if (std::abs((*bands)[b].band - n) <
          std::abs((*bands)[nearest].band - n)) {
        nearest = b;
      }
    }
    IndexedBand band = (*bands)[nearest];
    const Eigen::Vector2d shift = (n - band.band) * period;
    band.source_index = -1;
    band.band = n;
    band.implied = true;
    Eigen::Vector2d low =
        Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d high = -low;
    for (Eigen::Vector3d& corner : band.corners_enu) {
      corner.head<2>() += shift;
      low = low.cwiseMin(corner.head<2>());
      high = high.cwiseMax(corner.head<2>());
    }
    band.centre_enu += shift;
    band.crossing = index;
    const int id = static_cast<int>(bands->size());
    crossing->implied_bands.push_back(id);
    values->emplace_back(
        BoostBox(BoostPoint(low.x(), low.y()), BoostPoint(high.x(), high.y())),
        id);
    bands->push_back(std::move(band));
  }
}

}  // namespace

Eigen::Vector2d IndexedCrossing::ToCrossing(
    const Eigen::Vector2d& p_enu) const {
  const Eigen::Vector2d d = p_enu - centre_enu;
  return Eigen::Vector2d(d.dot(band_axis), d.dot(across_axis));
}

BandShape ShapeOfBand(const std::array<Eigen::Vector2d, 4>& c) {
  BandShape shape;
  shape.centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
  // Sides 0-1 and 2-3 face each other, as do 1-2 and 3-0; the longer pair
  // are the long sides.
  const double a = 0.5 * ((c[1] - c[0]).norm() + (c[3] - c[2]).norm());
  const double b = 0.5 * ((c[2] - c[1]).norm() + (c[0] - c[3]).norm());
  Eigen::Vector2d direction;
  if (a >= b) {
    direction = (c[1] - c[0]) + (c[2] - c[3]);
    shape.length_m = a;
  } else {
    direction = (c[2] - c[1]) + (c[3] - c[0]);
    shape.length_m = b;
  }
  if (direction.norm() > 0.0) shape.axis = direction.normalized();
  double twice_area = 0.0;
  for (int i = 0; i < 4; ++i) twice_area += Cross(c[i], c[(i + 1) % 4]);
  shape.width_m =
      shape.length_m > 0.0 ? 0.5 * std::abs(twice_area) / shape.length_m : 0.0;
  return shape;
}

struct RoadmarkIndex::Impl {
  int num_database_bands = 0;
  std::vector<IndexedBand> bands;
  std::vector<IndexedCrossing> crossings;
  std::unordered_map<std::string, int> crossing_of_id;
  Tree tree;
};

RoadmarkIndex::RoadmarkIndex() : impl_(std::make_unique<Impl>()) {}
RoadmarkIndex::~RoadmarkIndex() = default;
RoadmarkIndex::RoadmarkIndex(RoadmarkIndex&&) noexcept = default;
RoadmarkIndex& RoadmarkIndex::operator=(RoadmarkIndex&&) noexcept = default;

RoadmarkIndex::RoadmarkIndex(const RoadmarkDatabase& database,
                             const LocalFrame& frame)
    : impl_(std::make_unique<Impl>()) {
  std::vector<IndexedBand>& bands = impl_->bands;
  bands.reserve(database.bands.size());
  std::vector<std::vector<int>> members;
  std::vector<TreeValue> values;
  values.reserve(database.bands.size());
  for (size_t i = 0; i < database.bands.size(); ++i) {
    const RoadmarkBand& source = database.bands[i];
    IndexedBand band;
    band.source_index = static_cast<int>(i);
    band.crossing_id = source.crossing_id;
    band.band = source.band;
    band.sigma_xy_m = source.sigma_xy_m;
    band.sigma_z_m = source.sigma_z_m;
    std::array<Eigen::Vector2d, 4> corners2;
    Eigen::Vector2d low =
        Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d high = -low;
    for (int k = 0; k < 4; ++k) {
      band.corners_enu[k] = frame.EnuFromGeodetic(source.corners[k]);
      corners2[k] = band.corners_enu[k].head<2>();
      low = low.cwiseMin(corners2[k]);
      high = high.cwiseMax(corners2[k]);
    }
    const BandShape shape = ShapeOfBand(corners2);
    band.centre_enu = shape.centre;
    band.axis_enu = shape.axis;
    band.length_m = shape.length_m;
    band.width_m = shape.width_m;
    const auto found = impl_->crossing_of_id.find(source.crossing_id);
    if (found == impl_->crossing_of_id.end()) {
      band.crossing = static_cast<int>(members.size());
      impl_->crossing_of_id.emplace(source.crossing_id, band.crossing);
      members.emplace_back();
    } else {
      band.crossing = found->second;
    }
    members[band.crossing].push_back(static_cast<int>(i));
    values.emplace_back(
        BoostBox(BoostPoint(low.x(), low.y()), BoostPoint(high.x(), high.y())),
        static_cast<int>(i));
    bands.push_back(std::move(band));
  }
  impl_->crossings.reserve(members.size());
  for (size_t c = 0; c < members.size(); ++c) {
    const std::string& id = bands[members[c].front()].crossing_id;
    impl_->crossings.push_back(CrossingGeometry(id, members[c], bands));
  }
  impl_->num_database_bands = static_cast<int>(bands.size());
  for (size_t c = 0; c < impl_->crossings.size(); ++c) {
    AddImpliedBands(static_cast<int>(c), &impl_->crossings[c], &bands, &values);
  }
  impl_->tree = Tree(values.begin(), values.end());
  VLOG(1) << "road-mark index: " << bands.size() << " bands, "
          << impl_->crossings.size() << " crossings";
}

int RoadmarkIndex::num_database_bands() const {
  return impl_->num_database_bands;
}

const std::vector<IndexedBand>& RoadmarkIndex::bands() const {
  return impl_->bands;
}

const std::vector<IndexedCrossing>& RoadmarkIndex::crossings() const {
  return impl_->crossings;
}

int RoadmarkIndex::FindCrossing(const std::string& crossing_id) const {
  const auto found = impl_->crossing_of_id.find(crossing_id);
  return found == impl_->crossing_of_id.end() ? -1 : found->second;
}

void RoadmarkIndex::BandsWithin(const Eigen::Vector2d& point_enu,
                                double radius_m,
                                std::vector<int>* bands) const {
  bands->clear();
  const BoostBox query(
      BoostPoint(point_enu.x() - radius_m, point_enu.y() - radius_m),
      BoostPoint(point_enu.x() + radius_m, point_enu.y() + radius_m));
  const BoostPoint centre(point_enu.x(), point_enu.y());
  impl_->tree.query(
      bgi::intersects(query) && bgi::satisfies([&](const TreeValue& value) {
        return bg::comparable_distance(centre, value.first) <=
               radius_m * radius_m;
      }),
      boost::make_function_output_iterator(
          [bands](const TreeValue& value) { bands->push_back(value.second); }));
}

void RoadmarkIndex::CrossingsWithin(const Eigen::Vector2d& point_enu,
                                    double radius_m,
                                    std::vector<int>* crossings) const {
  std::vector<int> bands;
  BandsWithin(point_enu, radius_m, &bands);
  crossings->clear();
  for (int b : bands) crossings->push_back(impl_->bands[b].crossing);
  std::sort(crossings->begin(), crossings->end());
  crossings->erase(std::unique(crossings->begin(), crossings->end()),
                   crossings->end());
}

int RoadmarkIndex::NearestBand(const Eigen::Vector2d& point_enu) const {
  int nearest = -1;
  impl_->tree.query(
      bgi::nearest(BoostPoint(point_enu.x(), point_enu.y()), 1),
      boost::make_function_output_iterator(
          [&nearest](const TreeValue& value) { nearest = value.second; }));
  return nearest;
}

}  // namespace zebrageo
