// The simulated street: zebra crossings, other road marks, buildings, parked
// vehicles and shadows, in the survey's ENU frame (metres), plus the
// road-mark database made from it (true corners + noise + faults).
//
// Crossing frame: origin on the road centreline at s_m (after a repaint
// shift, see below), `t` the road tangent there (horizontal unit vector),
// `n` its left normal. Design band k (1-based) spans offsets
// o in [o_k, o_k + band_width], o_k = first_offset + (k - 1) * period, and
// along-road positions a in [-L/2, L/2] measured from the skew line
// a = o * tan_skew, i.e. its horizontal footprint is the parallelogram
//   xy(o, a) = origin + o n + (o tan_skew + a) t.
// Long sides are along t (the road), short sides along n + tan_skew t.
// Corners lie on the road surface; the band is the planar quad through them
// (they are coplanar to < 0.1 mm), which is what the renderer paints.
#ifndef ZEBRAGEO_SIMULATOR_WORLD_H_
#define ZEBRAGEO_SIMULATOR_WORLD_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "simulator/road.h"
#include "simulator/simulator.h"
#include "survey/geodesy.h"
#include "survey/roadmarks.h"

namespace zebrageo::sim {

// A box with vertical sides: horizontal rectangle (centre, unit axis u, its
// left perpendicular v, half sizes) extruded from z0 to z1.
struct VerticalBox {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis_u = Eigen::Vector2d::UnitX();
  double half_u = 1.0;
  double half_v = 1.0;
  double z0 = 0.0;
  double z1 = 1.0;

  Eigen::Vector2d axis_v() const { return {-axis_u.y(), axis_u.x()}; }
  std::array<Eigen::Vector2d, 4> Footprint() const;  // counter-clockwise
};

struct Building {
  VerticalBox box;
  // Sign of v of the face towards the road (+1: the +v face).
  int front_side = 1;
  float wall_tone = 150.0f;
  float window_tone = 45.0f;
  double window_period_m = 3.0;
  double window_width_m = 1.3;
  double window_height_m = 1.5;
  double sill_height_m = 0.9;  // above each floor
  double floor_height_m = 3.1;
  double ground_floor_height_m = 4.0;
  double window_offset_m = 0.5;  // of the first window from the face start
  bool shop_front = false;
  double s0 = 0.0, s1 = 0.0;  // road extent
  uint64_t salt = 0;
};

struct ParkedVehicle {
  VerticalBox box;
  float body_tone = 120.0f;
  double s0 = 0.0, s1 = 0.0;
  bool occludes_crossing = false;
  // A truck standing on a crossing (issue 52): a box body with lettered,
  // ribbed sides (texture a stereo pair can measure) and a cab.
  bool truck = false;
  uint64_t salt = 0;
};

// A painted band in the street.
struct Band {
  int crossing = -1;  // index into World::crossings
  int band = 0;       // 1-based across the crossing
  // ENU, counter-clockwise seen from above; ring_start rotates the start.
  std::array<Eigen::Vector3d, 4> corners;
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();  // up
  double plane_offset = 0.0;  // plane: normal . x = offset
  double o0 = 0.0, o1 = 0.0;  // offsets of its long sides
  // A patch of missing paint (crossing-frame coordinates a, o), radius 0 =
  // none.
  Eigen::Vector2d patch_ao = Eigen::Vector2d::Zero();
  double patch_radius_m = 0.0;
  uint64_t salt = 0;
};

struct Crossing {
  std::string id;
  double s_m = 0.0;
  Eigen::Vector2d origin_xy = Eigen::Vector2d::Zero();  // street position
  Eigen::Vector2d t = Eigen::Vector2d::UnitX();
  Eigen::Vector2d n = Eigen::Vector2d::UnitY();
  double skew_deg = 0.0;
  double tan_skew = 0.0;
  double band_length_m = 3.0;
  double band_width_m = 0.5;
  double band_period_m = 1.0;  // width + gap
  // The ladder design (issue 52): > 0 when two solid bars this wide (along
  // t) lie along the crossing's edges, just beyond its band ends, from the
  // first band's outer long side to the last one's (world_ladder.cc).
  double ladder_bar_width_m = 0.0;
  int num_design_bands = 0;
  double first_offset_m = 0.0;
  std::vector<int> ring_start;  // per design band, 0..3
  bool in_street = true;
  bool in_db = true;
  int num_street_bands = 0;  // bands 1..num_street_bands are painted
  int num_db_bands = 0;      // bands 1..num_db_bands are in the database
  // "", "worn_in_street", "missing_in_db" (the last band),
  // "end_missing_in_db", "interior_missing_in_db" (db_missing_bands).
  std::string missing_band_kind;
  // Band numbers of 1..num_db_bands the database lacks (it keeps the
  // street's numbering, with a gap).
  std::vector<int> db_missing_bands;
  bool repainted = false;
  // Street origin minus database origin (horizontal, metres).
  Eigen::Vector2d repaint_shift_xy = Eigen::Vector2d::Zero();
  Eigen::Vector3d db_offset_enu = Eigen::Vector3d::Zero();
  bool stop_line = false;
  bool occluded_by_vehicle = false;
  // "first" or "last" when a vehicle is parked over that band, else "".
  std::string end_band_vehicle;
  // Road s-range covered by the painted area (with skew), street position.
  double s_min = 0.0, s_max = 0.0;
  uint64_t salt = 0;
  // Index into World::side_streets of the side street it spans (its `t`
  // the side street's direction, its origin on that street's axis), or -1
  // for a crossing of the road driven.
  int side_street = -1;
  // "turning" or "parked" when a vehicle partly hides a side-street
  // crossing, else "".
  std::string side_vehicle;
  // A crossing split by an avenue's refuge island (issue 52): "one_id"
  // (one crossing, its island_bands neither painted nor in the database),
  // "near_half" or "far_half" (two crossings, other_half the other's id),
  // else "".
  std::string island_form;
  std::vector<int> island_bands;
  std::string other_half;
  // Paint beside it (world_paint_beside.cc, issue 52): how far it reaches
  // before s_min and after s_max (the stop line and the lane lines keep
  // clear of it), what it is ("squares", "squares+lane+squares", ...), and
  // a truck standing on it (the bands under it, 1-based).
  double beside_before_m = 0.0;
  double beside_after_m = 0.0;
  std::vector<std::string> beside;
  bool truck = false;
  std::vector<int> truck_bands;
};

// The vehicle moving to a neighbouring lane between road positions s0 and
// s1 (issue 52), l_from to l_to (road offsets of the lanes' centres).
struct LaneChange {
  double s0 = 0.0, s1 = 0.0;
  double l_from = 0.0, l_to = 0.0;
};

// Paint beside a crossing that is not a zebra band (issue 52): a bicycle
// square, a coloured bicycle lane, a give-way tooth. Convex polygon on the
// road surface, counter-clockwise; not in the database nor the truth.
struct BesideMark {
  std::string kind;  // "square", "bike_lane", "tooth"
  int crossing = -1;
  std::vector<Eigen::Vector2d> polygon;
  // Grey level fully lit; white paint is worn like the bands, a coloured
  // surface (the renderer is grey: a red lane is a mid-grey coat) is not.
  float tone = 212.0f;
  bool white = true;
  uint64_t salt = 0;

