// ImageScene: the part of the street one image can see, indexed for ray
// casting (a lookup grid from (x, y) to road coordinates, the marks per
// cell, the boxes by direction), and the intersection of a ray with the
// ground and with the boxes.
#include "simulator/image_scene.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "simulator/noise.h"

namespace zebrageo::sim::render_internal {
namespace {

// Monotonic stand-in for the angle of (x, y), in [0, 4).
inline double PseudoAngle(double x, double y) {
  const double p = x / (std::abs(x) + std::abs(y) + 1e-300);
  return y < 0.0 ? 3.0 + p : 1.0 - p;
}
}  // namespace

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
    // Its painted bands follow each other in world_.bands (an island's
    // places, issue 52, are not among them); a ladder's bars lie beside.
    for (int i = first_band_[c]; i < static_cast<int>(world_.bands.size()) &&
                                 world_.bands[i].crossing == c;
         ++i) {
      box.extend(box_of(world_.bands[i].corners,
                        0.3 + crossing.ladder_bar_width_m));
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
  for (int i = 0; i < static_cast<int>(world_.beside_marks.size()); ++i) {
    const Eigen::AlignedBox2d box =
        box_of(world_.beside_marks[i].polygon, 0.05);
    if (view.intersects(box)) items.push_back({(kItemBeside << 24) | i, box});
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
  g->side_street = -1;
  if (std::abs(g->l) > half_width_ && !world_.side_streets.empty()) {
    // A side street: level across, at the kerb line's height.
    g->side_street = SideStreetAt(world_, Eigen::Vector2d(x, y), g->l);
    if (g->side_street >= 0) {
      cross = road_.CrossSection(g->l < 0.0 ? -half_width_ : half_width_);
      slope = 0.0;
    }
  }
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

}  // namespace zebrageo::sim::render_internal
