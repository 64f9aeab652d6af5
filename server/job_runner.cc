#include "server/job_runner.h"

#include <glog/logging.h>
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "server/child_process.h"
#include "survey/atomic_file.h"

namespace zebrageo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double NowSeconds() {
  return std::chrono::duration<double>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string TimeText(double seconds) {
  const time_t t = static_cast<time_t>(seconds);
  char text[32];
  tm utc{};
  gmtime_r(&t, &utc);
  strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

void AppendToLog(const std::string& log, const std::string& line) {
  std::ofstream(log, std::ios::app) << "zebrageo serve: " << line << "\n";
}

std::string SignalMessage(int signal) {
  const char* name = sigabbrev_np(signal);
  return "the worker was killed by signal " + std::to_string(signal) +
         (name != nullptr ? std::string(" (SIG") + name + ")" : "") +
         (signal == SIGKILL ? ": out of memory, or killed from outside" : "");
}

constexpr auto kPollInterval = std::chrono::milliseconds(200);

}  // namespace

JobRunner::JobRunner(JobStore* store, Metrics* metrics, RunnerOptions options)
    : store_(store), metrics_(metrics), options_(std::move(options)) {
  metrics_->Declare("zebrageo_jobs", "Jobs in the store by state.", "gauge");
  metrics_->Declare("zebrageo_queue_length", "Jobs waiting for a worker.",
                    "gauge");
  metrics_->Declare("zebrageo_workers", "Worker slots.", "gauge");
  metrics_->Declare("zebrageo_workers_busy", "Worker slots running a job.",
                    "gauge");
  metrics_->Declare("zebrageo_jobs_finished_total",
                    "Jobs that ended since the server started, by state.",
                    "counter");
  metrics_->Declare("zebrageo_job_duration_seconds",
                    "Wall time of finished jobs, first start to end.",
                    "histogram", {1, 5, 15, 60, 300, 900, 3600, 14400});
  metrics_->Declare("zebrageo_stage_duration_seconds",
                    "Wall time of each stage of the jobs done, from their "
                    "report.json (stages resumed count once).",
                    "histogram", {0.5, 1, 5, 15, 60, 300, 900, 3600});
  metrics_->Declare("zebrageo_webhook_deliveries_total",
                    "Webhook deliveries by outcome.", "counter");
  for (const char* state : {"done", "failed", "cancelled"}) {
    metrics_->Add("zebrageo_jobs_finished_total", {{"state", state}}, 0.0);
  }
  webhooks_ = std::make_unique<WebhookSender>(
      options_.webhook,
      [this](const std::string& id) -> std::optional<std::string> {
        const std::optional<Job> job = store_->Get(id);
        if (!job) return std::nullopt;
        return JobToJson(*job).dump();
      },
      [this](const std::string& id, bool delivered) {
        metrics_->Add("zebrageo_webhook_deliveries_total",
                      {{"outcome", delivered ? "delivered" : "failed"}});
        std::lock_guard<std::mutex> lock(mutex_);
        std::optional<Job> job = store_->Get(id);
        if (!job) return;
        job->webhook_pending = false;
        if (!delivered) {
          LOG(WARNING) << "job " << id << ": webhook " << job->webhook
                       << " not delivered after " << options_.webhook.attempts
                       << " attempts";
        }
        store_->Update(*job);
      });
}

JobRunner::~JobRunner() { Stop(); }

JobFiles JobRunner::FilesOf(const std::string& id) const {
  return JobFiles{options_.data_root + "/jobs/" + id};
}

void JobRunner::Start() {
  RecoverJobsOfDeadServer();
  RemoveOrphanFolders();
  for (const Job& job : store_->PendingWebhooks()) {
    webhooks_->Send(job.id, job.webhook);
  }
  for (int i = 0; i < options_.workers; ++i) {
    workers_.emplace_back([this] { WorkerLoop(); });
  }
}

void JobRunner::RecoverJobsOfDeadServer() {
  for (Job job : store_->List(JobState::kRunning)) {
    const JobFiles files = FilesOf(job.id);
    // PR_SET_PDEATHSIG kills the children of a dead server, but the signal
    // may not have landed yet: wait until the old child is gone (it holds
    // the results folder's lock).
    if (ProcessRunsWith(job.pid, files.Results())) {
      kill(static_cast<pid_t>(job.pid), SIGKILL);
      for (int i = 0; i < 500 && ProcessRunsWith(job.pid, files.Results());
           ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    job.pid = 0;
    if (fs::is_directory(files.Results())) {
      RemoveStaleTemporaries(files.Results());
    }
    if (job.cancel_requested) {
      job.state = JobState::kCancelled;
      job.error = "cancelled";
      job.finished_at = NowSeconds();
      job.webhook_pending = !job.webhook.empty();
      AppendToLog(files.Log(), "cancelled (the server had stopped)");
    } else {
      // Queued again, in its original order (the oldest first): the
      // resumable run continues after its last complete stage.
      job.state = JobState::kQueued;
      AppendToLog(files.Log(),
                  "the server stopped during this run; resumed on restart");
    }
    store_->Update(job);
  }
}

void JobRunner::RemoveOrphanFolders() {
  // A folder without a job: an upload the server was extracting when it
  // died (a job is stored only once its survey is complete).
  const std::string jobs = options_.data_root + "/jobs";
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(jobs, error)) {
    const std::string id = entry.path().filename().string();
    if (!store_->Get(id)) {
      LOG(INFO) << "removing " << entry.path().string() << ": no such job";
      fs::remove_all(entry.path(), error);
    }
  }
}

void JobRunner::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ && workers_.empty()) return;
    stopping_ = true;
    for (auto& [id, running] : running_) {
      SignalChild(running.pid, SIGTERM);
      running.term_sent = true;
      running.term_time = std::chrono::steady_clock::now();
    }
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
  workers_.clear();
  webhooks_.reset();
}

