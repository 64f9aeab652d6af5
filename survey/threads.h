#ifndef ZEBRAGEO_SURVEY_THREADS_H_
#define ZEBRAGEO_SURVEY_THREADS_H_

#include <time.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <thread>
#include <vector>

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
// crossing against an empty one) still keep every thread busy.
inline void ParallelFor(int count, int threads,
                        const std::function<void(int)>& work) {
  threads = std::max(1, std::min(threads, count));
  if (threads == 1) {
    for (int k = 0; k < count; ++k) work(k);
    return;
  }
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (int k = next++; k < count; k = next++) work(k);
    });
  }
  for (std::thread& thread : pool) thread.join();
}

}  // namespace zebrageo

#endif  // ZEBRAGEO_SURVEY_THREADS_H_
