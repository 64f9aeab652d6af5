// A job of `zebrageo serve`: one survey through `zebrageo run`, as the job
// store keeps it and the HTTP API shows it.
//
// States, as NodeODM's tasks have them: queued -> running -> done | failed
// | cancelled. A running job whose server died is running still in the
// store; the restarted server resumes it (the resumable `run` continues
// after its last complete stage).
#ifndef ZEBRAGEO_SERVER_JOB_H_
#define ZEBRAGEO_SERVER_JOB_H_

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace zebrageo {

enum class JobState { kQueued, kRunning, kDone, kFailed, kCancelled };

// "queued", "running", "done", "failed", "cancelled".
const char* JobStateName(JobState state);
std::optional<JobState> JobStateFromName(const std::string& name);
// done, failed or cancelled: the job's child has ended for good.
bool IsFinal(JobState state);

// Where the survey came from.
enum class JobSource { kUpload, kFolder };

struct Job {
  std::string id;  // 16 lowercase hex digits, random
  std::string name;
  JobState state = JobState::kQueued;
  JobSource source = JobSource::kUpload;
  // The survey folder, absolute: the upload's extraction, or the folder
  // under the data root that the request named (`folder`, as named).
  std::string survey_path;
  std::string folder;
  nlohmann::json options = nlohmann::json::object();  // RunOptions JSON
  std::string webhook;                                // "" for none
  // Progress of the running child: the stage ("reconstruct", "match",
  // "adjust", "report"), its step and the fraction of the whole run done.
  std::string stage;
  std::string step;
  double progress = 0.0;
  // Seconds since the epoch (UTC); 0 when not yet.
  double created_at = 0.0;
  double started_at = 0.0;
  double finished_at = 0.0;
  int attempts = 0;    // children started (a resumed job has more than 1)
  int exit_code = -1;  // of the last child; -1 while none ended
  int signal = 0;      // that killed the last child, or 0
  std::string error;   // the CLI's words ("zebrageo: error: ..." stripped)
  nlohmann::json warnings = nlohmann::json::array();
  nlohmann::json timings = nlohmann::json::object();  // report.json timings_s
  bool cancel_requested = false;
  bool webhook_pending = false;  // ended, its webhook not yet delivered
  long pid = 0;                  // of the running child, 0 when none
};

// The job as the API shows it (GET /jobs/{id}; the webhook's body).
nlohmann::json JobToJson(const Job& job);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_JOB_H_
