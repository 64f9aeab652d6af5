#include "simulator/renderer.h"

#include <glog/logging.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "simulator/noise.h"
#include "survey/threads.h"

namespace zebrageo::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ------------------------------------------------------------ materials
// A sample's key: material type in the top byte, an instance id below.
// Pixels whose samples share one key are not supersampled.
enum Material : uint32_t {
  kSky = 1,
  kFarGround,
  kAsphalt,
  kGutter,
  kKerb,
  kSidewalk,
  kBandPaint,
  kLinePaint,
  kStopLinePaint,
  kManhole,
  kWall,
  kWindow,
  kVehicle,
};
constexpr uint32_t kShadowBit = 0x800000;

inline uint32_t Key(uint32_t material, uint64_t id) {
  return (material << 24) | static_cast<uint32_t>(id & 0x7fffff);
}

struct Sample {
  float value = 0.0f;
  uint32_t key = 0;
};

// Tones (grey levels of fully lit surfaces, 0..255).
constexpr float kAsphaltTone = 82.0f;
constexpr float kPaintTone = 212.0f;
constexpr float kHazeTone = 200.0f;
constexpr double kFogDistanceM = 700.0;

// Monotonic stand-in for the angle of (x, y), in [0, 4).
inline double PseudoAngle(double x, double y) {
  const double p = x / (std::abs(x) + std::abs(y) + 1e-300);
  return y < 0.0 ? 3.0 + p : 1.0 - p;
}

// Multi-scale value noise of asphalt, octaves finer than ~2 footprints
// faded out (a cheap mip-map: no aliasing far away).
float AsphaltTexture(double x, double y, double footprint_m, uint64_t salt) {
  static constexpr double kScales[6] = {4.0, 1.1, 0.3, 0.08, 0.025, 0.009};
  static constexpr float kAmplitudes[6] = {0.09f, 0.07f, 0.07f,
                                           0.11f, 0.13f, 0.10f};
  float sum = 0.0f;
  for (int o = 0; o < 6; ++o) {
    const double ratio = kScales[o] / footprint_m;
    if (ratio < 1.5) break;
    const float weight = static_cast<float>(std::min(1.0, (ratio - 1.5) / 1.5));
    sum += kAmplitudes[o] * weight *
           (2.0f * ValueNoise(x / kScales[o], y / kScales[o], salt + o) - 1.0f);
  }
  return 1.0f + sum;
}

// Paint coverage in [0, 1] at (x, y): worn by world-anchored noise.
float PaintAlpha(double x, double y, float wear, uint64_t salt) {
  const float n = 0.65f * ValueNoise(x / 0.4, y / 0.4, salt) +
                  0.35f * ValueNoise(x / 0.09, y / 0.09, salt + 1);
  const float worn = static_cast<float>(SmoothStep(0.3, 0.8, n));
  return 0.97f - wear * worn;
}

float PaintTone(double x, double y, double footprint_m, uint64_t salt) {
  float grain = 1.0f;
  if (footprint_m < 0.01) {
    grain += 0.05f * (2.0f * ValueNoise(x / 0.02, y / 0.02, salt + 7) - 1.0f);
  }
  return kPaintTone * grain;
}

struct BoxRef {
  const VerticalBox* box = nullptr;
  bool is_vehicle = false;
  int index = 0;
};

struct BoxHit {
  double t = kInf;
  int ref = -1;
  int face = 0;  // 0: -u, 1: +u, 2: -v, 3: +v, 4: top
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

struct GroundPoint {
  double s = 0.0, l = 0.0, z = 0.0, dzdx = 0.0, dzdy = 0.0;
  int cell = -1;
};

// The ground's tangent plane where a neighbouring ray hit it: intersecting
// the next ray with it starts Newton within micrometres of the root.
struct GroundHint {
  bool valid = false;
  double x = 0.0, y = 0.0, z = 0.0, dzdx = 0.0, dzdy = 0.0;
};

// ------------------------------------------------------------ one image
class ImageScene {
 public:
  ImageScene(const World& world, const RenderSettings& settings,
             const std::vector<int>& first_band, const Eigen::Isometry3d& T,
             double s_hint, double focal_px);

  // Traces the ray through normalised coordinates (xn, yn). `ground_hint`
  // carries the ground hit of a neighbouring ray and is updated.
  Sample Trace(double xn, double yn, GroundHint* ground_hint) const;

 private:
  void BuildGrid();
  void AddItems();
  void BuildBoxBins();
  bool Lookup(double x, double y, GroundPoint* g) const;
  void CrownAt(double s, double* z, double* grade) const;
  bool IntersectGround(const Eigen::Vector3d& d, double t_max, GroundHint* hint,
                       double* t_hit, GroundPoint* g) const;
  // Nearest box hit closer than t_max.
  bool IntersectBoxes(const Eigen::Vector3d& d, double t_max,
                      BoxHit* hit) const;
  Sample ShadeGround(const Eigen::Vector3d& d, double t, const GroundPoint& g,
                     double t_box) const;
  Sample ShadeBox(const Eigen::Vector3d& d, const BoxHit& hit) const;
  Sample ShadeSky(const Eigen::Vector3d& d) const;
  float Fog(float value, double t) const;

  const World& world_;
  const Road& road_;
  const RenderSettings& settings_;
  const std::vector<int>& first_band_;
  Eigen::Matrix3d R_enu_cam_;
  Eigen::Vector3d C_;
  double focal_px_;
  double s_cam_ = 0.0;
  double z_below_cam_ = 0.0;
  double s_lo_ = 0.0, s_hi_ = 0.0;
  double half_width_ = 0.0;

  // (x, y) -> (s - s_cam, l) lookup grid.
  double x0_ = 0.0, y0_ = 0.0;
  double cell_ = 0.5;
  int nx_ = 0, ny_ = 0;  // nodes
  std::vector<float> grid_s_, grid_l_;
  // Features whose footprint may touch a cell (CSR): item = type << 24 | i.
  std::vector<int> cell_start_;
  std::vector<uint32_t> cell_items_;
  // Crown height and grade every kCrownStep from crown_s0_.
  static constexpr double kCrownStep = 0.25;
  double crown_s0_ = 0.0;
  std::vector<double> crown_z_, crown_grade_;

