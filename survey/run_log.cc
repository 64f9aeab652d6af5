#include "survey/run_log.h"

#include <glog/logging.h>

#include <utility>

namespace zebrageo {
namespace {

thread_local RunLog* current_log = nullptr;

// The one glog sink of the process: each line to the run log of the thread
// that logged it.
class RunLogDispatcher : public google::LogSink {
 public:
  void send(google::LogSeverity severity, const char* full_filename,
            const char* base_filename, int line,
            const google::LogMessageTime& time, const char* message,
            size_t message_len) override {
    (void)full_filename;
    RunLog* log = current_log;
    if (log == nullptr) return;
    log->Write(severity, ToString(severity, base_filename, line, time, message,
                                  message_len));
  }
};

// Registered once, on the first RunLog, and never removed: glog may call it
// until the process ends.
void RegisterDispatcher() {
  static RunLogDispatcher* const dispatcher = [] {
    auto* d = new RunLogDispatcher();
    google::AddLogSink(d);
    return d;
  }();
  (void)dispatcher;
}

}  // namespace

RunLog::RunLog(Writer writer, int min_severity)
    : writer_(std::move(writer)), min_severity_(min_severity) {
  RegisterDispatcher();
}

void RunLog::Write(int severity, const std::string& line) {
  if (severity < min_severity_ || !writer_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  writer_(severity, line);
}

ScopedRunLog::ScopedRunLog(RunLog* log) : previous_(current_log) {
  current_log = log;
}

ScopedRunLog::~ScopedRunLog() { current_log = previous_; }

RunLog* CurrentRunLog() { return current_log; }

}  // namespace zebrageo
