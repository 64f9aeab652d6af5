#include "simulator/simulator.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "simulator/motion.h"
#include "simulator/noise.h"
#include "simulator/options_json.h"
#include "simulator/renderer.h"
#include "simulator/simulated_survey.h"
#include "simulator/world.h"
#include "survey/atomic_file.h"
#include "survey/csv.h"
#include "survey/exposures.h"
#include "survey/image_io.h"
#include "survey/math_util.h"
#include "survey/rig.h"
#include "survey/roadmarks.h"
#include "survey/survey.h"
#include "survey/trajectory.h"

namespace zebrageo {
namespace {

std::string Fmt(double v) { return FormatDouble(v); }

double RoundTo(double value, double step) {
  return std::round(value / step) * step;
}

}  // namespace

std::string SimulationSummary::BriefReport() const {
  std::ostringstream out;
  out << "simulated " << Fmt(RoundTo(driven_length_m, 0.1)) << " m in "
      << Fmt(RoundTo(duration_s, 0.01)) << " s: " << num_crossings_in_street
      << " crossings in the street (" << num_bands_in_street << " bands), "
      << num_crossings_in_database << " in the database ("
      << num_bands_in_database << " bands), " << num_exposures << " exposures, "
      << num_images_rendered << " images rendered ("
      << Fmt(RoundTo(seconds_per_image, 0.001)) << " s CPU each), "
      << "drift up to " << Fmt(RoundTo(max_horizontal_error_m, 0.001))
      << " m horizontal, " << Fmt(RoundTo(max_vertical_error_m, 0.001))
      << " m vertical; total " << Fmt(RoundTo(total_seconds, 0.01)) << " s";
  return out.str();
}

// ------------------------------------------------------------ simulation
namespace {

namespace fs = std::filesystem;
using sim::World;

// The road of meta.json: its length, width, driven part and segments.
nlohmann::json RoadJson(const World& world) {
  nlohmann::json road;
  road["centreline_length_m"] = world.road.length_m();
  road["width_m"] = world.road.width_m();
  road["driven_s_m"] = {world.s_drive_start, world.s_drive_end};
  road["lane_offset_m"] = world.lane_offset_m;
  nlohmann::json segments = nlohmann::json::array();
  for (const auto& seg : world.road.segments()) {
    const double radius0 = seg.kappa0 == 0.0 ? 0.0 : 1.0 / seg.kappa0;
    const double radius1 = seg.kappa1 == 0.0 ? 0.0 : 1.0 / seg.kappa1;
    segments.push_back(
        {{"s_m", {seg.s0, seg.s1}}, {"radius_m", {radius0, radius1}}});
  }
  road["segments"] = segments;
  nlohmann::json side_streets = nlohmann::json::array();
  for (const sim::SideStreet& street : world.side_streets) {
    side_streets.push_back({{"junction", street.junction},
                            {"s_m", street.s_m},
                            {"side", street.side > 0 ? "left" : "right"},
                            {"angle_deg", RadToDeg(street.angle_rad)},
                            {"width_m", street.width_m},
                            {"mouth_s_m", {street.mouth_s0, street.mouth_s1}}});
  }
  road["side_streets"] = side_streets;
  road["note"] =
      "radius 0 = straight; signed radius > 0 turns left; a segment whose "
      "two radii differ is a clothoid";
  return road;
}

// One crossing of meta.json: its design, where it is, and its faults.
nlohmann::json CrossingJson(const World& world, const sim::Crossing& c) {
  nlohmann::json j;
  j["crossing_id"] = c.id;
  j["in_db"] = c.in_db;
  j["in_street"] = c.in_street;
  const int island = static_cast<int>(c.island_bands.size());
  j["num_bands"] = c.in_street ? c.num_street_bands - island : 0;
  j["num_bands_db"] = c.in_db ? c.num_db_bands - island -
                                    static_cast<int>(c.db_missing_bands.size())
                              : 0;
  // Split by an avenue's refuge island (issue 52): its database form.
  if (!c.island_form.empty()) {
    j["island_form"] = c.island_form;
    if (!c.island_bands.empty()) j["island_bands"] = c.island_bands;
    if (!c.other_half.empty()) j["other_half"] = c.other_half;
  }
  j["skew_deg"] = c.skew_deg;
  j["band_length_m"] = c.band_length_m;
  j["band_width_m"] = c.band_width_m;
  j["band_period_m"] = c.band_period_m;
  // Issue 52: the design, and the ladder's bars (not in the database).
  j["design"] = c.ladder_bar_width_m > 0.0 ? "ladder" : "continental";
  if (c.ladder_bar_width_m > 0.0)
    j["ladder_bar_width_m"] = c.ladder_bar_width_m;
  j["s_m"] = c.s_m;
  const Eigen::Vector3d centre = world.road.SurfacePoint(c.s_m, 0.0);
  j["origin_enu"] = {c.origin_xy.x(), c.origin_xy.y(), centre.z()};
  j["db_offset_m"] = {c.db_offset_enu.x(), c.db_offset_enu.y(),
                      c.db_offset_enu.z()};
  j["repainted"] = c.repainted;
  j["repaint_shift_m"] = {c.repaint_shift_xy.x(), c.repaint_shift_xy.y(), 0.0};
  j["missing_band"] = c.missing_band_kind.empty()
                          ? nlohmann::json(nullptr)
                          : nlohmann::json(c.missing_band_kind);
  j["stop_line"] = c.stop_line;
  j["occluded_by_vehicle"] = c.occluded_by_vehicle;
  if (!c.db_missing_bands.empty()) j["db_missing_bands"] = c.db_missing_bands;
  if (!c.end_band_vehicle.empty()) j["end_band_vehicle"] = c.end_band_vehicle;
  // Issue 52: the paint beside it (not bands) and a truck standing on it.
  if (!c.beside.empty()) j["beside"] = c.beside;
  if (c.truck) {
    j["truck"] = true;
    j["truck_bands"] = c.truck_bands;
  }
  // Which street it spans: the road driven, or a side street (issue 51).
  j["across"] = c.side_street < 0 ? "road" : "side_street";
  if (c.side_street >= 0) {
    const sim::SideStreet& street = world.side_streets[c.side_street];
    j["junction"] = street.junction;
    j["side"] = street.side > 0 ? "left" : "right";
    j["junction_angle_deg"] = RadToDeg(street.angle_rad);
    j["side_street_width_m"] = street.width_m;
    if (!c.side_vehicle.empty()) j["side_vehicle"] = c.side_vehicle;
  }
  return j;
}

// The faults of meta.json: crossings missing, stale or repainted, bands
// missing from the street or the database, and the database's road lines
// that differ from the street.
nlohmann::json FaultsJson(const World& world) {
  nlohmann::json faults;
  faults["missing_crossings"] = nlohmann::json::array();
  faults["stale_crossings"] = nlohmann::json::array();
  faults["repainted_crossings"] = nlohmann::json::array();
  faults["missing_bands"] = nlohmann::json::array();
  for (const sim::Crossing& c : world.crossings) {
    if (!c.in_db) faults["missing_crossings"].push_back(c.id);
    if (!c.in_street) faults["stale_crossings"].push_back(c.id);
    if (c.repainted) faults["repainted_crossings"].push_back(c.id);
    if (c.missing_band_kind == "worn_in_street") {
      faults["missing_bands"].push_back({{"crossing_id", c.id},
                                         {"band", c.num_design_bands},
                                         {"kind", c.missing_band_kind},
                                         {"in_db", true},
                                         {"in_street", false}});
    } else if (c.missing_band_kind == "missing_in_db") {
      faults["missing_bands"].push_back({{"crossing_id", c.id},
                                         {"band", c.num_design_bands},
                                         {"kind", c.missing_band_kind},
                                         {"in_db", false},
                                         {"in_street", true}});
    }
    for (int band : c.db_missing_bands) {
      faults["missing_bands"].push_back({{"crossing_id", c.id},
                                         {"band", band},
                                         {"kind", c.missing_band_kind},
                                         {"in_db", false},
                                         {"in_street", true}});
    }
  }
  faults["database_lines"] = nlohmann::json::array();
  for (const sim::DatabaseLineFault& f : world.database_line_faults) {
    nlohmann::json j = {{"kind", f.kind},
                        {"l_m", f.l_m},
                        {"s0_m", f.s0},
                        {"s1_m", f.s1},
                        {"shift_m", f.shift_m}};
    if (f.crossing >= 0) j["crossing_id"] = world.crossings[f.crossing].id;
    faults["database_lines"].push_back(j);
  }
  return faults;
}

// The trajectory error of meta.json: its extremes, the outage and the
// multipath switches.
nlohmann::json TrajectoryErrorJson(const SimulationOptions& options,
                                   const sim::VehicleMotion& motion) {
  double max_h = 0.0, max_v = 0.0, sum_h2 = 0.0, max_heading = 0.0;
  for (size_t k = 0; k < motion.position_error_enu.size(); ++k) {
    const Eigen::Vector3d& e = motion.position_error_enu[k];
    max_h = std::max(max_h, e.head<2>().norm());
    max_v = std::max(max_v, std::abs(e.z()));
    sum_h2 += e.head<2>().squaredNorm();
    max_heading =
        std::max(max_heading, std::abs(motion.attitude_error_rad[k].z()));
  }
  nlohmann::json error;
  error["max_horizontal_m"] = max_h;
  error["rms_horizontal_m"] =
      std::sqrt(sum_h2 / std::max<size_t>(1, motion.position_error_enu.size()));
  error["max_vertical_m"] = max_v;
  error["max_heading_deg"] = RadToDeg(max_heading);
  error["reported_sd_horizontal_m"] = options.reported_sd_horizontal_m;
  if (motion.outage_end_time > motion.outage_begin_time) {
    error["outage_time"] = {motion.outage_begin_time, motion.outage_end_time};
  } else {
    error["outage_time"] = nullptr;
  }
  if (!motion.multipath_switches.empty()) {
    error["multipath_switches"] = nlohmann::json::array();
  }
  for (const sim::MultipathSwitch& m : motion.multipath_switches) {
    error["multipath_switches"].push_back({{"s_m", m.s_m},
                                           {"length_m", m.length_m},
                                           {"cross_track_m", m.cross_track_m}});
  }
  return error;
}

nlohmann::json CountsJson(const World& world,
                          const SimulationSummary& summary) {
  nlohmann::json counts;
  counts["crossings_in_street"] = summary.num_crossings_in_street;
  counts["crossings_in_db"] = summary.num_crossings_in_database;
  counts["bands_in_street"] = summary.num_bands_in_street;
  counts["bands_in_db"] = summary.num_bands_in_database;
  counts["lines"] = summary.num_lines;
  counts["exposures"] = summary.num_exposures;
  counts["images"] = summary.num_images;
  counts["images_rendered"] = summary.num_images_rendered;
  counts["trajectory_samples"] = summary.num_trajectory_samples;
  counts["buildings"] = static_cast<int>(world.buildings.size());
  counts["parked_vehicles"] = static_cast<int>(world.vehicles.size());
  counts["manholes"] = static_cast<int>(world.manholes.size());
  counts["stains"] = static_cast<int>(world.stains.size());
  return counts;
}

// truth/meta.json: what was simulated, for scoring and for people.
nlohmann::json MetaJson(const SimulationOptions& options, const World& world,
                        const sim::VehicleMotion& motion,
                        const SimulationSummary& summary) {
  nlohmann::json meta;
  meta["generator"] = "zebrageo simulate";
  meta["preset"] = options.preset;
  meta["seed"] = options.seed;
  meta["expect"] = "ok";
  meta["render_images"] = options.render_images;
  meta["options"] = OptionsToJson(options);
  meta["origin"] = {options.origin_lat_deg, options.origin_lon_deg,
                    options.origin_h_m};
  meta["road"] = RoadJson(world);
  nlohmann::json crossings = nlohmann::json::array();
  for (const sim::Crossing& c : world.crossings) {
    crossings.push_back(CrossingJson(world, c));
  }
  meta["crossings"] = crossings;
  meta["faults"] = FaultsJson(world);
  meta["trajectory_error"] = TrajectoryErrorJson(options, motion);
  meta["counts"] = CountsJson(world, summary);
  return meta;
}

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t)
      .count();
}