  std::vector<int> lines_;            // indices into world.lines
  std::vector<double> line_offsets_;  // distinct l of those lines
  double line_half_width_ = 0.0;
  std::vector<int> stop_lines_;  // indices into world.stop_lines
  std::vector<BoxRef> boxes_;
  std::vector<double> box_distance_;  // horizontal, camera to footprint
  // Boxes by pseudo-angle of the horizontal direction, in a frame whose
  // backward direction is the seam.
  static constexpr int kBins = 2048;
  Eigen::Vector2d back_x_, back_y_;
  std::vector<std::vector<int>> bins_;
};

enum ItemType : uint32_t {
  kItemCrossing = 1,
  kItemManhole,
  kItemStain,
  kItemShadow
};

ImageScene::ImageScene(const World& world, const RenderSettings& settings,
                       const std::vector<int>& first_band,
                       const Eigen::Isometry3d& T, double s_hint,
                       double focal_px)
    : world_(world),
      road_(world.road),
      settings_(settings),
      first_band_(first_band),
      R_enu_cam_(T.linear()),
      C_(T.translation()),
      focal_px_(focal_px),
      half_width_(0.5 * world.road.width_m()) {
  double l = 0.0;
  road_.ToRoadCoordinates(C_.head<2>(), s_hint, &s_cam_, &l);
  z_below_cam_ = road_.Height(s_cam_, l);
  // The road is drawn from 8 m behind the camera to max_ground_range_m in
  // front of it, along the road in the direction it looks (a rear camera
  // sees the road it has driven).
  const bool looks_back =
      R_enu_cam_.col(2).head<2>().dot(road_.Tangent(s_cam_)) < 0.0;
  s_lo_ = looks_back ? s_cam_ - settings.max_ground_range_m : s_cam_ - 8.0;
  s_hi_ = looks_back ? s_cam_ + 8.0 : s_cam_ + settings.max_ground_range_m;
  crown_s0_ = s_lo_ - 5.0;
  const int n = static_cast<int>((s_hi_ + 5.0 - crown_s0_) / kCrownStep) + 2;
  crown_z_.resize(n);
  crown_grade_.resize(n);
  for (int i = 0; i < n; ++i) {
    crown_z_[i] = road_.CrownHeight(crown_s0_ + i * kCrownStep);
    crown_grade_[i] = road_.Grade(crown_s0_ + i * kCrownStep);
  }
  BuildGrid();
  AddItems();
  BuildBoxBins();
  for (int i = 0; i < static_cast<int>(world.lines.size()); ++i) {
    const LinePiece& line = world.lines[i];
    if (line.s1 > s_lo_ && line.s0 < s_hi_) {
      lines_.push_back(i);
      line_half_width_ = std::max(line_half_width_, 0.5 * line.width_m);
      if (std::find(line_offsets_.begin(), line_offsets_.end(), line.l_m) ==
          line_offsets_.end()) {
        line_offsets_.push_back(line.l_m);
      }
    }
  }
  for (int i = 0; i < static_cast<int>(world.stop_lines.size()); ++i) {
    const double s = world.stop_lines[i].s_m;
    if (s > s_lo_ && s < s_hi_) stop_lines_.push_back(i);
  }
}

void ImageScene::BuildGrid() {
  const double l_max = half_width_ + 20.0;
  double x_min = kInf, x_max = -kInf, y_min = kInf, y_max = -kInf;
  for (double s = s_lo_; s <= s_hi_ + 2.0; s += 2.0) {
    for (double l : {-l_max, l_max}) {
      const Eigen::Vector2d p = road_.Centre(s) + l * road_.LeftNormal(s);
      x_min = std::min(x_min, p.x());
      x_max = std::max(x_max, p.x());
      y_min = std::min(y_min, p.y());
      y_max = std::max(y_max, p.y());
    }
  }
  x0_ = x_min;
  y0_ = y_min;
  nx_ = static_cast<int>(std::ceil((x_max - x_min) / cell_)) + 2;
  ny_ = static_cast<int>(std::ceil((y_max - y_min) / cell_)) + 2;
  grid_s_.resize(static_cast<size_t>(nx_) * ny_);
  grid_l_.resize(grid_s_.size());
  double row_guess = s_cam_;
  for (int j = 0; j < ny_; ++j) {
    double guess = row_guess;
    for (int i = 0; i < nx_; ++i) {
      double s = 0.0, l = 0.0;
      road_.ToRoadCoordinates(Eigen::Vector2d(x0_ + i * cell_, y0_ + j * cell_),
                              guess, &s, &l);
      grid_s_[static_cast<size_t>(j) * nx_ + i] =
          static_cast<float>(s - s_cam_);
      grid_l_[static_cast<size_t>(j) * nx_ + i] = static_cast<float>(l);
      guess = s;
      if (i == 0) row_guess = s;
    }
  }
}

void ImageScene::AddItems() {
  const int cells_x = nx_ - 1, cells_y = ny_ - 1;
  std::vector<std::pair<uint32_t, Eigen::AlignedBox2d>> items;
  auto box_of = [](const auto& points, double margin) {
    Eigen::AlignedBox2d box;
    for (const auto& p : points) box.extend(Eigen::Vector2d(p.x(), p.y()));
    box.min().array() -= margin;
    box.max().array() += margin;
    return box;
  };
  for (int c = 0; c < static_cast<int>(world_.crossings.size()); ++c) {
    const Crossing& crossing = world_.crossings[c];
    if (!crossing.in_street || first_band_[c] < 0) continue;
    if (crossing.s_max < s_lo_ || crossing.s_min > s_hi_) continue;
    Eigen::AlignedBox2d box;
    for (int b = 0; b < crossing.num_street_bands; ++b) {
      box.extend(box_of(world_.bands[first_band_[c] + b].corners, 0.3));
    }
    items.push_back({(kItemCrossing << 24) | c, box});
  }
  const Eigen::AlignedBox2d view(
      Eigen::Vector2d(x0_, y0_),
      Eigen::Vector2d(x0_ + cells_x * cell_, y0_ + cells_y * cell_));
  for (int i = 0; i < static_cast<int>(world_.manholes.size()); ++i) {
    const Manhole& m = world_.manholes[i];
    Eigen::AlignedBox2d box(m.centre);
    box.min().array() -= 1.5 * m.radius_m;
    box.max().array() += 1.5 * m.radius_m;
    if (view.intersects(box)) items.push_back({(kItemManhole << 24) | i, box});
  }
  for (int i = 0; i < static_cast<int>(world_.stains.size()); ++i) {
    const Stain& st = world_.stains[i];
    Eigen::AlignedBox2d box(st.centre);
    box.min().array() -= 1.4 * st.radius_m;
    box.max().array() += 1.4 * st.radius_m;
    if (view.intersects(box)) items.push_back({(kItemStain << 24) | i, box});
  }
  for (int i = 0; i < static_cast<int>(world_.shadows.size()); ++i) {
    const Eigen::AlignedBox2d box = box_of(world_.shadows[i].polygon, 0.1);
    if (view.intersects(box)) items.push_back({(kItemShadow << 24) | i, box});
  }
  // Two passes: count, then fill.
  cell_start_.assign(static_cast<size_t>(cells_x) * cells_y + 1, 0);
  auto for_cells = [&](const Eigen::AlignedBox2d& box, auto&& fn) {
    const int i0 = std::max(0, static_cast<int>((box.min().x() - x0_) / cell_));
    const int i1 =
        std::min(cells_x - 1, static_cast<int>((box.max().x() - x0_) / cell_));
    const int j0 = std::max(0, static_cast<int>((box.min().y() - y0_) / cell_));
    const int j1 =
        std::min(cells_y - 1, static_cast<int>((box.max().y() - y0_) / cell_));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) fn(static_cast<size_t>(j) * cells_x + i);
    }
  };
  for (const auto& [item, box] : items) {
    for_cells(box, [&](size_t cell) { ++cell_start_[cell + 1]; });
  }
  for (size_t k = 1; k < cell_start_.size(); ++k) {
    cell_start_[k] += cell_start_[k - 1];
  }
  cell_items_.resize(cell_start_.back());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (const auto& [item, box] : items) {
    for_cells(box, [&](size_t cell) { cell_items_[fill[cell]++] = item; });
  }
}

