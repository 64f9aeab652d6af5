#include "pipeline/adjust_stage.h"

#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "geodata/colmap_export.h"
#include "pipeline/adjust_outputs.h"
#include "pipeline/adjustment_pass.h"
#include "pipeline/diagnosis.h"
#include "pipeline/exit_codes.h"
#include "pipeline/mount_attitude_check.h"
#include "pipeline/rematch_stage.h"
#include "survey/atomic_file.h"
#include "survey/image_io.h"
#include "survey/input_error.h"
#include "survey/output_crs.h"
#include "survey/results.h"
#include "survey/results_adjustment.h"
#include "survey/results_lines.h"
#include "survey/results_survey.h"
#include "tiepoints/tie_points.h"

namespace zebrageo {
namespace {

constexpr int kMaxRematchPasses = 3;

// The tie tracks of the survey's images, once for every adjustment.
struct TiePoints {
  bool used = false;
  std::vector<TieTrack> tracks;
  TiePointSummary summary;
};

// Step "tie points": with RunOptions::tie_points and images on disk.
TiePoints MatchTiePoints(const AdjustmentData& data, const RunOptions& options,
                         const ProgressListener& progress,
                         const CancellationToken& cancel) {
  TiePoints ties;
  ties.used =
      options.tie_points &&
      data.missing_images < static_cast<int>(data.exposures.images.size());
  if (!ties.used) return ties;
  StepProgress step(progress, "tie points");
  ties.tracks = BuildTieTracks(options.tie_point_matching, data.survey_folder,
                               data.rig, data.trajectory, data.exposures,
                               &ties.summary, step.Callback(), cancel);
  step.Finish();
  return ties;
}

// What the stage carries from step to step and writes at its end.
struct AdjustState {
  // The control: the match stage's, less what the adjustment rejected,
  // with what the second pass added.
  std::vector<VertexMatch> matches;
  std::vector<CrossingDecision> decisions;
  // The comments of matches.csv and crossing_decisions.csv once a step
  // changed them (else the match stage's files stand).
  std::optional<std::vector<std::string>> matches_comments;
  std::optional<std::vector<std::string>> decisions_comments;
  // The last adjustment: its data (the control it was given), result and
  // record, and the last registration of the road lines.
  AdjustmentData data;
  AdjustmentPass pass;
  AdjustmentRecord record;
  std::optional<LineRegistration> lines;
  std::vector<std::string> warnings;
};

// The images of the exposures the reconstruction skipped that cannot be
// read (SURVEY_FORMAT.md: only they may lack a pose): the image its reason
// names, or whose header does not read. The other camera of an exposure
// whose right image is missing keeps its pose.
void DropUnreadableImages(const Survey& survey, StageResults* results,
                          AdjustmentResult* result) {
  std::map<int64_t, std::string> reasons;
  for (const SkippedExposure& s : results->SkippedExposures()) {
    reasons[s.exposure_id] = s.reason;
  }
  std::set<std::pair<int64_t, std::string>> unreadable;
  for (const ExposureImage& image : survey.exposures.images) {
    const auto reason = reasons.find(image.exposure_id);
    if (reason == reasons.end()) continue;
    bool readable = reason->second.find(image.image) == std::string::npos;
    if (readable) {
      try {
        ReadImageHeader(
            (std::filesystem::path(survey.folder) / image.image).string(),
            image.image);
      } catch (const InputError&) {
        readable = false;
      }
    }
    if (!readable) {
      unreadable.insert(
          {image.exposure_id, survey.rig.cameras[image.camera].camera.name()});
    }
  }
  auto& poses = result->camera_poses;
  poses.erase(
      std::remove_if(
          poses.begin(), poses.end(),
          [&unreadable](const CameraPose& pose) {
            return unreadable.count({pose.exposure_id, pose.camera}) > 0;
          }),
      poses.end());
}

// "adjust needs a usable result": the solver's message names no input, so
// the survey's warnings (gaps, rates, with their lines and times) follow.
[[noreturn]] void FailUnusable(const Survey& survey,
                               const AdjustmentSummary& summary) {
  std::string context;
  for (size_t i = 0; i < survey.warnings.size() && i < 3; ++i) {
    context +=
        (i == 0 ? "; the survey's warnings: " : "; ") + survey.warnings[i];
  }
  throw StageFailedError("adjust: " + summary.message +
                         "; no results were written" + context);
}

// Step "adjust" on the control so far, then "keep control".
void Adjust(const Survey& survey, StageResults* results, const TiePoints& ties,
            const RunOptions& options, const ProgressListener& progress,
            const CancellationToken& cancel, AdjustState* state) {
  AdjustmentData data =
      AdjustmentDataOf(survey, results->Vertices(), state->matches);
  // The survey's warnings first: adjustment.json and the report list them.
  data.warnings.insert(data.warnings.begin(), survey.warnings.begin(),
                       survey.warnings.end());
  LOG(INFO) << "adjust: " << data.vertices.size() << " reconstructed vertices, "
            << data.matches.size() << " matches, "
            << data.exposures.exposures.size() << " exposures";
  AdjustmentInput input = data.Input();
  if (ties.used) input.tie_tracks = &ties.tracks;
  AdjustmentPass pass = AdjustWithRoadLines(
      data, input, options.adjustment, options.line_registration,
      options.lines ? results->LinePoints() : nullptr, progress, cancel);
  if (!pass.result.summary.IsUsable())
    FailUnusable(survey, pass.result.summary);
  state->warnings = data.warnings;
  if (pass.lines) {
    state->warnings.insert(state->warnings.end(), pass.lines->warnings.begin(),
                           pass.lines->warnings.end());
    if (pass.lines->record) state->lines = pass.lines;
  }
  DropUnreadableImages(survey, results, &pass.result);
  state->record = AdjustmentRecordOf(data, options.adjustment, pass.result,
                                     ties.used ? &ties.summary : nullptr);
  std::string crossings;
  const int removed = RemoveRejectedMatches(pass.result, &state->matches,
                                            &state->decisions, &crossings);
  if (removed > 0) {
    state->matches_comments = {
        "zebrageo adjust removed " + std::to_string(removed) +
        " vertex matches the adjustment rejected (crossings " + crossings +
        "; gcp_residuals.csv, report.json warnings)"};
    // Without decisions (results of an older version) there is nothing to
    // rewrite.
    if (!state->decisions.empty()) {
      state->decisions_comments = {"zebrageo match, then adjust"};
    }
    LOG(INFO) << "adjust: " << removed
              << " vertex matches rejected by the adjustment removed from "
              << kMatchesFile;
  }
  LOG(INFO) << "adjust: " << pass.result.summary.BriefReport();
  state->data = std::move(data);
  state->pass = std::move(pass);
}

// Step "rematch": the second registration pass on the last adjustment; true
// when it changed the control.
bool Rematch(const Survey& survey, StageResults* results,
             const RunOptions& options, const CancellationToken& cancel,
             AdjustState* state, std::vector<std::string>* refusals) {
  AdjustedTrajectory adjusted;
  adjusted.record = &state->record;
  adjusted.trajectory = &state->pass.result.corrected_samples;
  adjusted.line_control_times = state->pass.line_control_times;
  adjusted.fitted_line_times = state->pass.fitted_line_times;
  adjusted.rejected_crossings = RejectedCrossings(state->pass.result);
  RematchSummary rematch =
      RematchStep(survey, options, adjusted, results->Vertices(),
                  state->matches, state->decisions,
                  options.lines ? results->LinePoints() : nullptr, cancel);
  LOG(INFO) << rematch.message;
  // Logged as a warning, so listed in report.json too.
  if (rematch.disagreements > 0) refusals->push_back(rematch.message);
  if (rematch.added == 0 && rematch.dropped == 0) return false;
  state->matches = std::move(rematch.matches);
  state->decisions = std::move(rematch.decisions);
  state->matches_comments = {"zebrageo run: " + rematch.message};
  state->decisions_comments = state->matches_comments;
  return true;
}

// Steps "adjust" and "rematch" on the match stage's control. The last
// adjustment logs its warnings when `log_warnings`.
AdjustState AdjustAndRematch(const Survey& survey, StageResults* results,
                             const TiePoints& ties, const RunOptions& options,
                             bool log_warnings,
                             const ProgressListener& progress,
                             const CancellationToken& cancel,
                             std::vector<std::string>* refusals) {
  AdjustState state;
  state.matches = results->Matches();
  state.decisions = results->Decisions();
  // With the second pass, an adjustment before it may not be the result:
  // its warnings go to the report (and stderr) only if it is.
  RunOptions trial = options;
  trial.adjustment.log_warnings = false;
  RunOptions last = options;
  last.adjustment.log_warnings = log_warnings;
  Adjust(survey, results, ties, options.rematch ? trial : last, progress,
         cancel, &state);
  for (int pass = 0; options.rematch && pass < kMaxRematchPasses; ++pass) {
    cancel.ThrowIfCancelled();
    if (!Rematch(survey, results, options, cancel, &state, refusals)) break;
    const bool again = pass + 1 < kMaxRematchPasses;
    Adjust(survey, results, ties, again ? trial : last, progress, cancel,
           &state);
  }
  return state;
}

// The mount-like offset of the corrected body attitude against the input's
// (mount_attitude_check.h).
AttitudeOffset AttitudeOffsetOf(const Survey& survey,
                                const MountAttitudeOptions& options,
                                const AdjustState& state) {
  return MountLikeAttitudeOffset(options, survey.trajectory.samples(),
                                 survey.trajectory.poses(),
                                 state.pass.result.corrected_poses);
}

// The boresight check's second look (mount_attitude_check.h): where the
// adjustment turned the body by one rotation beyond the INS's sd, it is
// repeated with the rig's boresight calibrated, and where that still
// turns it, with the input's attitude held. Replaces *state with the
// result kept; returns the diagnosis ("" when the first stands).
std::string SecondLookAtTheMount(const Survey& survey, StageResults* results,
                                 const TiePoints& ties,
                                 const RunOptions& options,
                                 const ProgressListener& progress,
                                 const CancellationToken& cancel,
                                 AdjustState* state,
                                 std::vector<std::string>* refusals) {
  const MountAttitudeOptions& mount = options.boresight.attitude;
  const AttitudeOffset offset = AttitudeOffsetOf(survey, mount, *state);
  LOG(INFO) << "mount check after the adjustment: body attitude against the "
               "input's: roll, pitch, yaw "
            << RadToDeg(offset.mean_rad.x()) << ", "
            << RadToDeg(offset.mean_rad.y()) << ", "
            << RadToDeg(offset.mean_rad.z())
            << " deg; heading off the course over ground (median over "
            << offset.course_chords << " chords): the input's "
            << RadToDeg(offset.input_course_departure_rad) << ", the corrected "
            << RadToDeg(offset.corrected_course_departure_rad) << " deg";
  if (!offset.found) return "";
  const std::string rig_file = survey.manifest.rig;
  std::string text =
      "diagnosis: the adjustment turned the vehicle's attitude from the "
      "trajectory's by one rotation for the whole survey, beyond the sd the "
      "trajectory states: " +
      offset.Describe() + "; a mount rotation that " + rig_file +
      " does not state turns the cameras so";
  RunOptions calibrating = options;
  calibrating.adjustment.rig_calibration.self_calibrate_rig = true;
  calibrating.adjustment.rig_calibration.boresight_sigma_rad =
      mount.boresight_sigma_rad;
  std::vector<std::string> calibrated_refusals;
  AdjustState calibrated =
      AdjustAndRematch(survey, results, ties, calibrating, false, progress,
                       cancel, &calibrated_refusals);
  const AttitudeOffset left = AttitudeOffsetOf(survey, mount, calibrated);
  if (!left.found) {
    const std::vector<Eigen::Isometry3d>& mounts =
        calibrated.pass.result.T_body_cam;
    double change_deg = 0.0;
    for (size_t c = 0; c < mounts.size() && c < survey.rig.cameras.size();
         ++c) {
      const Eigen::AngleAxisd turn(
          mounts[c].linear() *
          survey.rig.cameras[c].T_body_cam.linear().transpose());
      change_deg = std::max(change_deg, RadToDeg(turn.angle()));
    }
    std::ostringstream more;
    more.precision(3);
    more << std::fixed
         << "; the run adjusted again with the rig's boresight calibrated "
            "(prior "
         << RadToDeg(mount.boresight_sigma_rad)
         << " deg): the cameras turned by up to " << change_deg
         << " deg and the vehicle's attitude kept the trajectory's "
            "(adjustment.json rig); state the mount angles in "
         << rig_file << " if they are known";
    text += more.str();
    *state = std::move(calibrated);
    *refusals = std::move(calibrated_refusals);
  } else {
    RunOptions holding = options;
    // No attitude correction is significant: every axis keeps the input's.
    holding.adjustment.model.attitude_significance = 1e9;
    std::vector<std::string> held_refusals;
    *state = AdjustAndRematch(survey, results, ties, holding, false, progress,
                              cancel, &held_refusals);
    *refusals = std::move(held_refusals);
    text += "; calibrating the rig's boresight did not explain it (" +
            left.Describe() +
            "), so the run keeps the trajectory's attitude; state the mount "
            "angles in " +
            rig_file;
  }
  LOG(WARNING) << text;
  return text;
}

// Step "write": every file of the stage, once.
void WriteAdjustStage(const Survey& survey, const AdjustState& state,
                      const std::string& folder) {
  const std::unique_ptr<OutputCrs> crs = OutputCrs::Of(survey);
  auto path = [&folder](const char* name) { return folder + "/" + name; };
  RemoveStaleTemporaries(folder);
  const AdjustmentResult& result = state.pass.result;
  WriteColmapModel(ColmapModelOf(state.data, result), path(kColmapFolder));
  WriteGcpResiduals(GcpResidualsOf(result.control_points),
                    path(kGcpResidualsFile), crs.get());
  WriteAdjustedBands(result.bands, path(kBandsGeoJsonFile), crs.get());
  WriteAdjustmentRecord(state.record, path(kAdjustmentJsonFile));
  if (state.lines) {
    WriteLineMatches(state.lines->rows, path(kLineMatchesFile));
    WriteLineControl(*state.lines->record, path(kLineControlFile));
  }
  if (state.matches_comments) {
    WriteMatches(state.matches,
                 WithSurveyIdentity(survey.exposures, *state.matches_comments),
                 path(kMatchesFile), crs.get());
  }
  if (state.decisions_comments) {
    WriteCrossingDecisions(
        state.decisions,
        WithSurveyIdentity(survey.exposures, *state.decisions_comments),
        path(kCrossingDecisionsFile));
  }
  // The trajectory and the poses last: their presence means the stage
  // finished.
  WriteTrajectorySamples(result.corrected_samples,
                         path(kTrajectoryCorrectedFile), crs.get());
  WriteCameraPoses(result.camera_poses, path(kPosesFile), crs.get());
}

// The adjustment's correction at each crossing it kept as control or
// check (its middle observation time), for the diagnosis of a database
// offset (pipeline/diagnosis.h).
std::vector<CrossingCorrection> CrossingCorrections(
    const Survey& survey, const AdjustmentResult& result) {
  std::vector<CrossingCorrection> crossings;
  const std::vector<TrajectorySample>& input = survey.trajectory.samples();
  if (result.corrected_samples.size() != input.size()) return crossings;
  for (const GuardVerdict& verdict : result.summary.guard_verdicts) {
    if (!verdict.used) continue;
    const double time = 0.5 * (verdict.first_time_s + verdict.last_time_s);
    const auto at = std::lower_bound(
        input.begin(), input.end(), time,
        [](const TrajectorySample& s, double t) { return s.time < t; });
    const size_t i = std::min<size_t>(at - input.begin(), input.size() - 1);
    CrossingCorrection crossing;
    crossing.crossing_id = verdict.id;
    crossing.time_s = time;
    crossing.correction_enu =
        survey.frame.EnuFromGeodetic(result.corrected_samples[i].position) -
        survey.trajectory.poses()[i].p_enu;
    crossing.stated_sd_enu = input[i].sd_enu_m;
    crossings.push_back(crossing);
  }
  return crossings;
}

}  // namespace

std::vector<std::string> RunAdjustStage(const Survey& survey,
                                        StageResults* results,
                                        const RunOptions& options,
                                        const ProgressListener& progress,
                                        const CancellationToken& cancel) {
  // The output CRS is checked before anything runs.
  OutputCrs::Of(survey);
  const TiePoints ties = MatchTiePoints(AdjustmentDataOf(survey, {}, {}),
                                        options, progress, cancel);
  std::vector<std::string> refusals;
  const MountAttitudeOptions& mount = options.boresight.attitude;
  // The adjustment's warnings are logged once, for the result kept.
  const bool second_look =
      mount.enabled && !options.adjustment.rig_calibration.self_calibrate_rig;
  AdjustState state =
      AdjustAndRematch(survey, results, ties, options, !second_look, progress,
                       cancel, &refusals);
  std::string diagnosis;
  if (second_look) {
    diagnosis = SecondLookAtTheMount(survey, results, ties, options, progress,
                                     cancel, &state, &refusals);
    for (const std::string& warning : state.pass.result.summary.warnings) {
      LOG(WARNING) << warning;
    }
  }
  cancel.ThrowIfCancelled();
  WriteAdjustStage(survey, state, results->folder());
  results->SetMatches(state.matches, state.decisions);
  results->SetAdjustment(state.pass.result.corrected_samples, state.record);
  std::vector<std::string> warnings = state.warnings;
  warnings.insert(warnings.end(), refusals.begin(), refusals.end());
  if (!diagnosis.empty()) warnings.insert(warnings.begin(), diagnosis);
  const std::optional<Diagnosis> offset = DiagnoseCommonOffset(
      CrossingCorrections(survey, state.pass.result), survey.manifest.roadmarks,
      survey.manifest.trajectory, DiagnosisOptions());
  if (offset) {
    LOG(WARNING) << offset->message;
    warnings.push_back(offset->message);
  }
  return warnings;
}

}  // namespace zebrageo
