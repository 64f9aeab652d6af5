// Internals of the world builder shared by its files (world.cc: road,
// crossings and marks; world_scenery.cc: buildings, parked vehicles and
// shadows; world_database.cc: the truth and database road marks). Not part
// of the simulator's interface.
#ifndef ZEBRAGEO_SIMULATOR_WORLD_INTERNAL_H_
#define ZEBRAGEO_SIMULATOR_WORLD_INTERNAL_H_

#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "simulator/simulator.h"
#include "simulator/world.h"

namespace zebrageo::sim::world_internal {

// Purposes of the sub-generators (SubSeed).
enum Purpose : uint64_t {
  kRoadSeed = 1,
  kCrossingSeed = 2,
  kMarksSeed = 3,
  kDatabaseSeed = 4,
  kBuildingSeed = 5,
  kVehicleSeed = 6,
  kJunctionSeed = 7,
  kTextureSeed = 9,
};

// Distance kept between a crossing's outer bands and the kerbs of the
// street it spans.
constexpr double kBandKerbMarginM = 0.25;

// The s-intervals of [s0, s1] left after removing `holes` (sorted, merged).
std::vector<std::pair<double, double>> Subtract(
    double s0, double s1, std::vector<std::pair<double, double>> holes);

// The stop line painted min/max_stop_line_distance_m before crossing `ci`
// (and the paint beside it), across the right lane.
StopLine StopLineBefore(const World& world, int ci,
                        const SimulationOptions& options);

// True when [s0, s1] comes within `margin` of a crossing in the street.
bool NearCrossing(const World& world, double s0, double s1, double margin);

// Side streets and the crossings across them (world_junctions.cc), after
// the road's crossings, from their own generator.
// Crossing c's row of bands across a street `width` wide, at most `most`
// of them, and its database offset (world.cc: the random preset's draws).
void DrawBandRow(const SimulationOptions& options, double width, int most,
                 std::mt19937_64* rng, Crossing* c);

// A crossing's design (world_ladder.cc, issue 52): its band width and gap
// and its ladder bars' width (0: none).
struct CrossingDesignDraw {
  double band_width_m = 0.5;
  double band_gap_m = 0.5;
  double ladder_bar_width_m = 0.0;
};
// Drawn from `rng` for every crossing whatever the options (the same number
// of draws), so the other crossings' draws do not change with them.
CrossingDesignDraw DrawCrossingDesign(const SimulationOptions& options,
                                      std::mt19937_64* rng);

void PlaceJunctions(const SimulationOptions& options, World* world);
// Buildings cut back from the side streets' mouths (world_junctions.cc).
void OpenFacadesAtJunctions(const SimulationOptions& options, World* world);
// Vehicles partly hiding side-street crossings (world_junctions.cc).
void ParkAtSideCrossings(const SimulationOptions& options, World* world);

// Avenues (world_avenue.cc, issue 52), from their own generator: the
// driving lane and lane changes (before the scenery), the road crossings
// re-laid kerb to kerb and split by the median's island (after
// PlaceCrossings), the lines of the median and the lanes (after
// PaintLines). Each does nothing without a median or extra lanes.
void PlanLanes(const SimulationOptions& options, World* world);
void SplitCrossingsAtIsland(const SimulationOptions& options, World* world);
void PaintAvenueLines(const SimulationOptions& options, World* world);

// The scenery (world_scenery.cc), in this order after the road marks.
void BuildFacades(const SimulationOptions& options, World* world);
void ParkVehicles(const SimulationOptions& options, World* world);
void ParkOverEndBands(const SimulationOptions& options, World* world);
void CastShadows(const SimulationOptions& options, World* world);

// Paint beside the crossings (world_paint_beside.cc, issue 52), after the
// crossings and before the lines; trucks standing on crossings, after the
// other vehicles. Each from its own generator.
void PaintBeside(const SimulationOptions& options, World* world);
void ParkTrucks(const SimulationOptions& options, World* world);

}  // namespace zebrageo::sim::world_internal

#endif  // ZEBRAGEO_SIMULATOR_WORLD_INTERNAL_H_