  // True when xy lies inside the polygon.
  bool Contains(const Eigen::Vector2d& xy) const;
};

// A side street meeting the road at a junction (issue 51). Its surface is
// level across, at the height of the road's kerb line where it meets it
// (crown(s) + cross(side * half width) at the road position s beside it).
// It starts at the road's kerb line and runs length_m from the road's
// centreline along `direction`.
struct SideStreet {
  double s_m = 0.0;        // road position of its axis' foot
  int side = 1;            // +1: left of the road, -1: right
  double angle_rad = 0.0;  // from the road's normal, towards +t
  double width_m = 8.0;
  double length_m = 60.0;
  int junction = 0;  // side streets of a four-way junction share it
  Eigen::Vector2d axis_xy = Eigen::Vector2d::Zero();     // on the centreline
  Eigen::Vector2d direction = Eigen::Vector2d::UnitY();  // away from it
  // Road s-range of its mouth at the kerb line.
  double mouth_s0 = 0.0, mouth_s1 = 0.0;

  Eigen::Vector2d across() const { return {-direction.y(), direction.x()}; }
};

// A line painted along the road at constant l over [s0, s1].
struct LinePiece {
  std::string type;  // lane_solid, lane_dashed
  double l_m = 0.0;
  double width_m = 0.15;
  double s0 = 0.0, s1 = 0.0;
};

// A stop line across the road at constant s, from l0 to l1 (l0 < l1).
struct StopLine {
  double s_m = 0.0;
  double l0 = 0.0, l1 = 0.0;
  double width_m = 0.3;
  int crossing = -1;
};

struct Manhole {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.3;
  bool square = false;
  uint64_t salt = 0;
};

struct Stain {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius_m = 0.5;
  float darkness = 0.7f;  // multiplier at the centre
  uint64_t salt = 0;
};

// A cast shadow on the ground: convex polygon, counter-clockwise.
struct Shadow {
  std::vector<Eigen::Vector2d> polygon;
  float factor = 0.45f;  // light multiplier inside
  // Inward unit normals and offsets of the edges: the signed distance of p
  // inside is min_i (normal_i . p - offset_i). Set by Finish().
  std::vector<Eigen::Vector2d> edge_normals;
  std::vector<double> edge_offsets;