void ImageScene::BuildBoxBins() {
  // Backward-looking frame: its pseudo-angle seam is behind the camera.
  const Eigen::Vector3d forward = R_enu_cam_.col(2);
  Eigen::Vector2d f(forward.x(), forward.y());
  if (f.norm() < 1e-6) f = Eigen::Vector2d::UnitX();
  f.normalize();
  back_x_ = -f;
  back_y_ = Eigen::Vector2d(f.y(), -f.x());
  bins_.assign(kBins, {});
  auto consider = [&](const VerticalBox& box, bool is_vehicle, int index) {
    double lo = 5.0, hi = -1.0;
    for (const Eigen::Vector2d& p : box.Footprint()) {
      const Eigen::Vector2d d = p - C_.head<2>();
      if (d.norm() > settings_.max_ground_range_m + 40.0) return;
      const double a = PseudoAngle(d.dot(back_x_), d.dot(back_y_));
      lo = std::min(lo, a);
      hi = std::max(hi, a);
    }
    if (hi - lo > 2.0) return;  // straddles the seam: behind the camera
    boxes_.push_back({&box, is_vehicle, index});
    // Distance from the camera to the rectangle (0 inside).
    const Eigen::Vector2d rel = C_.head<2>() - box.centre;
    const double du = std::max(0.0, std::abs(rel.dot(box.axis_u)) - box.half_u);
    const double dv =
        std::max(0.0, std::abs(rel.dot(box.axis_v())) - box.half_v);
    box_distance_.push_back(std::hypot(du, dv));
    const int b0 = std::clamp(static_cast<int>(lo / 4.0 * kBins), 0, kBins - 1);
    const int b1 = std::clamp(static_cast<int>(hi / 4.0 * kBins), 0, kBins - 1);
    for (int b = b0; b <= b1; ++b) {
      bins_[b].push_back(static_cast<int>(boxes_.size()) - 1);
    }
  };
  for (int i = 0; i < static_cast<int>(world_.buildings.size()); ++i) {
    const Building& b = world_.buildings[i];
    if (b.s1 < s_lo_ - 30.0 || b.s0 > s_hi_ + 30.0) continue;
    consider(b.box, false, i);
  }
  for (int i = 0; i < static_cast<int>(world_.vehicles.size()); ++i) {
    const ParkedVehicle& v = world_.vehicles[i];
    if (v.s1 < s_lo_ - 10.0 || v.s0 > s_hi_ + 10.0) continue;
    consider(v.box, true, i);
  }
  // Nearest first, so a ray stops at the first box beyond its best hit.
  for (std::vector<int>& bin : bins_) {
    std::sort(bin.begin(), bin.end(), [this](int a, int b) {
      return box_distance_[a] < box_distance_[b];
    });
  }
}

void ImageScene::CrownAt(double s, double* z, double* grade) const {
  const double u = (s - crown_s0_) / kCrownStep;
  const int i = static_cast<int>(std::floor(u));
  if (i < 0 || i + 1 >= static_cast<int>(crown_z_.size())) {
    *z = road_.CrownHeight(s);
    *grade = road_.Grade(s);
    return;
  }
  const double f = u - i;
  *z = crown_z_[i] + f * (crown_z_[i + 1] - crown_z_[i]);
  *grade = crown_grade_[i] + f * (crown_grade_[i + 1] - crown_grade_[i]);
}

