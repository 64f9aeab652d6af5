// The shading of a ray's hit: the ground (asphalt, paint worn by noise,
// kerbs and sidewalks, manholes, stains, shadows), the boxes (facades with
// windows, vehicles) and the sky.
#include <algorithm>
#include <cmath>

#include "simulator/image_scene.h"
#include "simulator/noise.h"

namespace zebrageo::sim::render_internal {
namespace {

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

// A shop window of the ground floor at `along` the front face (of
// `face_length`), height h over the pavement; leaves *value, *key as they
// are elsewhere.
void ShadeShopWindow(const Building& b, double along, double face_length,
                     double h, uint64_t id, float* value, uint32_t* key) {
  const double period = 2.0 * b.window_period_m;
  const double col = std::floor((along - 0.5) / period);
  const double x = along - 0.5 - col * period;
  if (col >= 0 && along < face_length - 0.5 && x < 0.75 * period && h > 0.4 &&
      h < b.ground_floor_height_m - 0.6) {
    *value = static_cast<float>(
        b.window_tone *
        (0.8 +
         0.5 * HashToUnit(HashLattice(static_cast<int64_t>(col), -1, b.salt))));
    *key = Key(kWindow, id * 64 + static_cast<uint64_t>(col) % 64);
  }
}

// A window of an upper storey (frame or glass) at `along` the front face
// (of `face_length`), height h over the pavement; leaves *value, *key as
// they are between windows.
void ShadeStoreyWindow(const Building& b, double along, double face_length,
                       double h, uint64_t id, float* value, uint32_t* key) {
  const double storey =
      std::floor((h - b.ground_floor_height_m) / b.floor_height_m);
  const double hv = h - b.ground_floor_height_m - storey * b.floor_height_m;
  const double col =
      std::floor((along - b.window_offset_m) / b.window_period_m);
  const double x = along - b.window_offset_m - col * b.window_period_m;
  if (col >= 0 && along < face_length - 0.3 && x < b.window_width_m &&
      hv > b.sill_height_m && hv < b.sill_height_m + b.window_height_m) {
    const double frame = 0.07;
    const bool is_frame = x < frame || x > b.window_width_m - frame ||
                          hv < b.sill_height_m + frame ||
                          hv > b.sill_height_m + b.window_height_m - frame;
    const uint64_t window =
        (static_cast<uint64_t>(storey) * 97 + static_cast<uint64_t>(col)) * 2 +
        (is_frame ? 1 : 0);
    if (is_frame) {
      *value = 205.0f;
    } else {
      // Dark glass with a sky reflection rising with height, and
      // curtains varying per window.
      const float shade =
          0.75f + 0.6f * HashToUnit(HashLattice(static_cast<int64_t>(col),
                                                static_cast<int64_t>(storey),
                                                b.salt + 2));
      *value = static_cast<float>(
          b.window_tone * shade *
          (1.0 + 0.3 * (hv - b.sill_height_m) / b.window_height_m));
    }
    *key = Key(kWindow, id * 4096 + window);
  }
}

// A building's wall at p (u along the box's axis_u): noisy plaster, and on
// its front face a cornice, shop windows and storeys of windows.
void ShadeBuilding(const Building& b, const VerticalBox& box,
                   const Eigen::Vector3d& p, double u, int face,
                   double footprint, uint64_t id, float* value, uint32_t* key) {
  const bool front = face == (b.front_side > 0 ? 3 : 2);
  const double h = p.z() - (box.z0 + 0.5);
  const double wall_noise =
      0.93 + 0.14 * ValueNoise(u / 0.7, p.z() / 0.7, b.salt) +
      (footprint < 0.02
           ? 0.04 * (ValueNoise(u / 0.05, p.z() / 0.05, b.salt + 1) - 0.5)
           : 0.0);
  *value = static_cast<float>(b.wall_tone * wall_noise);
  *key = Key(kWall, id);
  if (!front || face >= 4) return;
  // Face coordinate from the face's start.
  const double along = u + box.half_u;
  const double face_length = 2.0 * box.half_u;
  if (h > box.z1 - box.z0 - 1.0) {
    *value *= 0.8f;  // cornice
    *key = Key(kWall, id + 4);
  } else if (h < b.ground_floor_height_m) {
    if (b.shop_front) {
      ShadeShopWindow(b, along, face_length, h, id, value, key);
    }
  } else {
    ShadeStoreyWindow(b, along, face_length, h, id, value, key);
  }
}

// A truck's body at p (u, v along the box's axes): ribbed, lettered and
// dirty box sides (the texture a stereo pair measures on real trucks), a
// darker cab at the -u end (it faces the survey vehicle) with a windscreen,
// wheels and the dark gap under the body.
void ShadeTruck(const ParkedVehicle& truck, const VerticalBox& box,
                const Eigen::Vector3d& p, double u, double v, int face,
                uint64_t id, float* value, uint32_t* key) {
  const double height = box.z1 - box.z0;
  const double h = p.z() - box.z0;
  const bool side = face >= 2;
  const double across = side ? u : v;  // along the face
  *key = Key(kVehicle, id * 8);
  // Grime and print at a few centimetres: the fine texture of a real body.
  const float grain =
      0.92f + 0.16f * ValueNoise(across / 0.05, h / 0.05, truck.salt + 11);
  if (h < 0.5 && face != 4) {
    // Bumper, mudguards, axles and tyres: dark, with their edges.
    const double wheel = std::abs(std::abs(across) -
                                  (side ? box.half_u - 1.2 : box.half_v - 0.4));
    const bool tyre = side && std::hypot(wheel, h - 0.5) < 0.5;
    const bool bumper =
        h > 0.3 && std::fmod(std::abs(across) + 10.0, 0.7) < 0.5;
    *value = (tyre ? 28.0f : bumper ? 60.0f : 18.0f) * grain;
    *key = Key(kVehicle, id * 8 + (tyre ? 3 : 1));
    return;
  }
  const bool cab = u < -box.half_u + 2.2;
  const float dirt =
      0.82f + 0.3f * ValueNoise(across / 0.6, h / 0.6, truck.salt + face);
  if (cab) {
    *value = 0.7f * truck.body_tone * dirt * grain;
    *key = Key(kVehicle, id * 8 + 6);
    if (h > 0.55 * height && h < 0.85 * height &&
        (face == 0 || (side && u < -box.half_u + 1.6))) {
      *value = 45.0f * grain;  // windscreen, side window
      *key = Key(kVehicle, id * 8 + 4);
    }
    return;
  }
  // Vertical ribs every 0.3 m, lettering: dark blocks over the sides, a
  // panel seam near the top.
  const double rib = std::fmod(std::abs(across) + 10.0, 0.3);
  float tone = truck.body_tone * dirt * grain * (rib < 0.04 ? 0.78f : 1.0f);
  if (h > 0.7 && h < height - 0.4) {
    const int64_t gx = static_cast<int64_t>(std::floor(across / 0.18));
    const int64_t gy = static_cast<int64_t>(std::floor(h / 0.25));
    if (HashToUnit(HashLattice(gx, gy, truck.salt + 9)) < 0.35f) {
      tone = 40.0f + 30.0f * HashToUnit(HashLattice(gx, gy, truck.salt + 10));
      *key = Key(kVehicle, id * 8 + 7);
    }
  }
  if (h > height - 0.25) tone *= 0.85f;
  *value = tone;
}

// A parked vehicle's body at p (u, v along the box's axes): roof, tyres
// and wheels, windows, head and tail lights.
void ShadeVehicle(const ParkedVehicle& car, const VerticalBox& box,
                  const Eigen::Vector3d& p, double u, double v, int face,
                  uint64_t id, float* value, uint32_t* key) {
  const double height = box.z1 - box.z0;
  const double h = p.z() - box.z0;
  *value = car.body_tone;
  if (car.truck) {
    ShadeTruck(car, box, p, u, v, face, id, value, key);
    return;
  }
  *key = Key(kVehicle, id * 8);
  if (face == 4) {
    *value *= 1.05f;
    return;
  }
  if (h < 0.25) {
    *value = 22.0f;
    *key = Key(kVehicle, id * 8 + 1);
    return;
  }
  const bool side = face >= 2;
  const double across = side ? u : v;
  const double half = side ? box.half_u : box.half_v;
  const double wheel_x = std::abs(std::abs(across) - (half - 0.8));
  const double wheel_r = std::hypot(wheel_x, h - 0.33);
  if (side && wheel_r < 0.33) {
    *value = wheel_r < 0.18 ? 95.0f : 25.0f;
    *key = Key(kVehicle, id * 8 + (wheel_r < 0.18 ? 2 : 3));
  } else if (h > 0.6 * height && h < 0.92 * height &&
             std::abs(across) < half - (side ? 0.5 : 0.15)) {
    *value = 38.0f +
             25.0f * static_cast<float>((h - 0.6 * height) / (0.32 * height));
    *key = Key(kVehicle, id * 8 + 4);
  } else if (!side && h > 0.55 * height - 0.2 && h < 0.55 * height &&
             std::abs(std::abs(across) - (half - 0.25)) < 0.15) {
    *value = face == 1 ? 220.0f : 90.0f;  // headlights, tail lights
    *key = Key(kVehicle, id * 8 + 5);
  }
}

// How many of an island's places (issue 52) come before design band b of
// crossing c: world.bands holds the painted bands only, without them.
int IslandPlacesBefore(const Crossing& c, int b) {
  return c.island_bands.empty()
             ? 0
             : std::clamp(b - c.island_bands.front(), 0,
                          static_cast<int>(c.island_bands.size()));
}

}  // namespace

// The paint of the bands of crossing `index` near the ground point *p: the
// ray's exact hit on a band's planar quad (before t_box) replaces *p, *value
// and *key.
void ImageScene::ShadeBandPaint(const Eigen::Vector3d& d, double t_box,
                                double footprint, int index, Eigen::Vector3d* p,
                                float* value, uint32_t* key) const {
  const uint64_t salt = world_.texture_salt;
  const Crossing& c = world_.crossings[index];
  const Eigen::Vector2d rel = p->head<2>() - c.origin_xy;
  const double o = rel.dot(c.n);
  const int nearest =
      static_cast<int>(std::floor((o - c.first_offset_m) / c.band_period_m)) +
      1;
  for (int b = std::max(1, nearest - 1);
       b <= std::min(c.num_street_bands, nearest + 1); ++b) {
    if (IsIslandBand(c, b)) continue;
    // World_.bands holds the painted bands in order, without the island's
    // places (issue 52).
    const int before_island = IslandPlacesBefore(c, b);
    const int band_index = first_band_[index] + b - 1 - before_island;
    const Band& band = world_.bands[band_index];
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
    if (oq < band.o0 || oq > band.o1 || std::abs(aq) > 0.5 * c.band_length_m) {
      continue;
    }
    float alpha = PaintAlpha(q.x(), q.y(), world_.paint_wear, band.salt);
    if (band.patch_radius_m > 0.0) {
      const double r = (Eigen::Vector2d(aq, oq) - band.patch_ao).norm();
      const double edge =
          band.patch_radius_m *
          (0.7 + 0.6 * ValueNoise(q.x() / 0.15, q.y() / 0.15, band.salt + 3));
      alpha *= static_cast<float>(
          1.0 - 0.88 * (1.0 - SmoothStep(edge - 0.04, edge, r)));
    }
    const float under =
        kAsphaltTone * AsphaltTexture(q.x(), q.y(), footprint, salt);
    *value = under * (1.0f - alpha) +
             alpha * PaintTone(q.x(), q.y(), footprint, band.salt);
    *key = Key(kBandPaint, band_index + 1);
    *p = q;
    return;
  }
  if (c.ladder_bar_width_m > 0.0) {
    ShadeLadderBar(d, t_box, footprint, index, nearest, p, value, key);
  }
}

// The paint of crossing `index`'s ladder bars (issue 52) near *p, on the
// plane of the band nearest (`nearest`, clamped): the bars lie on the road
// between the bands' planes, within a millimetre of either.
void ImageScene::ShadeLadderBar(const Eigen::Vector3d& d, double t_box,
                                double footprint, int index, int nearest,
                                Eigen::Vector3d* p, float* value,
                                uint32_t* key) const {
  const Crossing& c = world_.crossings[index];
  // World_.bands holds the painted bands only: an island's places (issue
  // 52) are not among them, so the index counts painted bands.
  const int painted =
      c.num_street_bands - static_cast<int>(c.island_bands.size());
  if (painted <= 0) return;
  const int before_island = IslandPlacesBefore(c, nearest);
  const int b = std::clamp(nearest - before_island, 1, painted);
  const Band& band = world_.bands[first_band_[index] + b - 1];
  const double denominator = band.plane_normal.dot(d);
  if (std::abs(denominator) < 1e-9) return;
  const double tp =
      (band.plane_offset - band.plane_normal.dot(C_)) / denominator;
  if (tp <= 0.0 || tp >= t_box) return;
  const Eigen::Vector3d q = C_ + tp * d;
  const Eigen::Vector2d rq = q.head<2>() - c.origin_xy;
  const double oq = rq.dot(c.n);
  const double aq = rq.dot(c.t) - oq * c.tan_skew;
  if (!InLadderBar(c, oq, aq)) return;
  const float alpha = PaintAlpha(q.x(), q.y(), world_.paint_wear, c.salt);
  const float under = kAsphaltTone * AsphaltTexture(q.x(), q.y(), footprint,
                                                    world_.texture_salt);
  *value = under * (1.0f - alpha) +
           alpha * PaintTone(q.x(), q.y(), footprint, c.salt);
  // One key per bar and band slot: the supersampling sees its edges.
  *key = Key(kBandPaint, first_band_[index] + b - 1);
  *p = q;
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
  double side_kerb = 0.0;  // side street: distance to its nearer kerb
  if (g.side_street >= 0) {
    const SideStreet& street = world_.side_streets[g.side_street];
    side_kerb = 0.5 * street.width_m -
                std::abs((p.head<2>() - street.axis_xy).dot(street.across()));
  }
  if (g.side_street >= 0) {
    value = (side_kerb > 0.2 ? 1.0f : 0.92f) * kAsphaltTone *
            AsphaltTexture(p.x(), p.y(), footprint,
                           side_kerb > 0.2 ? salt : salt + 11);
    key = Key(side_kerb > 0.2 ? kAsphalt : kGutter, 0);
  } else if (abs_l <= half_width_ - 0.2) {
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
        ShadeBandPaint(d, t_box, footprint, index, &p, &value, &key);
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
      } else if (type == kItemBeside) {
        const BesideMark& mark = world_.beside_marks[index];
        if (mark.Contains(p.head<2>())) {
          const float alpha =
              mark.white
                  ? PaintAlpha(p.x(), p.y(), world_.paint_wear, mark.salt)
                  : 0.95f;
          const float tone =
              mark.white ? PaintTone(p.x(), p.y(), footprint, mark.salt)
                         : mark.tone * AsphaltTexture(p.x(), p.y(), footprint,
                                                      salt + 81);
          value = value * (1.0f - alpha) + alpha * tone;
          key = Key(kBesidePaint, index);
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
    ShadeBuilding(world_.buildings[ref.index], box, p, u, hit.face, footprint,
                  id, &value, &key);
  } else {
    ShadeVehicle(world_.vehicles[ref.index], box, p, u, v, hit.face, id, &value,
                 &key);
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

}  // namespace zebrageo::sim::render_internal
