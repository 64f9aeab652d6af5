// Internals of the renderer shared by its files: the materials of a
// sample, and ImageScene, the street as one image sees it (image_scene.cc:
// the scene and its ray intersections; scene_shading.cc: the shading of a
// hit). Not part of the simulator's interface.
#ifndef ZEBRAGEO_SIMULATOR_IMAGE_SCENE_H_
#define ZEBRAGEO_SIMULATOR_IMAGE_SCENE_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <vector>

#include "simulator/renderer.h"
#include "simulator/road.h"
#include "simulator/world.h"

namespace zebrageo::sim::render_internal {

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
  kBesidePaint,
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
  int side_street = -1;  // index into World::side_streets, -1: none
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
  void ShadeBandPaint(const Eigen::Vector3d& d, double t_box, double footprint,
                      int index, Eigen::Vector3d* p, float* value,
                      uint32_t* key) const;
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
  kItemShadow,
  kItemBeside
};

}  // namespace zebrageo::sim::render_internal

#endif  // ZEBRAGEO_SIMULATOR_IMAGE_SCENE_H_
