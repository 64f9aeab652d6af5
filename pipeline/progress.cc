#include "pipeline/progress.h"

#include <atomic>
#include <utility>

namespace zebrageo {
namespace {

std::atomic<int> next_step_id{1};

}  // namespace

StepProgress::StepProgress(const ProgressListener& callback, std::string step)
    : callback_(callback),
      step_(std::move(step)),
      id_(next_step_id++),
      start_(std::chrono::steady_clock::now()) {
  if (callback_) callback_(Event(ProgressEvent::Kind::kStarted));
}

ProgressEvent StepProgress::Event(ProgressEvent::Kind kind) const {
  ProgressEvent event;
  event.kind = kind;
  event.id = id_;
  event.step = step_;
  event.elapsed_s = ElapsedSeconds();
  return event;
}

std::function<void(int, int)> StepProgress::Callback() const {
  if (!callback_) return [](int, int) {};
  return [this](int done, int total) {
    ProgressEvent event = Event(ProgressEvent::Kind::kAdvanced);
    event.done = done;
    event.total = total;
    callback_(event);
  };
}

void StepProgress::Finish() {
  if (finished_) return;
  finished_ = true;
  if (callback_) callback_(Event(ProgressEvent::Kind::kFinished));
}

double StepProgress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

}  // namespace zebrageo
