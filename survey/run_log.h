// A log of one run, in a process that runs several (a server's workers).
//
// glog is configured once for the process: its destinations (stderr, log
// files) receive every run's lines mixed. A RunLog receives the lines of
// the threads that work for one run: the thread that runs it, while a
// ScopedRunLog is alive on it, and the worker threads it starts through
// ParallelFor (survey/threads.h), which carries the scope over. Each line
// comes formatted as glog formats it ("I1207 01:25:18.714192 25499
// pipeline.cc:91] text") with its severity, to a callback of the caller's
// (a file of the job, a queue, a test's vector), as well as to glog's own
// destinations. Lines below glog's FLAGS_minloglevel are not made at all,
// and VLOG's verbosity is the process's (FLAGS_v); a RunLog can only drop
// more (min_severity). Threads the libraries do not start themselves (the
// solver's) log to glog's destinations only.
#ifndef ZEBRAGEO_SURVEY_RUN_LOG_H_
#define ZEBRAGEO_SURVEY_RUN_LOG_H_

#include <functional>
#include <mutex>
#include <string>

namespace zebrageo {

class RunLog {
 public:
  // severity: glog's (0 INFO, 1 WARNING, 2 ERROR, 3 FATAL); `line` without
  // its newline. Called from the run's threads, one line at a time.
  using Writer = std::function<void(int severity, const std::string& line)>;

  explicit RunLog(Writer writer, int min_severity = 0);
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;

  void Write(int severity, const std::string& line);

 private:
  Writer writer_;
  int min_severity_;
  std::mutex mutex_;  // lines of several threads, one at a time
};

// The calling thread's run log while the scope lives (null: none); scopes
// nest and restore the previous one.
class ScopedRunLog {
 public:
  explicit ScopedRunLog(RunLog* log);
  ~ScopedRunLog();
  ScopedRunLog(const ScopedRunLog&) = delete;
  ScopedRunLog& operator=(const ScopedRunLog&) = delete;

 private:
  RunLog* previous_;
};

// The calling thread's run log, or null.
RunLog* CurrentRunLog();

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_RUN_LOG_H_
