#include "tests/support/geometry_sweep.h"

#include <glog/logging.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "adjustment/trajectory_adjuster.h"
#include "pipeline/adjust_outputs.h"
#include "pipeline/adjustment_pass.h"
#include "pipeline/rematch_stage.h"
#include "registration/band_matcher.h"
#include "registration/observations.h"
#include "registration/roadmark_index.h"
#include "simulator/simulated_survey.h"
#include "survey/math_util.h"
#include "tests/support/synthetic_lines.h"
#include "tests/support/synthetic_reconstruction.h"

namespace zebrageo::support {
namespace {

// score_results.py: a matched vertex farther than this from its truth
// corner is wrong.
constexpr double kRightVertexM = 0.2;

using CornerKey = std::pair<std::string, int>;  // crossing_id, band

std::map<CornerKey, std::array<Eigen::Vector3d, 4>> TruthCorners(
    const sim::World& world) {
  std::map<CornerKey, std::array<Eigen::Vector3d, 4>> corners;
  for (const sim::Band& band : world.bands) {
    corners[{world.crossings[band.crossing].id, band.band}] = band.corners;
  }
  return corners;
}

// Scores the matches as score_results.py match does.
void ScoreMatches(const sim::SimulatedSurvey& simulated,
                  const SyntheticReconstruction& reconstruction,
                  const std::map<int64_t, Pose>& true_pose,
                  const std::vector<VertexMatch>& matches,
                  GeometryRunResult* result) {
  const auto truth = TruthCorners(simulated.world);
  std::map<std::pair<int64_t, int>, Eigen::Vector3d> p_body;
  for (const ReconstructedVertex& v : reconstruction.vertices) {
    p_body[{v.band_id, v.vertex}] = v.p_body;
  }
  std::map<int64_t, int64_t> exposure_of_band;
  for (const ReconstructedVertex& v : reconstruction.vertices) {
    exposure_of_band[v.band_id] = v.exposure_id;
  }
  std::set<std::string> matched;
  std::set<std::string> wrong;
  for (const VertexMatch& m : matches) {
    const auto origin = reconstruction.truth_of_band.find(m.band_id);
    if (origin != reconstruction.truth_of_band.end()) {
      const sim::Band& band = simulated.world.bands[origin->second.world_band];
      ++result->ids_checked;
      result->wrong_ids +=
          simulated.world.crossings[band.crossing].id != m.crossing_id ||
          band.band != m.band;
    }
    const auto corners = truth.find({m.crossing_id, m.band});
    const auto vertex = p_body.find({m.band_id, m.vertex});
    const auto pose = true_pose.find(m.exposure_id);
    bool right = corners != truth.end() && vertex != p_body.end() &&
                 pose != true_pose.end() && m.db_vertex >= 0 && m.db_vertex < 4;
    if (right) {
      const Eigen::Vector3d p_enu = pose->second.T_enu_body() * vertex->second;
      right = (p_enu - corners->second[m.db_vertex]).norm() <= kRightVertexM;
    }
    if (right) {
      ++result->right;
      matched.insert(m.crossing_id);
    } else {
      ++result->wrong;
      const auto band = reconstruction.truth_of_band.find(m.band_id);
      if (band != reconstruction.truth_of_band.end() &&
          band->second.cut_short) {
        ++result->wrong_on_cut_bands;
      }
      wrong.insert(m.crossing_id + ":" + std::to_string(m.band));
    }
  }
  result->wrong_crossings.assign(wrong.begin(), wrong.end());
  // Matchable: in the street and in the database, and reconstructed.
  std::set<int> seen;
  for (const auto& [band_id, band_truth] : reconstruction.truth_of_band) {
    seen.insert(simulated.world.bands[band_truth.world_band].crossing);
  }
  for (int c : seen) {
    const sim::Crossing& crossing = simulated.world.crossings[c];
    if (!crossing.in_street || !crossing.in_db) continue;
    ++result->crossings_matchable;
    if (!crossing.repainted) ++result->consistent_crossings;
    if (matched.count(crossing.id) == 0) continue;
    ++result->crossings_matched;
    result->matched_crossings.push_back(crossing.id);
    ++(crossing.repainted ? result->repainted_matched
                          : result->consistent_matched);
  }
}

struct PoseErrors {
  std::vector<double> h, v, att;
  void Add(const Eigen::Isometry3d& T_true, const Eigen::Vector3d& centre,
           const Eigen::Matrix3d& R) {
    const Eigen::Vector3d d = centre - T_true.translation();
    h.push_back(d.head<2>().norm());
    v.push_back(std::abs(d.z()));
    const double c = std::clamp(
        0.5 * ((R.transpose() * T_true.linear()).trace() - 1.0), -1.0, 1.0);
    att.push_back(RadToDeg(std::acos(c)));
  }
};

// Per image: the camera pose adjusted (when usable) and measured against the
// truth, as score_results.py poses does.
void ScorePoses(const sim::SimulatedSurvey& simulated, const Survey& survey,
                const AdjustmentResult& adjusted, GeometryRunResult* result) {
  const Trajectory truth(simulated.motion.truth, simulated.frame);
  std::map<std::pair<int64_t, std::string>, const CameraPose*> after;
  for (const CameraPose& pose : adjusted.camera_poses) {
    after[{pose.exposure_id, pose.camera}] = &pose;
  }
  PoseErrors before_errors, after_errors;
  for (const ExposureImage& image : survey.exposures.images) {
    const RigCamera& camera = survey.rig.cameras[image.camera];
    Pose true_pose, measured_pose;
    if (!truth.InterpolatePose(image.time, &true_pose) ||
        !survey.trajectory.InterpolatePose(image.time, &measured_pose)) {
      continue;
    }
    const Eigen::Isometry3d T_true = true_pose.T_enu_body() * camera.T_body_cam;
    const Eigen::Isometry3d T_measured =
        measured_pose.T_enu_body() * camera.T_body_cam;
    before_errors.Add(T_true, T_measured.translation(), T_measured.linear());
    if (result->usable) {
      const auto it = after.find({image.exposure_id, camera.camera.name()});
      if (it == after.end()) continue;
      after_errors.Add(T_true, it->second->p_enu,
                       it->second->q_enu_cam.toRotationMatrix());
      result->h_after_by_image.push_back(
          {image.time, T_true.translation(), after_errors.h.back()});
    }
  }
  result->cameras = static_cast<int>(before_errors.h.size());
  result->h_before_m = Rms(before_errors.h);
  result->v_before_m = Rms(before_errors.v);
  result->att_before_deg = Rms(before_errors.att);
  if (!result->usable) return;
  result->h_after_m = Rms(after_errors.h);
  result->v_after_m = Rms(after_errors.v);
  result->att_after_deg = Rms(after_errors.att);
}

void Dump(const SimulationOptions& options,
          const SyntheticReconstruction& reconstruction,
          const std::vector<ReconstructedLinePoint>* lines,
          const MatchResult& match, const AdjustmentResult& adjusted,
          bool usable, bool images, const std::string& folder) {
  namespace fs = std::filesystem;
  SimulationOptions render = options;
  render.render_images = images;
  SimulateSurvey(render, (fs::path(folder) / "survey").string(), {});
  const fs::path results = fs::path(folder) / "results";
  fs::create_directories(results);
  const std::vector<std::string> comments = {
      "geometry sweep: synthetic reconstruction from the truth, seed " +
      std::to_string(options.seed)};
  WriteReconstructedBands(reconstruction.vertices, comments,
                          (results / kReconstructedBandsFile).string());
  if (lines != nullptr) {
    WriteReconstructedLines(*lines, comments,
                            (results / kReconstructedLinesFile).string());
  }
  WriteMatches(match.matches, comments, (results / kMatchesFile).string());
  WriteCrossingDecisions(match.decisions, comments,
                         (results / kCrossingDecisionsFile).string());
  if (usable) {
    WriteCameraPoses(adjusted.camera_poses, (results / kPosesFile).string());
    WriteTrajectorySamples(adjusted.corrected_samples,
                           (results / kTrajectoryCorrectedFile).string());
  }
}

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

// Median, 95th percentile and worst.
std::array<double, 3> Spread(const std::vector<double>& values) {
  if (values.empty()) return {0.0, 0.0, 0.0};
  return {Median(values), Percentile(values, 0.95),
          *std::max_element(values.begin(), values.end())};
}

std::string SpreadText(const std::array<double, 3>& s, int digits) {
  return Fixed(s[0], digits) + " / " + Fixed(s[1], digits) + " / " +
         Fixed(s[2], digits);
}

}  // namespace

std::string GeometrySweepOptions::Check() const {
  if (!(max_road_length_m >= 0.0)) {
    return "max_road_length_m = " + std::to_string(max_road_length_m) +
           ": must be >= 0";
  }
  if (!only_kind.empty()) {
    const auto kinds = RandomKinds();
    if (std::find(kinds.begin(), kinds.end(), only_kind) == kinds.end()) {
      std::string names;
      for (const std::string& k : kinds)
        names += (names.empty() ? "" : ", ") + k;
      return "only_kind = \"" + only_kind + "\": must be one of " + names;
    }
  }
  if (!(worse_position_m >= 0.0) || !(worse_attitude_deg >= 0.0)) {
    return "worse_position_m and worse_attitude_deg must be >= 0";
  }
  return "";
}

std::string GeometryRunResult::Line() const {
  std::ostringstream out;
  out << "seed " << seed << " [" << kind << " " << params << "] ";
  if (!error.empty()) {
    out << "ERROR " << error;
    return out.str();
  }
  out << bands_reconstructed << " band views; match " << wrong << " wrong/"
      << right << " right";
  if (rejected_by_adjustment > 0) {
    out << " (" << rejected_by_adjustment << " rejected by the adjustment)";
  }
  out << ", crossings " << crossings_matched << "/" << crossings_matchable
      << "; ";
  if (wrong_ids > 0) out << wrong_ids << " WRONG IDS; ";
  if (usable) {
    out << "H " << Fixed(100 * h_before_m, 1) << "->"
        << Fixed(100 * h_after_m, 1) << " V " << Fixed(100 * v_before_m, 1)
        << "->" << Fixed(100 * v_after_m, 1) << " cm, att "
        << Fixed(att_before_deg, 3) << "->" << Fixed(att_after_deg, 3)
        << " deg";
  } else {
    out << "exit 3 (" << message << "), H before " << Fixed(100 * h_before_m, 1)
        << " cm";
  }
  out << "; " << Fixed(seconds, 2) << " s";
  std::string flags;
  if (wrong > 0) {
    flags += " WRONG";
    if (wrong_on_cut_bands > 0) {
      flags += " (" + std::to_string(wrong_on_cut_bands) + " on cut bands)";
    }
    for (const std::string& c : wrong_crossings) flags += " " + c;
  }
  if (input_kept_stretches > 0) {
    flags += " INPUT-KEPT-x" + std::to_string(input_kept_stretches);
  }
  if (worse_position) flags += " WORSE-POSITION";
  if (worse_attitude) flags += " WORSE-ATTITUDE";
  if (UnusableWithControl()) flags += " EXIT3";
  if (crossings_matchable > 0 && crossings_matched < crossings_matchable) {
    flags += " UNMATCHED";
  }
  if (refusals > 0 && !flags.empty()) {
    flags += " (" + std::to_string(refusals) + "x: " + refusal + ")";
  }
  if (!flags.empty()) out << " <<" << flags;
  return out.str();
}

// One second registration pass as `zebrageo run` does it
// (pipeline/rematch_stage.h), with the truth's paint probe: the matches the
// adjustment rejected removed, then the pass. Adds the vertex matches the
// adjustment rejected to *rejected.
RematchSummary SecondPass(
    const Survey& survey, const SyntheticReconstruction& reconstruction,
    const std::vector<ReconstructedLinePoint>* lines,
    const std::vector<double>& line_control_times,
    const std::vector<double>& fitted_line_times, const TruthPaintProbe& probe,
    const AdjustmentOptions& adjustment, const AdjustmentResult& adjusted,
    AdjustmentData* data, std::vector<CrossingDecision>* decisions,
    int* rejected) {
  std::string rejected_list;  // RemoveRejectedMatches' message
  *rejected += RemoveRejectedMatches(adjusted, &data->matches, decisions,
                                     &rejected_list);
  const AdjustmentRecord record =
      AdjustmentRecordOf(*data, adjustment, adjusted, nullptr);
  AdjustedTrajectory trajectory;
  trajectory.record = &record;
  trajectory.trajectory = &adjusted.corrected_samples;
  trajectory.line_control_times = line_control_times;
  trajectory.fitted_line_times = fitted_line_times;
  trajectory.rejected_crossings = RejectedCrossings(adjusted);
  RunOptions options;
  options.lines = lines != nullptr;
  options.adjustment = adjustment;
  return RematchStep(survey, options, trajectory, reconstruction.vertices,
                     data->matches, *decisions, lines, {},
                     [&probe](int64_t exposure_id, const Pose& pose,
                              const BandCornersEnu& band,
                              const std::vector<BandCornersEnu>& seen) {
                       return probe.Classify(exposure_id, pose, band, seen);
                     });
}

// What `zebrageo run` does after its first adjustment (pipeline.cc): the
// second registration pass and, while it adds or removes matches, the
// adjustment and the pass again (three passes at most). Returns the
// observations it matched; *matches and *adjusted are what the user gets,
// *rejected the vertex matches the adjustments before a pass rejected.
int RematchAndAdjust(const Survey& survey,
                     const SyntheticReconstruction& reconstruction,
                     const std::vector<ReconstructedLinePoint>* lines,
                     std::vector<double> line_control_times,
                     std::vector<double> fitted_line_times,
                     const TruthPaintProbe& probe,
                     const AdjustmentOptions& adjustment, AdjustmentData* data,
                     std::vector<CrossingDecision> decisions,
                     AdjustmentResult* adjusted, int* rejected) {
  constexpr int kMaxPasses = 3;  // adjust_stage.cc's kMaxRematchPasses
  int added = 0;
  *rejected = 0;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    RematchSummary rematch = SecondPass(
        survey, reconstruction, lines, line_control_times, fitted_line_times,
        probe, adjustment, *adjusted, data, &decisions, rejected);
    if (rematch.added == 0 && rematch.dropped == 0) break;
    added += rematch.added;
    data->matches = std::move(rematch.matches);
    decisions = std::move(rematch.decisions);
    AdjustmentPass again = AdjustWithRoadLines(
        *data, data->Input(), adjustment, LineRegistrationOptions(), lines);
    *adjusted = std::move(again.result);
    line_control_times = std::move(again.line_control_times);
    fitted_line_times = std::move(again.fitted_line_times);
  }
  return added;
}