bool ImageScene::Lookup(double x, double y, GroundPoint* g) const {
  const double fx = (x - x0_) / cell_;
  const double fy = (y - y0_) / cell_;
  double ds_dx, ds_dy, dl_dx, dl_dy;
  if (fx >= 0.0 && fy >= 0.0 && fx < nx_ - 1 && fy < ny_ - 1) {
    const int i = static_cast<int>(fx);
    const int j = static_cast<int>(fy);
    const double u = fx - i, v = fy - j;
    const size_t k = static_cast<size_t>(j) * nx_ + i;
    const double s00 = grid_s_[k], s10 = grid_s_[k + 1];
    const double s01 = grid_s_[k + nx_], s11 = grid_s_[k + nx_ + 1];
    const double l00 = grid_l_[k], l10 = grid_l_[k + 1];
    const double l01 = grid_l_[k + nx_], l11 = grid_l_[k + nx_ + 1];
    const double s0 = s00 + u * (s10 - s00), s1 = s01 + u * (s11 - s01);
    const double l0 = l00 + u * (l10 - l00), l1 = l01 + u * (l11 - l01);
    g->s = s_cam_ + s0 + v * (s1 - s0);
    g->l = l0 + v * (l1 - l0);
    ds_dx = ((s10 - s00) * (1 - v) + (s11 - s01) * v) / cell_;
    ds_dy = (s1 - s0) / cell_;
    dl_dx = ((l10 - l00) * (1 - v) + (l11 - l01) * v) / cell_;
    dl_dy = (l1 - l0) / cell_;
    g->cell = j * (nx_ - 1) + i;
  } else {
    road_.ToRoadCoordinates(Eigen::Vector2d(x, y), s_cam_, &g->s, &g->l);
    const Eigen::Vector2d t = road_.Tangent(g->s);
    const double scale =
        1.0 / std::max(0.2, 1.0 - road_.Curvature(g->s) * g->l);
    ds_dx = t.x() * scale;
    ds_dy = t.y() * scale;
    dl_dx = -t.y();
    dl_dy = t.x();
    g->cell = -1;
  }
  double crown, grade;
  CrownAt(g->s, &crown, &grade);
  double cross, slope;
  road_.CrossSectionAndSlope(g->l, &cross, &slope);
  g->z = crown + cross;
  g->dzdx = grade * ds_dx + slope * dl_dx;
  g->dzdy = grade * ds_dy + slope * dl_dy;
  return true;
}

bool ImageScene::IntersectGround(const Eigen::Vector3d& d, double t_max,
                                 GroundHint* hint, double* t_hit,
                                 GroundPoint* g) const {
  // f(t) = height of the ray above the surface; find its first root.
  auto eval = [&](double t, GroundPoint* p, double* f, double* df) {
    const double x = C_.x() + t * d.x(), y = C_.y() + t * d.y();
    Lookup(x, y, p);
    *f = C_.z() + t * d.z() - p->z;
    *df = d.z() - (p->dzdx * d.x() + p->dzdy * d.y());
  };
  double lo = 0.0, hi = t_max;
  bool hi_below = false;  // f(hi) <= 0 established
  double t = -1.0;
  if (hint->valid) {
    const double denominator = d.z() - hint->dzdx * d.x() - hint->dzdy * d.y();
    if (denominator < -1e-9) {
      const double tp = (hint->z + hint->dzdx * (C_.x() - hint->x) +
                         hint->dzdy * (C_.y() - hint->y) - C_.z()) /
                        denominator;
      if (tp > 0.0 && tp < t_max) t = tp;
    }
  }
  if (t > 0.0) {
    // From the neighbour's tangent plane.
  } else if (d.z() < -1e-4) {
    t = std::min(0.9 * t_max, (z_below_cam_ - C_.z()) / d.z());
  } else {
    t = 0.5 * t_max;
  }
  for (int iteration = 0; iteration < 40; ++iteration) {
    double f, df;
    eval(t, g, &f, &df);
    if (std::abs(f) < 2e-5) {
      *t_hit = t;
      *hint = {true,   C_.x() + t * d.x(), C_.y() + t * d.y(), g->z, g->dzdx,
               g->dzdy};
      return true;
    }
    if (f > 0.0) {
      lo = t;
    } else {
      hi = t;
      hi_below = true;
    }
    double next = df < 0.0 ? t - f / df : -1.0;
    if (!(next > lo && next < hi)) {
      if (!hi_below) {
        double f_max, df_max;
        GroundPoint end;
        eval(t_max, &end, &f_max, &df_max);
        if (f_max > 0.0) return false;  // still above the ground at t_max
        hi = t_max;
        hi_below = true;
      }
      next = 0.5 * (lo + hi);
    }
    if (hi - lo < 1e-7) break;
    t = next;
  }
  if (!hi_below) return false;
  *t_hit = t;
  return true;
}

bool ImageScene::IntersectBoxes(const Eigen::Vector3d& d, double t_max,
                                BoxHit* hit) const {
  const Eigen::Vector2d dh(d.x(), d.y());
  const double horizontal = dh.norm();
  if (horizontal < 1e-9) return false;
  hit->t = t_max;
  const double a = PseudoAngle(dh.dot(back_x_), dh.dot(back_y_));
  const int bin = std::clamp(static_cast<int>(a / 4.0 * kBins), 0, kBins - 1);
  bool found = false;
  for (int ref : bins_[bin]) {
    if (box_distance_[ref] > hit->t * horizontal) break;
    const VerticalBox& box = *boxes_[ref].box;
    const Eigen::Vector2d axis_v = box.axis_v();
    const Eigen::Vector2d o = C_.head<2>() - box.centre;
    const double ou = o.dot(box.axis_u), ov = o.dot(axis_v);
    const double du = dh.dot(box.axis_u), dv = dh.dot(axis_v);
    double t_in = -kInf, t_out = kInf;
    int face = -1;
    auto slab = [&](double origin, double dir, double half, int face_neg) {
      if (std::abs(dir) < 1e-12) return std::abs(origin) <= half;
      double t1 = (-half - origin) / dir, t2 = (half - origin) / dir;
      int f1 = face_neg, f2 = face_neg + 1;
      if (t1 > t2) {
        std::swap(t1, t2);
        std::swap(f1, f2);
      }
      if (t1 > t_in) {
        t_in = t1;
        face = f1;
      }
      t_out = std::min(t_out, t2);
      return true;
    };
    if (!slab(ou, du, box.half_u, 0) || !slab(ov, dv, box.half_v, 2)) continue;
    if (t_in > t_out || t_out <= 0.0 || t_in <= 0.0) continue;
    double t = t_in;
    const double z_in = C_.z() + t_in * d.z();
    if (z_in > box.z1) {
      if (d.z() >= 0.0) continue;
      t = (box.z1 - C_.z()) / d.z();
      if (t > t_out) continue;
      face = 4;
    } else if (z_in < box.z0) {
      continue;
    }
    if (t < hit->t) {
      hit->t = t;
      hit->ref = ref;
      hit->face = face;
      found = true;
    }
  }
  if (found) {
    hit->point = C_ + hit->t * d;
  } else {
    hit->t = kInf;
  }
  return found;
}

