#ifndef ZEBRAGEO_SURVEY_THREADS_H_
#define ZEBRAGEO_SURVEY_THREADS_H_

#include <time.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "survey/run_log.h"

namespace zebrageo {

// CPU time of the calling thread: step timings stay per core when other
// threads (or processes) compete for the cores.
inline double ThreadCpuSeconds() {
  timespec now;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return now.tv_sec + 1e-9 * now.tv_nsec;
}

// Runs `work(k)` for k in [0, count) on `threads` threads. Items are handed
// out one at a time from a shared counter, so unequal items (a pair with a
// crossing against an empty one) still keep every thread busy. The workers
// log to the caller's run log (survey/run_log.h). An exception of `work`
// (a cancellation, survey/cancellation.h) stops the handing out; the first
// one is rethrown here once every worker has finished its item.
inline void ParallelFor(int count, int threads,
                        const std::function<void(int)>& work) {
  threads = std::max(1, std::min(threads, count));
  if (threads == 1) {
    for (int k = 0; k < count; ++k) work(k);
    return;
  }
  RunLog* const log = CurrentRunLog();
  std::atomic<int> next{0};
  std::mutex error_mutex;
  std::exception_ptr error;
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      const ScopedRunLog log_scope(log);
      try {
        for (int k = next++; k < count; k = next++) work(k);
      } catch (...) {
        next = count;  // no more items
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    });
  }
  for (std::thread& thread : pool) thread.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_THREADS_H_