GeometryRunResult RunGeometrySurvey(uint64_t seed,
                                    const GeometrySweepOptions& options,
                                    const std::string& dump_folder) {
  const auto start = std::chrono::steady_clock::now();
  GeometryRunResult result;
  result.seed = seed;
  SimulationOptions simulation;
  simulation.seed = seed;
  RandomPresetLimits limits;
  limits.junctions = options.junctions;
  limits.avenues = options.avenues;
  if (options.max_road_length_m > 0.0) {
    limits.max_road_length_m =
        std::min(limits.max_road_length_m, options.max_road_length_m);
  }
  const std::string problem = options.preset.empty()
                                  ? DrawRandomOptions(seed, limits, &simulation)
                                  : ApplyPreset(options.preset, &simulation);
  result.kind = options.preset.empty() ? simulation.scenario : options.preset;
  if (!problem.empty()) {
    result.error = problem;
    return result;
  }
  for (const std::string& key_equals_value : options.sim_set) {
    const std::string bad = SetOption(key_equals_value, &simulation);
    if (!bad.empty()) {
      result.error = "sim_set " + key_equals_value + ": " + bad;
      return result;
    }
  }
  result.params = RandomOptionsBrief(simulation);
  if (!options.only_kind.empty() && options.only_kind != result.kind) {
    result.skipped = true;
    return result;
  }
  simulation.render_images = false;
  try {
    const sim::SimulatedSurvey simulated = sim::MakeSimulatedSurvey(simulation);
    const Survey survey = sim::ToSurvey(simulated, dump_folder);
    const ReconstructionModel model = ReconstructionModel::Random(seed);
    const SyntheticReconstruction reconstruction =
        SynthesiseReconstruction(simulated, model, seed);
    result.params += "; " + model.Brief();
    result.bands_reconstructed = reconstruction.views_reconstructed;

    MatchInput input;
    int incomplete = 0;
    input.observations = BuildObservations(
        survey, reconstruction.vertices, kReconstructedBandsFile, &incomplete);
    input.exposures = ExposurePoses(survey);
    const RoadmarkIndex index(survey.roadmarks, survey.frame);
    input.index = &index;
    input.rig = &survey.rig;
    const TruthPaintProbe probe(simulated, model, seed);
    input.paint_probe = [&probe](int64_t exposure_id, const Pose& pose,
                                 const BandCornersEnu& band,
                                 const std::vector<BandCornersEnu>& seen) {
      return probe.Classify(exposure_id, pose, band, seen);
    };
    const MatchResult match = MatchBands(input, MatchOptions());
    std::map<std::string, int> reasons;
    for (const CrossingDecision& d : match.decisions) {
      if (d.decision != Decision::kMatched) ++reasons[d.reason];
    }
    for (const auto& [reason, count] : reasons) {
      if (count > result.refusals) {
        result.refusal = reason;
        result.refusals = count;
      }
    }

    std::vector<ReconstructedLinePoint> line_points;
    if (options.lines) {
      line_points = SynthesiseLinePoints(simulated, model, seed);
    }
    const std::vector<ReconstructedLinePoint>* lines =
        options.lines ? &line_points : nullptr;
    result.line_points = static_cast<int>(line_points.size());
    AdjustmentOptions adjustment;
    adjustment.solver.num_threads = 1;
    adjustment.log_warnings = false;
    if (!options.outage_readings) {
      adjustment.never_worse.outage_min_jump_m = 0.0;
    }
    if (!options.guard) adjustment.never_worse.guard_sigmas = 0.0;
    AdjustmentData data =
        AdjustmentDataOf(survey, reconstruction.vertices, match.matches);
    AdjustmentPass first = AdjustWithRoadLines(
        data, data.Input(), adjustment, LineRegistrationOptions(), lines);
    AdjustmentResult adjusted = std::move(first.result);
    int rejected_first = 0;
    if (options.rematch && adjusted.summary.IsUsable()) {
      result.rematched = RematchAndAdjust(
          survey, reconstruction, lines, first.line_control_times,
          first.fitted_line_times, probe, adjustment, &data, match.decisions,
          &adjusted, &rejected_first);
    }
    const std::vector<VertexMatch>& matches = data.matches;
    // Scored as the user gets them: matches.csv keeps only the vertices
    // that became control (RemoveRejectedMatches).
    const std::vector<VertexMatch> kept =
        MatchesKeptAsControl(matches, adjusted);
    result.rejected_by_adjustment =
        rejected_first + static_cast<int>(matches.size() - kept.size());
    ScoreMatches(simulated, reconstruction, TruePoses(simulated), kept,
                 &result);
    result.usable = adjusted.summary.IsUsable();
    if (!result.usable) result.message = adjusted.summary.message;
    result.input_kept_stretches =
        static_cast<int>(adjusted.summary.kept_input.size());
    ScorePoses(simulated, survey, adjusted, &result);
    if (result.usable) {
      result.worse_position = std::hypot(result.h_after_m, result.v_after_m) >
                              std::hypot(result.h_before_m, result.v_before_m) +
                                  options.worse_position_m;
      result.worse_attitude =
          result.att_after_deg >
          result.att_before_deg + options.worse_attitude_deg;
    }
    if (!dump_folder.empty()) {
      Dump(simulation, reconstruction, lines, match, adjusted, result.usable,
           options.dump_images, dump_folder);
      if (result.usable) {
        // The adjustment's record, for `zebrageo report` on the dump.
        WriteAdjustmentRecord(
            AdjustmentRecordOf(data, adjustment, adjusted, nullptr),
            (std::filesystem::path(dump_folder) / "results" /
             kAdjustmentJsonFile)
                .string());
      }
    }
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

std::vector<GeometryRunResult> RunGeometrySweep(
    uint64_t first, uint64_t last, int threads,
    const GeometrySweepOptions& options,
    const std::function<void(const GeometryRunResult&)>& done) {
  std::vector<GeometryRunResult> results(last >= first ? last - first + 1 : 0);
  std::atomic<size_t> next{0};
  std::mutex mutex;
  auto work = [&]() {
    while (true) {
      const size_t index = next++;
      if (index >= results.size()) break;
      GeometryRunResult result = RunGeometrySurvey(first + index, options);
      std::lock_guard<std::mutex> lock(mutex);
      results[index] = result;
      if (done && !result.skipped) done(results[index]);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back(work);
  for (std::thread& t : pool) t.join();
  return results;
}

GeometrySweepSummary Summarise(const std::vector<GeometryRunResult>& results) {
  GeometrySweepSummary s;
  std::vector<double> h_after, v_after, att_after, h_before, v_before,
      att_before;
  for (const GeometryRunResult& r : results) {
    if (r.skipped) continue;
    ++s.surveys;
    s.seconds += r.seconds;
    if (!r.error.empty()) {
      ++s.errors;
      continue;
    }
    s.wrong_matches += r.wrong;
    s.wrong_on_cut_bands += r.wrong_on_cut_bands;
    s.wrong_ids += r.wrong_ids;
    s.ids_checked += r.ids_checked;
    s.surveys_with_wrong_matches += r.wrong > 0 ? 1 : 0;
    s.right_matches += r.right;
    s.crossings_matchable += r.crossings_matchable;
    s.crossings_matched += r.crossings_matched;
    s.consistent_crossings += r.consistent_crossings;
    s.consistent_matched += r.consistent_matched;
    s.repainted_matched += r.repainted_matched;
    s.worse_position += r.worse_position ? 1 : 0;
    s.worse_attitude += r.worse_attitude ? 1 : 0;
    s.input_kept += r.input_kept_stretches > 0 ? 1 : 0;
    s.unusable += r.usable ? 0 : 1;
    s.unusable_with_control += r.UnusableWithControl() ? 1 : 0;
    std::array<int, 7>& kind = s.by_kind[r.kind];
    kind[0] += 1;
    kind[1] += r.wrong;
    kind[2] += r.worse_position ? 1 : 0;
    kind[3] += r.worse_attitude ? 1 : 0;
    kind[4] += r.UnusableWithControl() ? 1 : 0;
    kind[5] += r.crossings_matched;
    kind[6] += r.crossings_matchable;
    h_before.push_back(100 * r.h_before_m);
    v_before.push_back(100 * r.v_before_m);
    att_before.push_back(r.att_before_deg);
    if (!r.usable) continue;
    h_after.push_back(100 * r.h_after_m);
    v_after.push_back(100 * r.v_after_m);
    att_after.push_back(r.att_after_deg);
  }
  s.h_after_cm = Spread(h_after);
  s.v_after_cm = Spread(v_after);
  s.att_after_deg = Spread(att_after);
  s.h_before_cm = Spread(h_before);
  s.v_before_cm = Spread(v_before);
  s.att_before_deg = Spread(att_before);
  return s;
}

std::vector<std::string> GeometrySweepSummary::Failures() const {
  std::vector<std::string> failures;
  if (errors > 0) {
    failures.push_back(std::to_string(errors) + " surveys threw an exception");
  }
  if (wrong_matches > 0) {
    failures.push_back(
        std::to_string(wrong_matches) + " wrong vertex matches in " +
        std::to_string(surveys_with_wrong_matches) + " surveys (must be 0)");
  }
  if (worse_position > 0) {
    failures.push_back(std::to_string(worse_position) +
                       " surveys worse than their input in position (must "
                       "be 0)");
  }
  if (worse_attitude > 0) {
    failures.push_back(std::to_string(worse_attitude) +
                       " surveys worse than their input in attitude (must "
                       "be 0)");
  }
  if (unusable_with_control > 0) {
    failures.push_back(std::to_string(unusable_with_control) +
                       " unusable adjustments (exit 3) while a consistent set "
                       "of crossings exists (must be 0)");
  }
  if (MatchedShare() < 0.9) {
    failures.push_back("crossings matched " + Fixed(100.0 * MatchedShare(), 1) +
                       " % (" + std::to_string(consistent_matched) + "/" +
                       std::to_string(consistent_crossings) +
                       ") of the matchable not repainted (must be >= 90 %)");
  }
  return failures;
}

std::string GeometrySweepSummary::Report() const {
  std::ostringstream out;
  out << surveys << " surveys, " << Fixed(seconds, 1) << " s of CPU ("
      << Fixed(surveys > 0 ? seconds / surveys : 0.0, 2) << " s each)\n"
      << "  wrong vertex matches " << wrong_matches << " (in "
      << surveys_with_wrong_matches << " surveys; " << wrong_on_cut_bands
      << " on bands cut short), right " << right_matches << "\n"
      << "  matched band ids against the truth band: " << wrong_ids
      << " wrong of " << ids_checked << "\n"
      << "  crossings matched " << Fixed(100.0 * MatchedShare(), 1) << " % ("
      << consistent_matched << "/" << consistent_crossings
      << ") of the matchable not repainted; of all matchable "
      << Fixed(100.0 * AllMatchedShare(), 1) << " % (" << crossings_matched
      << "/" << crossings_matchable << "); repainted ones kept as control "
      << repainted_matched << " of "
      << crossings_matchable - consistent_crossings << "\n"
      << "  worse than the input: position " << worse_position << ", attitude "
      << worse_attitude << "; the input kept somewhere by the guard in "
      << input_kept << " surveys\n"
      << "  unusable adjustments (exit 3) " << unusable << ", of which "
      << unusable_with_control << " with a consistent set of crossings\n"
      << "  errors (exceptions) " << errors << "\n"
      << "  median / p95 / worst over usable runs, after (before, all runs):\n"
      << "    H   " << SpreadText(h_after_cm, 1) << " cm ("
      << SpreadText(h_before_cm, 1) << ")\n"
      << "    V   " << SpreadText(v_after_cm, 1) << " cm ("
      << SpreadText(v_before_cm, 1) << ")\n"
      << "    att " << SpreadText(att_after_deg, 3) << " deg ("
      << SpreadText(att_before_deg, 3) << ")\n"
      << "  by kind: surveys, wrong matches, worse position, worse attitude, "
         "exit 3 with control, crossings matched\n";
  for (const auto& [kind, k] : by_kind) {
    out << "    " << kind << ": " << k[0] << ", " << k[1] << ", " << k[2]
        << ", " << k[3] << ", " << k[4] << ", " << k[5] << "/" << k[6] << "\n";
  }
  return out.str();
}

}  // namespace zebrageo::support