float ImageScene::Fog(float value, double t) const {
  // Haze: a rational stand-in for 1 - exp(-t / kFogDistanceM).
  const float f = static_cast<float>(t / (t + kFogDistanceM));
  return value * (1.0f - f) + kHazeTone * f;
}

Sample ImageScene::Trace(double xn, double yn, GroundHint* ground_hint) const {
  Eigen::Vector3d d = R_enu_cam_ * Eigen::Vector3d(xn, yn, 1.0);
  d.normalize();
  double t_ground = kInf;
  GroundPoint g;
  const bool has_ground = IntersectGround(d, settings_.max_ground_range_m,
                                          ground_hint, &t_ground, &g);
  BoxHit box;
  // Paint can lie a few millimetres under the surface: look for boxes a
  // little beyond the ground hit.
  const bool has_box =
      IntersectBoxes(d, has_ground ? t_ground + 0.05 : kInf, &box);
  if (has_ground && (!has_box || t_ground < box.t)) {
    return ShadeGround(d, t_ground, g, has_box ? box.t : kInf);
  }
  if (has_box) return ShadeBox(d, box);
  if (d.z() < 0.0) return {Fog(0.9f * kAsphaltTone, 300.0), Key(kFarGround, 0)};
  return ShadeSky(d);
}

Sample ImageScene::ShadeGround(const Eigen::Vector3d& d, double t,
                               const GroundPoint& g, double t_box) const {
  Eigen::Vector3d p = C_ + t * d;
  const double grazing = std::max(0.03, -d.z());
  const double footprint = t / focal_px_ / grazing;
  const uint64_t salt = world_.texture_salt;
  const double abs_l = std::abs(g.l);
  float value;
  uint32_t key;
  if (abs_l <= half_width_ - 0.2) {
    value = kAsphaltTone * AsphaltTexture(p.x(), p.y(), footprint, salt);
    key = Key(kAsphalt, 0);
  } else if (abs_l <= half_width_) {
    value = 0.92f * kAsphaltTone *
            AsphaltTexture(p.x(), p.y(), footprint, salt + 11);
    key = Key(kGutter, 0);
  } else if (abs_l <= half_width_ + 0.15) {
    value = 150.0f * AsphaltTexture(p.x(), p.y(), 4.0 * footprint, salt + 21);
    key = Key(kKerb, 0);
  } else {
    const double ts = g.s / 0.3;
    const double tl = (abs_l - half_width_ - 0.15) / 0.3;
    const int64_t is = static_cast<int64_t>(std::floor(ts));
    const int64_t il = static_cast<int64_t>(std::floor(tl));
    const float tile =
        118.0f +
        24.0f * HashToUnit(HashLattice(is, il * (g.l < 0 ? -1 : 1), salt + 31));
    const bool joint = (ts - is) < 0.04 || (tl - il) < 0.04;
    value = tile * (joint && footprint < 0.02 ? 0.78f : 1.0f) *
            AsphaltTexture(p.x(), p.y(), 2.0 * footprint, salt + 41);
    key = Key(kSidewalk, 0);
  }
  // Lines along the road and stop lines.
  bool near_line = false;
  for (double offset : line_offsets_) {
    near_line |= std::abs(g.l - offset) <= line_half_width_;
  }
  for (int i : lines_) {
    if (!near_line) break;
    const LinePiece& line = world_.lines[i];
    if (std::abs(g.l - line.l_m) <= 0.5 * line.width_m && g.s >= line.s0 &&
        g.s <= line.s1) {
      const float alpha =
          PaintAlpha(p.x(), p.y(), 0.8f * world_.paint_wear, salt + 51);
      value = value * (1.0f - alpha) +
              alpha * PaintTone(p.x(), p.y(), footprint, salt);
      key = Key(kLinePaint, i);
    }
  }
  for (int i : stop_lines_) {
    const StopLine& line = world_.stop_lines[i];
    if (std::abs(g.s - line.s_m) <= 0.5 * line.width_m && g.l >= line.l0 &&
        g.l <= line.l1) {
      const float alpha =
          PaintAlpha(p.x(), p.y(), 0.8f * world_.paint_wear, salt + 53);
      value = value * (1.0f - alpha) +
              alpha * PaintTone(p.x(), p.y(), footprint, salt);
      key = Key(kStopLinePaint, i);
    }
  }
  float light = 1.0f;
  float stain = 1.0f;
  if (g.cell >= 0) {
    for (int k = cell_start_[g.cell]; k < cell_start_[g.cell + 1]; ++k) {
      const uint32_t item = cell_items_[k];
      const uint32_t type = item >> 24;
      const int index = static_cast<int>(item & 0xffffff);
      if (type == kItemCrossing) {
        const Crossing& c = world_.crossings[index];
        const Eigen::Vector2d rel = p.head<2>() - c.origin_xy;
        const double o = rel.dot(c.n);
        const int nearest = static_cast<int>(std::floor((o - c.first_offset_m) /
                                                        c.band_period_m)) +
                            1;
        for (int b = std::max(1, nearest - 1);
             b <= std::min(c.num_street_bands, nearest + 1); ++b) {
          const Band& band = world_.bands[first_band_[index] + b - 1];
          if (o < band.o0 - 0.3 || o > band.o1 + 0.3) continue;
          // Exact intersection with the band's planar quad.
          const double denominator = band.plane_normal.dot(d);
          if (std::abs(denominator) < 1e-9) continue;
          const double tp =
              (band.plane_offset - band.plane_normal.dot(C_)) / denominator;
          if (tp <= 0.0 || tp >= t_box) continue;
          const Eigen::Vector3d q = C_ + tp * d;
          const Eigen::Vector2d rq = q.head<2>() - c.origin_xy;
          const double oq = rq.dot(c.n);
          const double aq = rq.dot(c.t) - oq * c.tan_skew;
          if (oq < band.o0 || oq > band.o1 ||
              std::abs(aq) > 0.5 * c.band_length_m) {
            continue;
          }
          float alpha = PaintAlpha(q.x(), q.y(), world_.paint_wear, band.salt);
          if (band.patch_radius_m > 0.0) {
            const double r = (Eigen::Vector2d(aq, oq) - band.patch_ao).norm();
            const double edge =
                band.patch_radius_m *
                (0.7 +
                 0.6 * ValueNoise(q.x() / 0.15, q.y() / 0.15, band.salt + 3));
            alpha *= static_cast<float>(
                1.0 - 0.88 * (1.0 - SmoothStep(edge - 0.04, edge, r)));
          }
          const float under =
              kAsphaltTone * AsphaltTexture(q.x(), q.y(), footprint, salt);
          value = under * (1.0f - alpha) +
                  alpha * PaintTone(q.x(), q.y(), footprint, band.salt);
          key = Key(kBandPaint, first_band_[index] + b);
          p = q;
          break;
        }
      } else if (type == kItemManhole) {
        const Manhole& m = world_.manholes[index];
        const Eigen::Vector2d rel = p.head<2>() - m.centre;
        const double r = m.square
                             ? std::max(std::abs(rel.x()), std::abs(rel.y()))
                             : rel.norm();
        if (r <= m.radius_m) {
          const bool rim = r > m.radius_m - 0.05;
          const int64_t gx = static_cast<int64_t>(std::floor(rel.x() / 0.06));
          const int64_t gy = static_cast<int64_t>(std::floor(rel.y() / 0.06));
          const float pattern = ((gx + gy) & 1) ? 1.0f : 0.85f;
          value = (rim ? 95.0f : 62.0f * (footprint < 0.03 ? pattern : 0.93f)) *
                  AsphaltTexture(p.x(), p.y(), footprint, salt + 61);
          key = Key(kManhole, index * 2 + (rim ? 1 : 0));
        }
      } else if (type == kItemStain) {
        const Stain& st = world_.stains[index];
        const Eigen::Vector2d rel = p.head<2>() - st.centre;
        const double r = rel.norm() / st.radius_m;
        if (r < 1.4) {
          const double shape =
              0.75 + 0.5 * ValueNoise(p.x() / 0.25, p.y() / 0.25, st.salt);
          const double amount = 1.0 - SmoothStep(0.5 * shape, shape, r);
          stain *= static_cast<float>(1.0 - amount * (1.0 - st.darkness));
        }
      } else if (type == kItemShadow) {
        const Shadow& shadow = world_.shadows[index];
        const double inside = shadow.InsideDistance(p.head<2>());
        const double amount = SmoothStep(-0.05, 0.05, inside);
        light = std::min(
            light, static_cast<float>(1.0 - amount * (1.0 - shadow.factor)));
      }
    }
  }
  if (light < 0.8f) key |= kShadowBit;
  return {Fog(value * stain * light, t), key};
}

