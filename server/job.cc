#include "server/job.h"

#include <array>
#include <cmath>

namespace zebrageo {
namespace {

using nlohmann::json;

constexpr std::array<JobState, 5> kStates = {
    JobState::kQueued, JobState::kRunning, JobState::kDone, JobState::kFailed,
    JobState::kCancelled};

// Seconds since the epoch as JSON: null for "not yet".
json TimeOrNull(double seconds) {
  return seconds > 0.0 ? json(seconds) : json(nullptr);
}

}  // namespace

const char* JobStateName(JobState state) {
  switch (state) {
    case JobState::kQueued:
      return "queued";
    case JobState::kRunning:
      return "running";
    case JobState::kDone:
      return "done";
    case JobState::kFailed:
      return "failed";
    case JobState::kCancelled:
      return "cancelled";
  }
  return "failed";
}

std::optional<JobState> JobStateFromName(const std::string& name) {
  for (JobState state : kStates) {
    if (name == JobStateName(state)) return state;
  }
  return std::nullopt;
}

bool IsFinal(JobState state) {
  return state == JobState::kDone || state == JobState::kFailed ||
         state == JobState::kCancelled;
}

json JobToJson(const Job& job) {
  json out;
  out["id"] = job.id;
  out["name"] = job.name;
  out["state"] = JobStateName(job.state);
  out["source"] = job.source == JobSource::kUpload ? "upload" : "folder";
  if (job.source == JobSource::kFolder) out["folder"] = job.folder;
  out["options"] = job.options;
  out["webhook"] = job.webhook.empty() ? json(nullptr) : json(job.webhook);
  out["stage"] = job.stage.empty() ? json(nullptr) : json(job.stage);
  out["step"] = job.step.empty() ? json(nullptr) : json(job.step);
  out["progress"] = std::round(job.progress * 1000.0) / 1000.0;
  out["created_at"] = job.created_at;
  out["started_at"] = TimeOrNull(job.started_at);
  out["finished_at"] = TimeOrNull(job.finished_at);
  double elapsed = 0.0;
  if (job.started_at > 0.0 && job.finished_at > 0.0) {
    elapsed = job.finished_at - job.started_at;
  }
  out["processing_seconds"] = elapsed > 0.0 ? json(elapsed) : json(nullptr);
  out["attempts"] = job.attempts;
  out["exit_code"] = job.exit_code >= 0 ? json(job.exit_code) : json(nullptr);
  out["signal"] = job.signal > 0 ? json(job.signal) : json(nullptr);
  out["error"] = job.error.empty() ? json(nullptr) : json(job.error);
  out["warnings"] = job.warnings;
  out["timings"] = job.timings;
  out["cancel_requested"] = job.cancel_requested;
  const std::string base = "/jobs/" + job.id;
  out["links"] = {{"self", base},
                  {"log", base + "/log"},
                  {"results", base + "/results"},
                  {"results_zip", base + "/results.zip"},
                  {"report", base + "/report"}};
  return out;
}

}  // namespace zebrageo