// The summary of what the simulation made, before writing and rendering.
SimulationSummary SummaryOf(const sim::SimulatedSurvey& simulated) {
  const World& world = simulated.world;
  const sim::VehicleMotion& motion = simulated.motion;
  SimulationSummary summary;
  summary.num_trajectory_samples = static_cast<int>(motion.truth.size());
  summary.driven_length_m = world.s_drive_end - world.s_drive_start;
  summary.duration_s = motion.truth.back().time - motion.truth.front().time;
  for (const sim::Crossing& c : world.crossings) {
    summary.num_crossings_in_street += c.in_street ? 1 : 0;
    summary.num_crossings_in_database += c.in_db ? 1 : 0;
  }
  for (const Eigen::Vector3d& e : motion.position_error_enu) {
    summary.max_horizontal_error_m =
        std::max(summary.max_horizontal_error_m, e.head<2>().norm());
    summary.max_vertical_error_m =
        std::max(summary.max_vertical_error_m, std::abs(e.z()));
  }
  summary.num_exposures =
      static_cast<int>(simulated.exposures.exposures.size());
  summary.num_images = static_cast<int>(simulated.exposures.images.size());
  summary.num_bands_in_street = static_cast<int>(simulated.truth.bands.size());
  summary.num_bands_in_database =
      static_cast<int>(simulated.database.bands.size());
  summary.num_lines = static_cast<int>(simulated.database.lines.size());
  return summary;
}