Sample ImageScene::ShadeBox(const Eigen::Vector3d& d, const BoxHit& hit) const {
  const BoxRef& ref = boxes_[hit.ref];
  const VerticalBox& box = *ref.box;
  const Eigen::Vector3d& p = hit.point;
  const Eigen::Vector2d rel = p.head<2>() - box.centre;
  const double u = rel.dot(box.axis_u);
  const double v = rel.dot(box.axis_v());
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  if (hit.face < 4) {
    const Eigen::Vector2d axis = hit.face < 2 ? box.axis_u : box.axis_v();
    const double sign = (hit.face % 2 == 0) ? -1.0 : 1.0;
    normal = Eigen::Vector3d(sign * axis.x(), sign * axis.y(), 0.0);
  }
  const float light = static_cast<float>(
      0.55 + 0.55 * std::max(0.0, normal.dot(world_.sun_enu)));
  const double distance = hit.t;
  const double footprint =
      distance / focal_px_ / std::max(0.1, std::abs(normal.dot(d)));
  const uint64_t id = static_cast<uint64_t>(ref.index) * 8 + hit.face;
  float value;
  uint32_t key;
  if (!ref.is_vehicle) {
    const Building& b = world_.buildings[ref.index];
    const bool front = hit.face == (b.front_side > 0 ? 3 : 2);
    const double h = p.z() - (box.z0 + 0.5);
    const double wall_noise =
        0.93 + 0.14 * ValueNoise(u / 0.7, p.z() / 0.7, b.salt) +
        (footprint < 0.02
             ? 0.04 * (ValueNoise(u / 0.05, p.z() / 0.05, b.salt + 1) - 0.5)
             : 0.0);
    value = static_cast<float>(b.wall_tone * wall_noise);
    key = Key(kWall, id);
    if (front && hit.face < 4) {
      // Face coordinate from the face's start.
      const double along = u + box.half_u;
      const double face_length = 2.0 * box.half_u;
      if (h > box.z1 - box.z0 - 1.0) {
        value *= 0.8f;  // cornice
        key = Key(kWall, id + 4);
      } else if (h < b.ground_floor_height_m) {
        if (b.shop_front) {
          const double period = 2.0 * b.window_period_m;
          const double col = std::floor((along - 0.5) / period);
          const double x = along - 0.5 - col * period;
          if (col >= 0 && along < face_length - 0.5 && x < 0.75 * period &&
              h > 0.4 && h < b.ground_floor_height_m - 0.6) {
            value = static_cast<float>(
                b.window_tone *
                (0.8 + 0.5 * HashToUnit(HashLattice(static_cast<int64_t>(col),
                                                    -1, b.salt))));
            key = Key(kWindow, id * 64 + static_cast<uint64_t>(col) % 64);
          }
        }
      } else {
        const double storey =
            std::floor((h - b.ground_floor_height_m) / b.floor_height_m);
        const double hv =
            h - b.ground_floor_height_m - storey * b.floor_height_m;
        const double col =
            std::floor((along - b.window_offset_m) / b.window_period_m);
        const double x = along - b.window_offset_m - col * b.window_period_m;
        if (col >= 0 && along < face_length - 0.3 && x < b.window_width_m &&
            hv > b.sill_height_m && hv < b.sill_height_m + b.window_height_m) {
          const double frame = 0.07;
          const bool is_frame =
              x < frame || x > b.window_width_m - frame ||
              hv < b.sill_height_m + frame ||
              hv > b.sill_height_m + b.window_height_m - frame;
          const uint64_t window = (static_cast<uint64_t>(storey) * 97 +
                                   static_cast<uint64_t>(col)) *
                                      2 +
                                  (is_frame ? 1 : 0);
          if (is_frame) {
            value = 205.0f;
          } else {
            // Dark glass with a sky reflection rising with height, and
            // curtains varying per window.
            const float shade =
                0.75f + 0.6f * HashToUnit(HashLattice(
                                   static_cast<int64_t>(col),
                                   static_cast<int64_t>(storey), b.salt + 2));
            value = static_cast<float>(
                b.window_tone * shade *
                (1.0 + 0.3 * (hv - b.sill_height_m) / b.window_height_m));
          }
          key = Key(kWindow, id * 4096 + window);
        }
      }
    }
  } else {
    const ParkedVehicle& car = world_.vehicles[ref.index];
    const double height = box.z1 - box.z0;
    const double h = p.z() - box.z0;
    value = car.body_tone;
    key = Key(kVehicle, id * 8);
    if (hit.face == 4) {
      value *= 1.05f;
    } else if (h < 0.25) {
      value = 22.0f;
      key = Key(kVehicle, id * 8 + 1);
    } else {
      const bool side = hit.face >= 2;
      const double across = side ? u : v;
      const double half = side ? box.half_u : box.half_v;
      const double wheel_x = std::abs(std::abs(across) - (half - 0.8));
      const double wheel_r = std::hypot(wheel_x, h - 0.33);
      if (side && wheel_r < 0.33) {
        value = wheel_r < 0.18 ? 95.0f : 25.0f;
        key = Key(kVehicle, id * 8 + (wheel_r < 0.18 ? 2 : 3));
      } else if (h > 0.6 * height && h < 0.92 * height &&
                 std::abs(across) < half - (side ? 0.5 : 0.15)) {
        value = 38.0f + 25.0f * static_cast<float>((h - 0.6 * height) /
                                                   (0.32 * height));
        key = Key(kVehicle, id * 8 + 4);
      } else if (!side && h > 0.55 * height - 0.2 && h < 0.55 * height &&
                 std::abs(std::abs(across) - (half - 0.25)) < 0.15) {
        value = hit.face == 1 ? 220.0f : 90.0f;  // headlights, tail lights
        key = Key(kVehicle, id * 8 + 5);
      }
    }
  }
  return {Fog(value * light, distance), key};
}

