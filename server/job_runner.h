// The workers of `zebrageo serve`: K slots, each running one job at a time
// as a `zebrageo run` child (server/child_process.h), the oldest queued job
// first; cancellation; the restart of jobs a dead server left running; the
// webhook when a job ends; the figures of GET /metrics.
//
// A cancel sends SIGTERM to the child's process group, then SIGKILL after a
// grace period. Every results file is written atomically (survey/
// atomic_file.h), so a killed run leaves complete stage outputs and stray
// temporaries only, which the runner removes: nothing half-written. When
// the server stops (SIGTERM) or dies, its running jobs stay "running" in
// the store; the next server queues them again first, and the resumable
// `run` continues after their last complete stage, so their results are
// those of an uninterrupted run.
#ifndef ZEBRAGEO_SERVER_JOB_RUNNER_H_
#define ZEBRAGEO_SERVER_JOB_RUNNER_H_

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/job.h"
#include "server/job_store.h"
#include "server/metrics.h"
#include "server/run_invocation.h"
#include "server/webhook.h"

namespace zebrageo {

struct RunnerOptions {
  std::string data_root;   // canonical
  std::string executable;  // the zebrageo binary its children run
  int workers = 2;
  double cancel_grace_s = 10.0;  // SIGTERM, then SIGKILL after this
  long job_memory_limit_mb = 0;  // RLIMIT_AS of each child; 0: none
  WebhookOptions webhook;
};

class JobRunner {
 public:
  JobRunner(JobStore* store, Metrics* metrics, RunnerOptions options);
  ~JobRunner();
  JobRunner(const JobRunner&) = delete;
  JobRunner& operator=(const JobRunner&) = delete;

  // Re-queues the jobs a previous server left running (after making sure
  // no child of it still runs), resends pending webhooks, starts the
  // workers.
  void Start();
  // Stops the workers: running children get SIGTERM (SIGKILL after the
  // grace period) and their jobs stay running in the store.
  void Stop();
  // A job was queued.
  void Wake();

  // The job's folder (jobs/<id> under the data root).
  JobFiles FilesOf(const std::string& id) const;
  // The stored job with the live progress of its child; nullopt if unknown.
  std::optional<Job> Get(const std::string& id) const;
  std::vector<Job> List(std::optional<JobState> state) const;
  // Cancels a queued or running job (a final one is left as it is).
  std::optional<Job> Cancel(const std::string& id);
  enum class DeleteOutcome { kDeleted, kUnknown, kStillRunning };
  // Cancels the job, waits for its child to end, removes its folder and
  // its row. A folder job's survey (the user's) is never touched.
  DeleteOutcome Delete(const std::string& id);
  // Sets the gauges of GET /metrics (jobs by state, queue, busy workers).
  void UpdateGauges();

 private:
  struct Running {
    pid_t pid = 0;
    bool term_sent = false;
    std::chrono::steady_clock::time_point term_time;
    RunProgress progress;
  };
  void WorkerLoop();
  // Takes the oldest queued job and marks it running (under mutex_).
  std::optional<Job> TakeNext();
  void RunJob(Job job);
  void FinishJob(const std::string& id, pid_t pid, int exit_code, int signal);
  void RecoverJobsOfDeadServer();
  void RemoveOrphanFolders();
  Job WithLiveProgress(Job job) const;  // under mutex_
  // A job has ended: stores it, counts it, sends its webhook (under mutex_).
  void Ended(Job* job);

  JobStore* store_;
  Metrics* metrics_;
  RunnerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;   // a job queued, or stopping
  std::condition_variable ended_;  // a child ended
  bool stopping_ = false;
  std::map<std::string, Running> running_;  // by job id
  std::vector<std::thread> workers_;
  std::unique_ptr<WebhookSender> webhooks_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_JOB_RUNNER_H_