// The survey's files (all but the images and truth/meta.json), and the
// truth beside them.
void WriteSurveyFiles(const sim::SimulatedSurvey& simulated,
                      const fs::path& folder) {
  const sim::VehicleMotion& motion = simulated.motion;
  WriteRig(simulated.rig, (folder / "rig.yaml").string());
  WriteTrajectorySamples(motion.measured, (folder / "trajectory.csv").string());
  WriteTrajectorySamples(motion.truth,
                         (folder / "truth" / "trajectory.csv").string());
  WriteExposures(simulated.exposures, simulated.rig,
                 (folder / "exposures.csv").string());
  WriteRoadmarks(simulated.database, (folder / "roadmarks.geojson").string());
  WriteRoadmarks(simulated.truth,
                 (folder / "truth" / "roadmarks.geojson").string());
}

int RenderThreads(const SimulationOptions& options, int total) {
  return std::max(
      1, std::min(total, options.threads > 0
                             ? options.threads
                             : static_cast<int>(std::max(
                                   1u, std::thread::hardware_concurrency()))));
}

// Renders every image of the survey on RenderThreads() threads, each image
// from its own seed (the images do not depend on the threads); fills the
// summary's image counts and times.
void RenderImages(const SimulationOptions& options,
                  const sim::SimulatedSurvey& simulated, const fs::path& folder,
                  const std::function<void(int done, int total)>& progress,
                  SimulationSummary* summary) {
  const Rig& rig = simulated.rig;
  const ExposureTable& table = simulated.exposures;
  // Poses exactly as a reader of truth/trajectory.csv interpolates them.
  const Trajectory truth_trajectory(simulated.motion.truth, simulated.frame);
  std::vector<sim::RayTable> ray_tables;
  for (const RigCamera& c : rig.cameras) ray_tables.emplace_back(c.camera);
  const sim::Renderer renderer(simulated.world,
                               sim::RenderSettings::FromOptions(options));
  const int total = summary->num_images;
  const int workers = RenderThreads(options, total);
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  int done = 0;
  double cpu_seconds = 0.0;
  std::exception_ptr first_error;
  const auto render_start = std::chrono::steady_clock::now();
  auto work = [&]() {
    try {
      while (!failed) {
        const int index = next++;
        if (index >= total) break;
        const ExposureImage& item = table.images[index];
        Pose pose;
        CHECK(truth_trajectory.InterpolatePose(item.time, &pose));
        const RigCamera& camera = rig.cameras[item.camera];
        const Eigen::Isometry3d T_enu_cam =
            pose.T_enu_body() * camera.T_body_cam;
        const double s_hint =
            simulated.motion.exposures[index / rig.cameras.size()].s_m;
        sim::RenderStats stats;
        const cv::Mat image = renderer.Render(
            camera.camera, ray_tables[item.camera], T_enu_cam, s_hint,
            sim::SubSeed(options.seed, 100, static_cast<uint64_t>(index)),
            &stats);
        std::vector<uchar> png;
        CHECK(
            cv::imencode(".png", image, png, {cv::IMWRITE_PNG_COMPRESSION, 3}));
        WriteFileAtomically(
            (folder / item.image).string(), [&png](std::ostream& out) {
              out.write(reinterpret_cast<const char*>(png.data()),
                        static_cast<std::streamsize>(png.size()));
            });
        std::lock_guard<std::mutex> lock(mutex);
        ++done;
        cpu_seconds += stats.seconds;
        VLOG(1) << item.image << ": " << stats.rays << " rays, "
                << stats.supersampled_pixels << " supersampled pixels, "
                << stats.seconds << " s";
        if (progress) progress(done, total);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!first_error) first_error = std::current_exception();
      failed = true;
    }
  };
  PrepareImageCodecs();
  std::vector<std::thread> threads;
  for (int w = 0; w < workers; ++w) threads.emplace_back(work);
  for (std::thread& t : threads) t.join();
  if (first_error) std::rethrow_exception(first_error);
  summary->num_images_rendered = done;
  summary->render_seconds = SecondsSince(render_start);
  summary->seconds_per_image = done > 0 ? cpu_seconds / done : 0.0;
}

}  // namespace