Sample ImageScene::ShadeSky(const Eigen::Vector3d& d) const {
  const double elevation = std::asin(std::clamp(d.z(), -1.0, 1.0));
  float value =
      static_cast<float>(236.0 - 40.0 * std::min(1.0, elevation / 0.9));
  if (elevation > 0.0) {
    const double azimuth = std::atan2(d.y(), d.x());
    const float cloud =
        ValueNoise(azimuth * 5.0, elevation * 12.0, world_.texture_salt + 71) *
            0.7f +
        0.3f * ValueNoise(azimuth * 15.0, elevation * 36.0,
                          world_.texture_salt + 72);
    value += 14.0f * static_cast<float>(SmoothStep(0.45, 0.8, cloud));
  }
  return {std::min(value, 250.0f), Key(kSky, 0)};
}

// Separable Gaussian blur with clamped borders.
void GaussianBlur(double sigma, int width, int height,
                  std::vector<float>* image) {
  if (sigma <= 0.0) return;
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<float> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int k = -radius; k <= radius; ++k) {
    kernel[k + radius] =
        static_cast<float>(std::exp(-0.5 * k * k / (sigma * sigma)));
    sum += kernel[k + radius];
  }
  for (float& k : kernel) k = static_cast<float>(k / sum);
  std::vector<float> tmp(image->size());
  const std::vector<float>& in = *image;
  for (int y = 0; y < height; ++y) {
    const float* row = &in[static_cast<size_t>(y) * width];
    float* out = &tmp[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      float acc = 0.0f;
      for (int k = -radius; k <= radius; ++k) {
        acc += kernel[k + radius] * row[std::clamp(x + k, 0, width - 1)];
      }
      out[x] = acc;
    }
  }
  for (int y = 0; y < height; ++y) {
    float* out = &(*image)[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x) {
      float acc = 0.0f;
      for (int k = -radius; k <= radius; ++k) {
        acc +=
            kernel[k + radius] *
            tmp[static_cast<size_t>(std::clamp(y + k, 0, height - 1)) * width +
                x];
      }
      out[x] = acc;
    }
  }
}

}  // namespace

RayTable::RayTable(const Camera& camera)
    : width_(camera.width()), height_(camera.height()) {
  corners_.resize(2 * static_cast<size_t>(width_ + 1) * (height_ + 1));
  Eigen::Vector2d xy;
  for (int j = 0; j <= height_; ++j) {
    for (int i = 0; i <= width_; ++i) {
      CHECK(
          camera.UnprojectToNormalized(Eigen::Vector2d(i - 0.5, j - 0.5), &xy))
          << "camera " << camera.name() << ": distortion not invertible at ("
          << i - 0.5 << ", " << j - 0.5 << ")";
      float* c = &corners_[2 * (static_cast<size_t>(j) * (width_ + 1) + i)];
      c[0] = static_cast<float>(xy.x());
      c[1] = static_cast<float>(xy.y());
    }
  }
}

