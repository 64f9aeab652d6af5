// How the pipeline reports progress: one callback receives every step's
// events (the CLI draws bars from them, tools/progress.h; a server would
// send them over HTTP). Steps may nest ("adjust" holds "tie points" and the
// solves) and share a name: `id` tells them apart.
#ifndef ZEBRAGEO_PIPELINE_PROGRESS_H_
#define ZEBRAGEO_PIPELINE_PROGRESS_H_

#include <chrono>
#include <functional>
#include <string>

namespace zebrageo {

struct ProgressEvent {
  enum class Kind { kStarted, kAdvanced, kFinished };
  Kind kind = Kind::kStarted;
  int id = 0;  // unique per step in the process
  std::string step;
  int done = 0;  // kAdvanced: done of total
  int total = 0;
  double elapsed_s = 0.0;  // since kStarted
};
// Called from worker threads for kAdvanced: must be thread-safe. May be
// empty (no reporting).
using ProgressListener = std::function<void(const ProgressEvent&)>;

// One step's events, and the (done, total) callback the libraries take.
class StepProgress {
 public:
  StepProgress(const ProgressListener& callback, std::string step);
  StepProgress(const StepProgress&) = delete;
  StepProgress& operator=(const StepProgress&) = delete;

  std::function<void(int, int)> Callback() const;
  // Sends kFinished (once).
  void Finish();
  double ElapsedSeconds() const;

 private:
  ProgressEvent Event(ProgressEvent::Kind kind) const;

  const ProgressListener& callback_;
  std::string step_;
  int id_;
  std::chrono::steady_clock::time_point start_;
  bool finished_ = false;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_PIPELINE_PROGRESS_H_
