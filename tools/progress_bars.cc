#include "tools/progress_bars.h"

#include <glog/logging.h>
#include <unistd.h>

#include <cstdio>
#include <utility>

namespace zebrageo {

ProgressBar::ProgressBar(std::string stage)
    : stage_(std::move(stage)),
      start_(std::chrono::steady_clock::now()),
      is_terminal_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  if (!finished_ && is_terminal_) std::fputc('\n', stderr);
}

double ProgressBar::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

void ProgressBar::Update(int done, int total) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_ || total <= 0) return;
  if (is_terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * static_cast<double>(done) /
                                        static_cast<double>(total));
    std::string bar(filled, '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r%s [%s] %d/%d %.1f s", stage_.c_str(), bar.c_str(),
                 done, total, ElapsedSeconds());
    std::fflush(stderr);
    return;
  }
  const int decile = done * 10 / total;
  if (decile > last_logged_decile_) {
    last_logged_decile_ = decile;
    LOG(INFO) << stage_ << ": " << done << "/" << total << " (" << decile * 10
              << "%), " << ElapsedSeconds() << " s";
  }
}

std::function<void(int, int)> ProgressBar::Callback() {
  return [this](int done, int total) { Update(done, total); };
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (is_terminal_) std::fputc('\n', stderr);
  LOG(INFO) << stage_ << ": done in " << ElapsedSeconds() << " s";
}

ProgressListener ProgressBars() {
  struct Bars {
    std::mutex mutex;
    std::map<int, std::unique_ptr<ProgressBar>> of_step;
  };
  auto bars = std::make_shared<Bars>();
  return [bars](const ProgressEvent& event) {
    ProgressBar* bar = nullptr;
    {
      std::lock_guard<std::mutex> lock(bars->mutex);
      if (event.kind == ProgressEvent::Kind::kStarted) {
        bars->of_step[event.id] = std::make_unique<ProgressBar>(event.step);
        return;
      }
      const auto it = bars->of_step.find(event.id);
      if (it == bars->of_step.end()) return;
      if (event.kind == ProgressEvent::Kind::kFinished) {
        it->second->Finish();
        bars->of_step.erase(it);
        return;
      }
      bar = it->second.get();
    }
    // Outside the lock: the bar has its own; the step cannot finish while
    // its own callback runs.
    bar->Update(event.done, event.total);
  };
}

}  // namespace zebrageo
