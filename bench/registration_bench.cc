// Timings of the registration stage on a city-sized road-mark database.
//
// The database: the real crossing locations and road bearings of Monaco
// (OpenStreetMap, ../shared/datasets/osm/monaco_crossings.geojson, ODbL,
// (c) OpenStreetMap contributors), 398 point crossings, tiled over a grid
// of copies 4 km apart until there are >= 100,000 bands (4 to 12 bands of
// 0.5 m every 1 m, 2.5 to 6 m long, along the road bearing). Without the
// shared folder, random positions and bearings stand in.
//
// Targets (issue 6): load (GeoJSON parse) + index under 2 s, one candidate
// query under 50 microseconds.
//
// Measured 2026-11-23 on the 2-core development machine while other builds
// ran (load average 6-17, so wall time is up to 2-9x CPU time), medians of
// 3 repetitions, 101,715 bands (46 MB of GeoJSON):
//   LoadAndIndex100kBands  0.35-0.45 s CPU, 0.65-0.92 s wall at load 6-10
//                          (3.2 s wall at load 17); was 1.9 s CPU, 2.2-2.9 s
//                          wall with nlohmann::json's DOM
//   ReadRoadmarks100kBands 0.29-0.36 s CPU
//   Index100kBands         0.06-0.08 s CPU
//   CandidateQuery/20      0.4-0.7 us CPU (12.7 bands per query)
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "registration/band_matcher.h"
#include "registration/roadmark_index.h"
#include "survey/math_util.h"
#include "survey/roadmarks.h"

namespace zebrageo {
namespace {

constexpr int kTargetBands = 100000;

struct Seed {
  double lat = 0.0;
  double lon = 0.0;
  double bearing_deg = 0.0;  // of the road, clockwise from north
};

std::vector<Seed> MonacoCrossings() {
  std::vector<Seed> seeds;
  const std::string path = std::string(ZEBRAGEO_SHARED_DIR) +
                           "/datasets/osm/monaco_crossings.geojson";
  std::ifstream in(path);
  if (in) {
    const nlohmann::json root = nlohmann::json::parse(in);
    for (const nlohmann::json& f : root["features"]) {
      if (f["geometry"]["type"] != "Point") continue;
      const nlohmann::json& p = f["properties"];
      Seed s;
      s.lon = f["geometry"]["coordinates"][0].get<double>();
      s.lat = f["geometry"]["coordinates"][1].get<double>();
      // 35 nodes have no road bearing: any direction will do for timing.
      s.bearing_deg =
          p.contains("@road_bearing_deg") && p["@road_bearing_deg"].is_number()
              ? p["@road_bearing_deg"].get<double>()
              : 0.0;
      seeds.push_back(s);
    }
  }
  if (seeds.empty()) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 400; ++i) {
      seeds.push_back(
          {43.725 + 0.02 * u(rng), 7.41 + 0.03 * u(rng), 180.0 * u(rng)});
    }
  }
  return seeds;
}

// >= kTargetBands bands around Monaco's origin, in tiles 4 km apart.
const RoadmarkDatabase& CityDatabase() {
  static const RoadmarkDatabase* const database = [] {
    auto* db = new RoadmarkDatabase;
    const std::vector<Seed> seeds = MonacoCrossings();
    const LocalFrame frame(Geodetic{seeds[0].lat, seeds[0].lon, 0.0});
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> bands(4, 12);
    std::uniform_real_distribution<double> length(2.5, 6.0);
    int tile = 0;
    while (static_cast<int>(db->bands.size()) < kTargetBands) {
      const Eigen::Vector3d offset(4000.0 * (tile % 6), 4000.0 * (tile / 6),
                                   0.0);
      for (size_t c = 0; c < seeds.size(); ++c) {
        const Eigen::Vector3d centre =
            frame.EnuFromGeodetic(Geodetic{seeds[c].lat, seeds[c].lon, 0.0}) +
            offset;
        // Road direction in ENU (bearing is clockwise from north).
        const double b = seeds[c].bearing_deg * kPi / 180.0;
        const Eigen::Vector3d along(std::sin(b), std::cos(b), 0.0);
        const Eigen::Vector3d across(-along.y(), along.x(), 0.0);
        const int n = bands(rng);
        const double half = 0.5 * length(rng);
        for (int k = 1; k <= n; ++k) {
          const Eigen::Vector3d m = centre + (k - 0.5 * (n + 1)) * across;
          RoadmarkBand band;
          band.crossing_id =
              "T" + std::to_string(tile) + "-" + std::to_string(c);
          band.band = k;
          band.sigma_xy_m = 0.05;
          band.sigma_z_m = 0.1;
          const Eigen::Vector3d corners[4] = {m - half * along - 0.25 * across,
                                              m + half * along - 0.25 * across,
                                              m + half * along + 0.25 * across,
                                              m - half * along + 0.25 * across};
          for (int v = 0; v < 4; ++v) {
            band.corners[v] = frame.GeodeticFromEnu(corners[v]);
          }
          db->bands.push_back(band);
        }
      }
      ++tile;
    }
    return db;
  }();
  return *database;
}

