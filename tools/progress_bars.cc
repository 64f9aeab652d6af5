#include "tools/progress_bars.h"

#include <glog/logging.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace zebrageo {
namespace {

// The terminal's last line: the bar drawn there, if any. Log lines and
// bars are written through it, one at a time, so that a log line never
// lands on a bar's line.
class Console {
 public:
  static Console& Get() {
    static Console* const console = new Console();  // lives to the exit
    return *console;
  }
  // Draws `bar` over the current bar (no newline).
  void DrawBar(const std::string& bar) {
    std::lock_guard<std::mutex> lock(mutex_);
    bar_ = bar;
    std::fprintf(stderr, "\r%s\033[K", bar_.c_str());
    std::fflush(stderr);
  }
  // Draws `bar` as the bar's last state and ends its line.
  void EndBar(const std::string& bar) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::fprintf(stderr, "\r%s\033[K\n", bar.c_str());
    std::fflush(stderr);
    bar_.clear();
  }
  // A line of its own; the bar, if one is drawn, again under it.
  void WriteLine(const std::string& line) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!bar_.empty()) std::fputs("\r\033[K", stderr);
    std::fputs(line.c_str(), stderr);
    std::fputc('\n', stderr);
    if (!bar_.empty()) std::fputs(bar_.c_str(), stderr);
    std::fflush(stderr);
  }

 private:
  std::mutex mutex_;
  std::string bar_;
};

std::string Seconds(double s) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), s < 10 ? "%.1f s" : "%.0f s", s);
  return buffer;
}

std::string BarText(const std::string& stage, double fraction) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * fraction);
  std::string bar(std::max(0, std::min(kWidth, filled)), '#');
  bar.resize(kWidth, '.');
  return stage + " [" + bar + "]";
}

class ConsoleSink : public google::LogSink {
 public:
  explicit ConsoleSink(bool full_format) : full_format_(full_format) {}
  void send(google::LogSeverity severity, const char* full_filename,
            const char* base_filename, int line,
            const google::LogMessageTime& time, const char* message,
            size_t message_len) override {
    (void)full_filename;
    if (full_format_) {
      Console::Get().WriteLine(
          ToString(severity, base_filename, line, time, message, message_len));
      return;
    }
    char clock[16];
    std::snprintf(clock, sizeof(clock), "%02d:%02d:%02d ", time.hour(),
                  time.min(), time.sec());
    const char* level = severity >= google::GLOG_ERROR     ? "error: "
                        : severity == google::GLOG_WARNING ? "warning: "
                                                           : "";
    Console::Get().WriteLine(clock + std::string(level) +
                             std::string(message, message_len));
  }

 private:
  bool full_format_;
};

}  // namespace

void LogToConsole(bool full_format) {
  static ConsoleSink* const sink = new ConsoleSink(full_format);
  google::AddLogSink(sink);
  // glog itself neither to stderr (the sink writes there) nor to files.
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::NUM_SEVERITIES;
  for (int severity = 0; severity < google::NUM_SEVERITIES; ++severity) {
    google::SetLogDestination(severity, "");
  }
}

ProgressBar::ProgressBar(std::string stage)
    : stage_(std::move(stage)),
      start_(std::chrono::steady_clock::now()),
      is_terminal_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!finished_ && is_terminal_) {
    Console::Get().EndBar(BarText(stage_, 0.0) + " stopped after " +
                          Seconds(ElapsedSeconds()));
  }
}

double ProgressBar::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

void ProgressBar::Update(int done, int total) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_ || total <= 0) return;
  const double elapsed = ElapsedSeconds();
  // The rate so far: a fair guess for loops of alike items.
  const std::string left =
      done > 0 && done < total
          ? ", ~" + Seconds(elapsed * (total - done) / done) + " left"
          : "";
  if (is_terminal_) {
    Console::Get().DrawBar(BarText(stage_, static_cast<double>(done) / total) +
                           " " + std::to_string(done) + "/" +
                           std::to_string(total) + " " + Seconds(elapsed) +
                           left);
    return;
  }
  const int decile = done * 10 / total;
  if (decile > last_logged_decile_) {
    last_logged_decile_ = decile;
    LOG(INFO) << stage_ << ": " << done << "/" << total << " (" << decile * 10
              << "%), " << Seconds(elapsed) << left;
  }
}

std::function<void(int, int)> ProgressBar::Callback() {
  return [this](int done, int total) { Update(done, total); };
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (is_terminal_) {
    Console::Get().EndBar(BarText(stage_, 1.0) + " done in " +
                          Seconds(ElapsedSeconds()));
    return;
  }
  LOG(INFO) << stage_ << ": done in " << Seconds(ElapsedSeconds());
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