void JobRunner::Wake() { wake_.notify_all(); }

std::optional<Job> JobRunner::TakeNext() {
  std::optional<Job> job = store_->NextQueued();
  if (!job) return std::nullopt;
  job->state = JobState::kRunning;
  job->attempts += 1;
  if (job->started_at <= 0.0) job->started_at = NowSeconds();
  job->exit_code = -1;
  job->signal = 0;
  job->error.clear();
  store_->Update(*job);
  running_[job->id] = Running{};
  return job;
}

void JobRunner::WorkerLoop() {
  for (;;) {
    std::optional<Job> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!stopping_ && !(job = TakeNext())) {
        wake_.wait_for(lock, std::chrono::seconds(2));
      }
      if (stopping_ && !job) return;
    }
    try {
      RunJob(std::move(*job));
    } catch (const std::exception& error) {
      // The store failing (disk full) must not end the worker silently.
      LOG(ERROR) << "job " << job->id << ": " << error.what();
      std::lock_guard<std::mutex> lock(mutex_);
      running_.erase(job->id);
      ended_.notify_all();
    }
  }
}

void JobRunner::RunJob(Job job) {
  const JobFiles files = FilesOf(job.id);
  const std::vector<std::string> args =
      RunArguments(job.survey_path, files, job.options);
  std::string command = "zebrageo";
  for (const std::string& arg : args) command += " " + arg;
  AppendToLog(files.Log(), "attempt " + std::to_string(job.attempts) + " at " +
                               TimeText(NowSeconds()) + ": " + command);
  ChildSpec spec{options_.executable, args, files.Log(),
                 options_.job_memory_limit_mb};
  pid_t pid = -1;
  try {
    pid = StartChild(spec);
  } catch (const std::exception& error) {
    AppendToLog(files.Log(), std::string("cannot start: ") + error.what());
    FinishJob(job.id, -1, 5, 0);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_[job.id].pid = pid;
    job.pid = pid;
    std::optional<Job> stored = store_->Get(job.id);
    if (stored) {
      stored->pid = pid;
      store_->Update(*stored);
      // Cancelled between TakeNext and now.
      if (stored->cancel_requested) {
        SignalChild(pid, SIGTERM);
        running_[job.id].term_sent = true;
        running_[job.id].term_time = std::chrono::steady_clock::now();
      }
    }
  }
  for (;;) {
    const std::optional<ChildExit> exit = PollChild(pid);
    if (exit) {
      FinishJob(job.id, pid, exit->exit_code, exit->signal);
      return;
    }
    RunProgress progress = ReadRunProgress(files);
    std::unique_lock<std::mutex> lock(mutex_);
    Running& running = running_[job.id];
    // The log's tail may lose a stage's progress lines behind later lines
    // (warnings): what the client saw is never taken back.
    progress.fraction = std::max(progress.fraction, running.progress.fraction);
    running.progress = progress;
    if (running.term_sent &&
        std::chrono::steady_clock::now() - running.term_time >
            std::chrono::duration<double>(options_.cancel_grace_s)) {
      SignalChild(pid, SIGKILL);
    }
    wake_.wait_for(lock, kPollInterval);
  }
}