SimulationSummary SimulateSurvey(
    const SimulationOptions& options, const std::string& output_folder,
    const std::function<void(int done, int total)>& progress) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(error);
  const auto start = std::chrono::steady_clock::now();
  LOG(INFO) << "simulate: preset " << options.preset << ", seed "
            << options.seed << ", " << options.road_length_m << " m";
  const sim::SimulatedSurvey simulated = sim::MakeSimulatedSurvey(options);
  SimulationSummary summary = SummaryOf(simulated);

  const fs::path folder(output_folder);
  std::error_code ec;
  fs::create_directories(folder / "truth", ec);
  if (!ec && options.render_images)
    fs::create_directories(folder / "images", ec);
  if (ec) {
    throw std::runtime_error("cannot create " + output_folder + ": " +
                             ec.message());
  }
  WriteSurveyFiles(simulated, folder);
  if (options.render_images) {
    RenderImages(options, simulated, folder, progress, &summary);
  }

  summary.total_seconds = SecondsSince(start);
  const nlohmann::json meta =
      MetaJson(options, simulated.world, simulated.motion, summary);
  WriteFileAtomically(
      (folder / "truth" / "meta.json").string(),
      [&meta](std::ostream& out) { out << meta.dump(2) << "\n"; });
  SurveyManifest manifest;
  manifest.name =
      "zebrageo-sim-" + options.preset + "-seed" + std::to_string(options.seed);
  manifest.origin = simulated.origin;
  WriteManifest(manifest, (folder / "survey.yaml").string());
  summary.total_seconds = SecondsSince(start);
  LOG(INFO) << summary.BriefReport();
  return summary;
}

}  // namespace zebrageo
