// The jobs of `zebrageo serve` in SQLite, so that they survive the server:
// one row per job, in the data root's zebrageo-jobs.sqlite, WAL mode (the
// HTTP threads read while a worker writes), synchronous FULL (a state that
// the API has shown is on disk, even when the machine loses power next).
//
// Thread-safe: one connection, every call under one mutex. Progress, which
// changes every second, is not stored: the runner keeps it in memory and a
// restarted server reads it again from its children.
#ifndef ZEBRAGEO_SERVER_JOB_STORE_H_
#define ZEBRAGEO_SERVER_JOB_STORE_H_

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "server/job.h"

struct sqlite3;

namespace zebrageo {

class JobStore {
 public:
  // Opens (creating) the database at `path`. Throws std::runtime_error with
  // SQLite's message when it cannot.
  explicit JobStore(const std::string& path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  // Adds a new job (its id must be new). Throws on a database error.
  void Insert(const Job& job);
  // Replaces the stored job of the same id; false when there is none.
  bool Update(const Job& job);
  bool Remove(const std::string& id);
  std::optional<Job> Get(const std::string& id) const;
  // Oldest first; all states when `state` is empty.
  std::vector<Job> List(std::optional<JobState> state = std::nullopt) const;
  // The oldest queued job, if any.
  std::optional<Job> NextQueued() const;
  std::map<JobState, int> CountByState() const;
  // The jobs whose webhook is still to be delivered.
  std::vector<Job> PendingWebhooks() const;

 private:
  void Execute(const std::string& sql) const;

  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_JOB_STORE_H_