  void Finish();
  double InsideDistance(const Eigen::Vector2d& p) const;
};

// A stretch of a road line whose database copy differs from the street.
struct DatabaseLineFault {
  // "gap": missing from the database; "moved": repainted shift_m across the
  // road since the database was made (the database holds the old position);
  // "removed": a stop line in the database that is no longer painted.
  std::string kind;
  double l_m = 0.0;  // street position of the line (removed: database's)
  double s0 = 0.0, s1 = 0.0;
  double shift_m = 0.0;  // moved: database l minus street l
  int crossing = -1;     // removed: the crossing it stood before
};

struct World {
  Road road;
  double s_drive_start = 0.0;  // the vehicle drives s in [start, end]
  double s_drive_end = 0.0;
  // l of the driving lane's centre; with lane changes (LaneOffsetAt) the
  // lane nearest the right kerb the vehicle drives in.
  double lane_offset_m = 0.0;
  double median_width_m = 0.0;  // an avenue's median (issue 52), 0 = none
  std::vector<LaneChange> lane_changes;
  std::vector<Crossing> crossings;  // in the street and/or in the database
  std::vector<SideStreet> side_streets;
  std::vector<Band> bands;  // painted bands, grouped by crossing
  std::vector<LinePiece> lines;
  std::vector<StopLine> stop_lines;
  std::vector<BesideMark> beside_marks;
  std::vector<DatabaseLineFault> database_line_faults;
  std::vector<Manhole> manholes;
  std::vector<Stain> stains;
  std::vector<Building> buildings;
  std::vector<ParkedVehicle> vehicles;
  std::vector<Shadow> shadows;
  Eigen::Vector3d sun_enu = Eigen::Vector3d::UnitZ();  // towards the sun
  float paint_wear = 0.3f;
  uint64_t texture_salt = 0;
};

// Builds the street from the options (seeded by options.seed).
World BuildWorld(const SimulationOptions& options);

// Index of the side street holding horizontal position `xy` (road offset
// `l` there), -1 if none: beyond the road's kerb on its side, within its
// width and length.
int SideStreetAt(const World& world, const Eigen::Vector2d& xy, double l);

// Height of the ground at `xy` (road coordinates s, l): the road's
// cross-section, or in a side street the kerb line's height beside it.
double GroundHeight(const World& world, const Eigen::Vector2d& xy, double s,
                    double l);

// Horizontal corner positions and heights of design band `band` (1-based)
// of `crossing`, with the crossing's origin at `origin_xy` (the street
// position, or the database position = street - repaint shift), in ring
// order (counter-clockwise, rotated by ring_start).
std::array<Eigen::Vector3d, 4> DesignBandCorners(
    const World& world, const Crossing& crossing, int band,
    const Eigen::Vector2d& origin_xy);

// True when crossing-frame point (o, a) (a measured from the skew line, as
// for the bands) lies on one of the crossing's ladder bars.
bool InLadderBar(const Crossing& crossing, double o, double a);
// Road offset of the vehicle's lane centre at road position s, and its
// derivative dl/ds (lane changes, issue 52; world_avenue.cc).
double LaneOffsetAt(const World& world, double s);
double LaneOffsetSlopeAt(const World& world, double s);
// True when design band `band` of `crossing` is an island's place: neither
// painted nor in the database.
bool IsIslandBand(const Crossing& crossing, int band);

// Truth: the bands painted in the street and the lines, exact.
RoadmarkDatabase MakeTruthRoadmarks(const World& world,
                                    const LocalFrame& frame);
// The database: bands of crossings in_db at their database position (and
// with their database band count), shifted by the crossing's systematic
// offset, plus per-corner Gaussian noise; lines with noise and with the
// world's database_line_faults (gaps, moved stretches, removed stop lines).
RoadmarkDatabase MakeDatabaseRoadmarks(const World& world,
                                       const SimulationOptions& options,
                                       const LocalFrame& frame);

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_WORLD_H_