RenderSettings RenderSettings::FromOptions(const SimulationOptions& options) {
  RenderSettings s;
  s.supersampling = options.supersampling;
  s.blur_sigma_px = options.blur_sigma_px;
  s.vignetting = options.vignetting;
  s.gain_variation = options.gain_variation;
  s.noise_sigma = options.noise_sigma;
  s.shot_noise = options.shot_noise;
  s.pixel_depth = options.pixel_depth;
  return s;
}

Renderer::Renderer(const World& world, const RenderSettings& settings)
    : world_(world), settings_(settings) {
  first_band_of_crossing_.assign(world.crossings.size(), -1);
  for (int i = static_cast<int>(world.bands.size()) - 1; i >= 0; --i) {
    first_band_of_crossing_[world.bands[i].crossing] = i;
  }
}

cv::Mat Renderer::RenderRadiance(const Camera& camera, const RayTable& rays,
                                 const Eigen::Isometry3d& T_enu_cam,
                                 double s_hint, RenderStats* stats) const {
  const double start = ThreadCpuSeconds();
  const int width = camera.width(), height = camera.height();
  CHECK_EQ(rays.width(), width);
  CHECK_EQ(rays.height(), height);
  const ImageScene scene(world_, settings_, first_band_of_crossing_, T_enu_cam,
                         s_hint, camera.fx());
  cv::Mat radiance(height, width, CV_32FC1);
  std::vector<Sample> upper(width + 1), lower(width + 1);
  std::vector<GroundHint> hint_upper(width + 1), hint_lower(width + 1);
  int64_t ray_count = 0, supersampled = 0;
  auto trace_corner_row = [&](int j, std::vector<Sample>* row,
                              std::vector<GroundHint>* hints) {
    GroundHint hint = (*hints)[0];
    for (int i = 0; i <= width; ++i) {
      const float* xy = rays.Corner(i, j);
      if ((*hints)[i].valid) hint = (*hints)[i];
      (*row)[i] = scene.Trace(xy[0], xy[1], &hint);
      (*hints)[i] = hint;
    }
    ray_count += width + 1;
  };
  trace_corner_row(0, &upper, &hint_upper);
  const int n = std::max(1, settings_.supersampling);
  for (int j = 0; j < height; ++j) {
    hint_lower = hint_upper;
    trace_corner_row(j + 1, &lower, &hint_lower);
    float* out = radiance.ptr<float>(j);
    for (int i = 0; i < width; ++i) {
      const Sample& c00 = upper[i];
      const Sample& c10 = upper[i + 1];
      const Sample& c01 = lower[i];
      const Sample& c11 = lower[i + 1];
      if (c00.key == c10.key && c00.key == c01.key && c00.key == c11.key) {
        out[i] = 0.25f * (c00.value + c10.value + c01.value + c11.value);
        continue;
      }
      GroundHint hint = hint_upper[i].valid ? hint_upper[i] : hint_lower[i];
      // Supersample n x n, rays bilinear between the pixel's corners.
      ++supersampled;
      const float* a = rays.Corner(i, j);
      const float* b = rays.Corner(i + 1, j);
      const float* c = rays.Corner(i, j + 1);
      const float* d = rays.Corner(i + 1, j + 1);
      double sum = 0.0;
      GroundHint sub_hint = hint;
      for (int sy = 0; sy < n; ++sy) {
        const double v = (sy + 0.5) / n;
        for (int sx = 0; sx < n; ++sx) {
          const double u = (sx + 0.5) / n;
          const double x = (1 - v) * ((1 - u) * a[0] + u * b[0]) +
                           v * ((1 - u) * c[0] + u * d[0]);
          const double y = (1 - v) * ((1 - u) * a[1] + u * b[1]) +
                           v * ((1 - u) * c[1] + u * d[1]);
          sum += scene.Trace(x, y, &sub_hint).value;
        }
      }
      ray_count += n * n;
      out[i] = static_cast<float>(sum / (n * n));
    }
    std::swap(upper, lower);
    std::swap(hint_upper, hint_lower);
  }
  if (stats != nullptr) {
    stats->rays = ray_count;
    stats->supersampled_pixels = supersampled;
    stats->seconds = ThreadCpuSeconds() - start;
  }
  return radiance;
}

cv::Mat Renderer::Render(const Camera& camera, const RayTable& rays,
                         const Eigen::Isometry3d& T_enu_cam, double s_hint,
                         uint64_t image_seed, RenderStats* stats) const {
  const double start = ThreadCpuSeconds();
  cv::Mat radiance = RenderRadiance(camera, rays, T_enu_cam, s_hint, stats);
  const int width = camera.width(), height = camera.height();
  std::vector<float> pixels(radiance.begin<float>(), radiance.end<float>());
  GaussianBlur(settings_.blur_sigma_px, width, height, &pixels);
  const double gain =
      1.0 + settings_.gain_variation *
                (2.0 * HashToUnit(Mix64(image_seed + 0x6a09e667)) - 1.0);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const double corner2 = cx * cx + cy * cy;
  const bool deep = settings_.pixel_depth == PixelDepth::kUint16;
  cv::Mat image(height, width, deep ? CV_16UC1 : CV_8UC1);
  const double read2 = settings_.noise_sigma * settings_.noise_sigma;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t index = static_cast<size_t>(y) * width + x;
      const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / corner2;
      double value = pixels[index] * gain * (1.0 - settings_.vignetting * r2);
      const double sigma =
          std::sqrt(read2 + settings_.shot_noise * std::max(0.0, value));
      value += sigma * HashGaussian(
                           Mix64(image_seed ^ (index * 0x9e3779b97f4a7c15ULL)));
      if (deep) {
        image.at<uint16_t>(y, x) = static_cast<uint16_t>(
            std::clamp(std::lround(value * 257.0), 0L, 65535L));
      } else {
        image.at<uint8_t>(y, x) =
            static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
  if (stats != nullptr) stats->seconds = ThreadCpuSeconds() - start;
  return image;
}

}  // namespace zebrageo::sim
