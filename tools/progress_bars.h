// Progress of long loops: a bar on a terminal, plain lines in a log.
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
// "stage [#####.....] 52/100 3.1 s"; otherwise it logs a line every 10%.
class ProgressBar {
 public:
  explicit ProgressBar(std::string stage);
  ~ProgressBar();

  void Update(int done, int total);
  // The callback form the libraries take.
  std::function<void(int, int)> Callback();
  // Ends the bar and logs "stage: done in X s".
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

}  // namespace zebrageo

#endif  // ZEBRAGEO_TOOLS_PROGRESS_H_
