// Stopping a run from outside (a user's Ctrl-C, a server's cancel): a flag
// the caller sets, from any thread or a signal handler, and the libraries
// read at their checkpoints: between exposures (reconstruction, road
// lines, tie points), between observations (registration), between solves
// and between the solver's iterations (the adjustment, through a Ceres
// IterationCallback). There they throw CancelledError, which unwinds the
// stage before it writes: every file is written after the work, each
// atomically, so a cancelled run leaves no file half-written and resumes
// as a killed one does (pipeline/run_state.h).
#ifndef ZEBRAGEO_SURVEY_CANCELLATION_H_
#define ZEBRAGEO_SURVEY_CANCELLATION_H_

#include <atomic>
#include <memory>
#include <stdexcept>
#include <string>

namespace zebrageo {

class CancelledError : public std::runtime_error {
 public:
  CancelledError() : std::runtime_error("cancelled") {}
};

// Copies share one flag. A default-constructed token can never be
// cancelled (the libraries' default argument).
class CancellationToken {
 public:
  CancellationToken() = default;
  // A token that Cancel() sets.
  static CancellationToken Cancellable() {
    CancellationToken token;
    token.flag_ = std::make_shared<std::atomic<bool>>(false);
    return token;
  }

  // Thread-safe; nothing for a token that cannot be cancelled.
  void Cancel() const {
    if (flag_) flag_->store(true);
  }
  bool IsCancelled() const { return flag_ && flag_->load(); }
  void ThrowIfCancelled() const {
    if (IsCancelled()) throw CancelledError();
  }
  // The flag itself, for a signal handler (a lock-free atomic store is
  // async-signal-safe); null for a token that cannot be cancelled.
  std::atomic<bool>* flag() const { return flag_.get(); }

 private:
  std::shared_ptr<std::atomic<bool>> flag_;
};

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_CANCELLATION_H_