const std::string& CityDatabaseFile() {
  static const std::string* const path = [] {
    auto* p = new std::string((std::filesystem::temp_directory_path() /
                               "zebrageo_registration_bench_roadmarks.geojson")
                                  .string());
    WriteRoadmarks(CityDatabase(), *p);
    return p;
  }();
  return *path;
}

LocalFrame CityFrame() {
  return LocalFrame(Geodetic{CityDatabase().bands[0].corners[0].lat_deg,
                             CityDatabase().bands[0].corners[0].lon_deg, 0.0});
}

// Reading the GeoJSON (with the survey reader's validation), reprojecting
// and indexing: what `zebrageo match` does before matching.
void BM_LoadAndIndex100kBands(benchmark::State& state) {
  const std::string& path = CityDatabaseFile();
  const LocalFrame frame = CityFrame();
  for (auto _ : state) {
    const RoadmarkDatabase db = ReadRoadmarks(path, "roadmarks.geojson");
    const RoadmarkIndex index(db, frame);
    benchmark::DoNotOptimize(index.bands().data());
  }
  state.counters["bands"] = static_cast<double>(CityDatabase().bands.size());
}
BENCHMARK(BM_LoadAndIndex100kBands)->Unit(benchmark::kMillisecond);

// The survey reader alone (JSON parse and validation): most of the above.
void BM_ReadRoadmarks100kBands(benchmark::State& state) {
  const std::string& path = CityDatabaseFile();
  for (auto _ : state) {
    const RoadmarkDatabase db = ReadRoadmarks(path, "roadmarks.geojson");
    benchmark::DoNotOptimize(db.bands.data());
  }
}
BENCHMARK(BM_ReadRoadmarks100kBands)->Unit(benchmark::kMillisecond);

void BM_Index100kBands(benchmark::State& state) {
  const RoadmarkDatabase& db = CityDatabase();
  const LocalFrame frame = CityFrame();
  for (auto _ : state) {
    const RoadmarkIndex index(db, frame);
    benchmark::DoNotOptimize(index.bands().data());
  }
  state.counters["bands"] = static_cast<double>(db.bands.size());
}
BENCHMARK(BM_Index100kBands)->Unit(benchmark::kMillisecond);

// Query points near crossings (where the matcher asks), radius as the drift
// gate of an observation (max_drift_m 4 + group radius 6 m).
void BM_CandidateQuery(benchmark::State& state) {
  static const RoadmarkIndex* const index =
      new RoadmarkIndex(CityDatabase(), CityFrame());
  const double radius = static_cast<double>(state.range(0));
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> pick(
      0, static_cast<int>(index->crossings().size()) - 1);
  std::normal_distribution<double> jitter(0.0, 5.0);
  std::vector<Eigen::Vector2d> points(4096);
  for (Eigen::Vector2d& p : points) {
    p = index->crossings()[pick(rng)].centre_enu +
        Eigen::Vector2d(jitter(rng), jitter(rng));
  }
  std::vector<int> found;
  size_t i = 0;
  int64_t total = 0;
  for (auto _ : state) {
    index->BandsWithin(points[i++ % points.size()], radius, &found);
    total += static_cast<int64_t>(found.size());
    benchmark::DoNotOptimize(found.data());
  }
  state.counters["bands_per_query"] =
      static_cast<double>(total) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_CandidateQuery)
    ->Arg(1)
    ->Arg(10)
    ->Arg(20)
    ->Unit(benchmark::kMicrosecond);

void BM_CrossingsQuery(benchmark::State& state) {
  static const RoadmarkIndex* const index =
      new RoadmarkIndex(CityDatabase(), CityFrame());
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> pick(
      0, static_cast<int>(index->crossings().size()) - 1);
  std::vector<int> found;
  for (auto _ : state) {
    index->CrossingsWithin(index->crossings()[pick(rng)].centre_enu, 15.0,
                           &found);
    benchmark::DoNotOptimize(found.data());
  }
}
BENCHMARK(BM_CrossingsQuery)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace zebrageo

BENCHMARK_MAIN();
