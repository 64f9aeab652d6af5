#include "server/job_store.h"

#include <sqlite3.h>

#include <memory>
#include <stdexcept>

namespace zebrageo {
namespace {

using nlohmann::json;

// Everything the store keeps of a job, as one JSON document (the columns
// beside it are for queries).
json StoredJson(const Job& job) {
  return {{"id", job.id},
          {"name", job.name},
          {"state", JobStateName(job.state)},
          {"source", job.source == JobSource::kUpload ? "upload" : "folder"},
          {"survey_path", job.survey_path},
          {"folder", job.folder},
          {"options", job.options},
          {"webhook", job.webhook},
          {"stage", job.stage},
          {"created_at", job.created_at},
          {"started_at", job.started_at},
          {"finished_at", job.finished_at},
          {"attempts", job.attempts},
          {"exit_code", job.exit_code},
          {"signal", job.signal},
          {"error", job.error},
          {"warnings", job.warnings},
          {"timings", job.timings},
          {"cancel_requested", job.cancel_requested},
          {"webhook_pending", job.webhook_pending},
          {"pid", job.pid}};
}

Job JobFromStoredJson(const json& in) {
  Job job;
  job.id = in.at("id").get<std::string>();
  job.name = in.value("name", "");
  job.state =
      JobStateFromName(in.value("state", "failed")).value_or(JobState::kFailed);
  job.source = in.value("source", "upload") == "folder" ? JobSource::kFolder
                                                        : JobSource::kUpload;
  job.survey_path = in.value("survey_path", "");
  job.folder = in.value("folder", "");
  job.options = in.value("options", json::object());
  job.webhook = in.value("webhook", "");
  job.stage = in.value("stage", "");
  job.created_at = in.value("created_at", 0.0);
  job.started_at = in.value("started_at", 0.0);
  job.finished_at = in.value("finished_at", 0.0);
  job.attempts = in.value("attempts", 0);
  job.exit_code = in.value("exit_code", -1);
  job.signal = in.value("signal", 0);
  job.error = in.value("error", "");
  job.warnings = in.value("warnings", json::array());
  job.timings = in.value("timings", json::object());
  job.cancel_requested = in.value("cancel_requested", false);
  job.webhook_pending = in.value("webhook_pending", false);
  job.pid = in.value("pid", 0L);
  if (IsFinal(job.state)) job.progress = job.state == JobState::kDone ? 1 : 0;
  return job;
}

// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      throw std::runtime_error(std::string("job store: ") + sqlite3_errmsg(db));
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& Bind(int index, const std::string& text) {
    sqlite3_bind_text(stmt_, index, text.c_str(), static_cast<int>(text.size()),
                      SQLITE_TRANSIENT);
    return *this;
  }
  Statement& Bind(int index, double value) {
    sqlite3_bind_double(stmt_, index, value);
    return *this;
  }
  // True while a row is there; throws on an error.
  bool Step() {
    const int code = sqlite3_step(stmt_);
    if (code == SQLITE_ROW) return true;
    if (code == SQLITE_DONE) return false;
    throw std::runtime_error(std::string("job store: ") + sqlite3_errmsg(db_));
  }
  std::string Text(int column) const {
    const unsigned char* text = sqlite3_column_text(stmt_, column);
    return text == nullptr ? "" : reinterpret_cast<const char*>(text);
  }
  int Int(int column) const { return sqlite3_column_int(stmt_, column); }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

std::vector<Job> JobsOf(Statement* statement) {
  std::vector<Job> jobs;
  while (statement->Step()) {
    jobs.push_back(JobFromStoredJson(json::parse(statement->Text(0))));
  }
  return jobs;
}

}  // namespace

JobStore::JobStore(const std::string& path) {
  if (sqlite3_open_v2(
          path.c_str(), &db_,
          SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
          nullptr) != SQLITE_OK) {
    const std::string message =
        db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw std::runtime_error("job store " + path + ": " + message);
  }
  sqlite3_busy_timeout(db_, 10000);
  try {
    Execute("PRAGMA journal_mode=WAL");
    Execute("PRAGMA synchronous=FULL");
    Execute(
        "CREATE TABLE IF NOT EXISTS jobs ("
        " seq INTEGER PRIMARY KEY AUTOINCREMENT,"
        " id TEXT NOT NULL UNIQUE,"
        " state TEXT NOT NULL,"
        " webhook_pending INTEGER NOT NULL DEFAULT 0,"
        " data TEXT NOT NULL)");
    Execute("CREATE INDEX IF NOT EXISTS jobs_state ON jobs(state, seq)");
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

JobStore::~JobStore() { sqlite3_close(db_); }

void JobStore::Execute(const std::string& sql) const {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message != nullptr ? message : "unknown error";
    sqlite3_free(message);
    throw std::runtime_error("job store: " + text);
  }
}

void JobStore::Insert(const Job& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement insert(db_,
                   "INSERT INTO jobs (id, state, webhook_pending, data) "
                   "VALUES (?1, ?2, ?3, ?4)");
  insert.Bind(1, job.id)
      .Bind(2, std::string(JobStateName(job.state)))
      .Bind(3, job.webhook_pending ? 1.0 : 0.0)
      .Bind(4, StoredJson(job).dump());
  insert.Step();
}

bool JobStore::Update(const Job& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement update(db_,
                   "UPDATE jobs SET state = ?2, webhook_pending = ?3, "
                   "data = ?4 WHERE id = ?1");
  update.Bind(1, job.id)
      .Bind(2, std::string(JobStateName(job.state)))
      .Bind(3, job.webhook_pending ? 1.0 : 0.0)
      .Bind(4, StoredJson(job).dump());
  update.Step();
  return sqlite3_changes(db_) > 0;
}

bool JobStore::Remove(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement remove(db_, "DELETE FROM jobs WHERE id = ?1");
  remove.Bind(1, id).Step();
  return sqlite3_changes(db_) > 0;
}

std::optional<Job> JobStore::Get(const std::string& id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement select(db_, "SELECT data FROM jobs WHERE id = ?1");
  select.Bind(1, id);
  std::vector<Job> jobs = JobsOf(&select);
  if (jobs.empty()) return std::nullopt;
  return jobs.front();
}

std::vector<Job> JobStore::List(std::optional<JobState> state) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!state) {
    Statement select(db_, "SELECT data FROM jobs ORDER BY seq");
    return JobsOf(&select);
  }
  Statement select(db_, "SELECT data FROM jobs WHERE state = ?1 ORDER BY seq");
  select.Bind(1, std::string(JobStateName(*state)));
  return JobsOf(&select);
}

std::optional<Job> JobStore::NextQueued() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement select(
      db_, "SELECT data FROM jobs WHERE state = 'queued' ORDER BY seq LIMIT 1");
  std::vector<Job> jobs = JobsOf(&select);
  if (jobs.empty()) return std::nullopt;
  return jobs.front();
}

std::map<JobState, int> JobStore::CountByState() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<JobState, int> counts;
  for (const char* name :
       {"queued", "running", "done", "failed", "cancelled"}) {
    counts[*JobStateFromName(name)] = 0;
  }
  Statement select(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
  while (select.Step()) {
    const std::optional<JobState> state = JobStateFromName(select.Text(0));
    if (state) counts[*state] = select.Int(1);
  }
  return counts;
}

std::vector<Job> JobStore::PendingWebhooks() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement select(
      db_, "SELECT data FROM jobs WHERE webhook_pending = 1 ORDER BY seq");
  return JobsOf(&select);
}

}  // namespace zebrageo
