// Progress of long loops: a bar on a terminal, plain lines in a log; and
// the log lines themselves, which share the terminal with the bars.
#ifndef ZEBRAGEO_TOOLS_PROGRESS_H_
#define ZEBRAGEO_TOOLS_PROGRESS_H_

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "pipeline/progress.h"

namespace zebrageo {

// Thread-safe. On a terminal (stderr is a tty) it redraws one line
// "stage [#####.....] 52/100 3.1 s, ~2.9 s left" and ends it as
// "stage [##########] done in 6.2 s" on a line of its own; otherwise it
// logs a line every 10% and "stage: done in X s".
class ProgressBar {
 public:
  explicit ProgressBar(std::string stage);
  ~ProgressBar();

  void Update(int done, int total);
  // The callback form the libraries take.
  std::function<void(int, int)> Callback();
  // Ends the bar (full: a step may end before its last count, e.g. a
  // solver that converged) and logs "stage: done in X s".
  void Finish();
  double ElapsedSeconds() const;

 private:
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  bool is_terminal_;
  bool finished_ = false;
  int last_logged_decile_ = -1;
  std::mutex mutex_;
};

// The pipeline's progress events (pipeline/progress.h) drawn as bars: one
// ProgressBar per step, from kStarted to kFinished. Thread-safe.
ProgressListener ProgressBars();

// Sends glog's lines to stderr through the terminal the bars draw on: a
// line clears the bar, takes its own line, and the bar is drawn again
// under it. `full_format`: glog's prefix (severity, date, thread, source
// file and line, for --log-level debug); else "HH:MM:SS " and "warning: "
// or "error: " before the text. Replaces glog's own stderr output; call
// once, from main.
void LogToConsole(bool full_format);

}  // namespace zebrageo

#endif  // ZEBRAGEO_TOOLS_PROGRESS_H_