void JobRunner::FinishJob(const std::string& id, pid_t pid, int exit_code,
                          int signal) {
  const JobFiles files = FilesOf(id);
  if (signal != 0 && fs::is_directory(files.Results())) {
    // A killed run's temporaries (its complete files stay: they resume).
    RemoveStaleTemporaries(files.Results());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  running_.erase(id);
  ended_.notify_all();
  std::optional<Job> stored = store_->Get(id);
  if (!stored) return;  // deleted meanwhile
  Job job = *stored;
  job.pid = 0;
  job.exit_code = exit_code;
  job.signal = signal;
  if (stopping_ && !job.cancel_requested) {
    // The server is stopping: the job stays running, to be resumed.
    AppendToLog(files.Log(),
                "the server stopped; the job resumes when it "
                "starts again");
    store_->Update(job);
    return;
  }
  (void)pid;
  if (job.cancel_requested) {
    job.state = JobState::kCancelled;
    job.error = "cancelled";
    AppendToLog(files.Log(), "cancelled");
  } else if (exit_code == 0 && signal == 0) {
    job.state = JobState::kDone;
    job.progress = 1.0;
    job.stage = "";
    ReadReportSummary(files, &job.warnings, &job.timings);
  } else {
    job.state = JobState::kFailed;
    job.error =
        signal != 0 ? SignalMessage(signal) : RunErrorFromLog(files.Log());
    if (job.error.empty()) {
      job.error = "zebrageo run ended with exit status " +
                  std::to_string(exit_code) + " (see the log)";
    }
    AppendToLog(files.Log(), "failed: " + job.error);
  }
  job.finished_at = NowSeconds();
  Ended(&job);
}

void JobRunner::Ended(Job* job) {
  job->webhook_pending = !job->webhook.empty();
  metrics_->Add("zebrageo_jobs_finished_total",
                {{"state", JobStateName(job->state)}});
  if (job->state == JobState::kDone) {
    if (job->started_at > 0.0) {
      metrics_->Observe("zebrageo_job_duration_seconds", {},
                        job->finished_at - job->started_at);
    }
    for (const auto& [stage, seconds] : job->timings.items()) {
      if (stage != "total" && seconds.is_number()) {
        metrics_->Observe("zebrageo_stage_duration_seconds", {{"stage", stage}},
                          seconds.get<double>());
      }
    }
  }
  // Stored before the webhook reads it back.
  store_->Update(*job);
  if (job->webhook_pending) webhooks_->Send(job->id, job->webhook);
}

Job JobRunner::WithLiveProgress(Job job) const {
  auto it = running_.find(job.id);
  if (job.state == JobState::kRunning && it != running_.end()) {
    job.stage = it->second.progress.stage;
    job.step = it->second.progress.step;
    job.progress = it->second.progress.fraction;
  }
  return job;
}

std::optional<Job> JobRunner::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<Job> job = store_->Get(id);
  if (!job) return std::nullopt;
  return WithLiveProgress(*job);
}

std::vector<Job> JobRunner::List(std::optional<JobState> state) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<Job> jobs = store_->List(state);
  for (Job& job : jobs) job = WithLiveProgress(job);
  return jobs;
}

std::optional<Job> JobRunner::Cancel(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<Job> job = store_->Get(id);
  if (!job) return std::nullopt;
  if (job->state == JobState::kQueued) {
    job->state = JobState::kCancelled;
    job->cancel_requested = true;
    job->error = "cancelled";
    job->finished_at = NowSeconds();
    AppendToLog(FilesOf(id).Log(), "cancelled before it started");
    Ended(&*job);
  } else if (job->state == JobState::kRunning && !job->cancel_requested) {
    job->cancel_requested = true;
    store_->Update(*job);
    auto it = running_.find(id);
    if (it != running_.end() && it->second.pid > 0 && !it->second.term_sent) {
      SignalChild(it->second.pid, SIGTERM);
      it->second.term_sent = true;
      it->second.term_time = std::chrono::steady_clock::now();
    }
    wake_.notify_all();
  }
  return WithLiveProgress(*job);
}

JobRunner::DeleteOutcome JobRunner::Delete(const std::string& id) {
  if (!Cancel(id)) return DeleteOutcome::kUnknown;
  std::unique_lock<std::mutex> lock(mutex_);
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration<double>(options_.cancel_grace_s + 10.0);
  while (running_.count(id) > 0) {
    if (ended_.wait_until(lock, deadline) == std::cv_status::timeout &&
        running_.count(id) > 0) {
      return DeleteOutcome::kStillRunning;
    }
  }
  if (!store_->Remove(id)) return DeleteOutcome::kUnknown;
  std::error_code ignored;
  fs::remove_all(FilesOf(id).folder, ignored);
  return DeleteOutcome::kDeleted;
}

void JobRunner::UpdateGauges() {
  const std::map<JobState, int> counts = store_->CountByState();
  for (const auto& [state, count] : counts) {
    metrics_->Set("zebrageo_jobs", {{"state", JobStateName(state)}}, count);
  }
  metrics_->Set("zebrageo_queue_length", {}, counts.at(JobState::kQueued));
  metrics_->Set("zebrageo_workers", {}, options_.workers);
  std::lock_guard<std::mutex> lock(mutex_);
  metrics_->Set("zebrageo_workers_busy", {},
                static_cast<double>(running_.size()));
}

}  // namespace zebrageo
