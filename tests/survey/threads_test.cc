// ParallelFor (survey/threads.h): every item runs exactly once whatever the
// thread count, results written per item need no lock, and the calling
// thread sees them all once it returns; PrepareImageCodecs() makes image
// codecs safe for threads started after it. Runs under ThreadSanitizer in
// scripts/test.sh (label sanitize_threads).
#include "survey/threads.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <thread>
#include <vector>

#include "survey/image_io.h"

namespace zebrageo {
namespace {

TEST(ParallelFor, RunsEveryItemExactlyOnce) {
  for (int threads : {1, 2, 3, 8}) {
    for (int count : {0, 1, 2, 7, 100}) {
      SCOPED_TRACE(testing::Message() << threads << " threads, " << count);
      std::vector<int> runs(count, 0);  // one slot per item: no lock
      ParallelFor(count, threads, [&](int k) { ++runs[k]; });
      for (int k = 0; k < count; ++k) EXPECT_EQ(runs[k], 1) << k;
    }
  }
}

TEST(ParallelFor, UsesSeveralThreadsButNoMoreThanItems) {
  std::mutex mutex;
  std::set<std::thread::id> ids;
  std::atomic<int> running{0};
  std::atomic<int> most{0};
  ParallelFor(40, 4, [&](int) {
    const int now = ++running;
    for (int seen = most;
         now > seen && !most.compare_exchange_weak(seen, now);) {
    }
    {
      std::lock_guard<std::mutex> lock(mutex);
      ids.insert(std::this_thread::get_id());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    --running;
  });
  EXPECT_LE(most.load(), 4);
  EXPECT_GE(ids.size(), 1u);
  EXPECT_LE(ids.size(), 4u);
  // Two items and eight threads: at most two workers.
  ids.clear();
  ParallelFor(2, 8, [&](int) {
    std::lock_guard<std::mutex> lock(mutex);
    ids.insert(std::this_thread::get_id());
  });
  EXPECT_LE(ids.size(), 2u);
}

// One thread (or fewer asked for) runs on the caller, in order.
TEST(ParallelFor, OneThreadRunsInOrderOnTheCaller) {
  for (int threads : {1, 0, -3}) {
    std::vector<int> order;
    const std::thread::id caller = std::this_thread::get_id();
    bool on_caller = true;
    ParallelFor(5, threads, [&](int k) {
      order.push_back(k);
      on_caller = on_caller && std::this_thread::get_id() == caller;
    });
    EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
    EXPECT_TRUE(on_caller);
  }
}

// The pattern of the stages: each item writes its own slot of a shared
// vector, the caller reduces after the call.
TEST(ParallelFor, PerItemResultsAreVisibleAfterTheCall) {
  std::vector<double> squares(1000);
  ParallelFor(1000, 2, [&](int k) { squares[k] = 1.0 * k * k; });
  double sum = 0.0;
  for (double s : squares) sum += s;
  EXPECT_DOUBLE_EQ(sum, 332833500.0);
}

TEST(ThreadCpuSeconds, GrowsWithWorkOnThisThread) {
  const double start = ThreadCpuSeconds();
  volatile double x = 0.0;
  for (int k = 0; k < 2000000; ++k) x = x + 1e-9 * k;
  EXPECT_GT(ThreadCpuSeconds(), start);
}

// Two threads encode images, the second only once the first has built
// OpenCV's codec registry. Without PrepareImageCodecs() on the starting
// thread ThreadSanitizer reports the second thread's read of the codecs'
// strings as a data race (the registry's guard is checked in uninstrumented
// code); with it, thread creation orders the two. The relaxed flag orders
// the threads in time without ordering their memory for ThreadSanitizer.
TEST(PrepareImageCodecs, LetsLaterThreadsEncodeWithoutARace) {
  PrepareImageCodecs();
  const cv::Mat image(24, 32, CV_8U, cv::Scalar(90));
  std::vector<uchar> first, second;
  std::atomic<bool> first_done{false};
  std::thread early([&] {
    EXPECT_TRUE(cv::imencode(".png", image, first));
    first_done.store(true, std::memory_order_relaxed);
  });
  std::thread late([&] {
    while (!first_done.load(std::memory_order_relaxed)) {
      std::this_thread::yield();
    }
    EXPECT_TRUE(cv::imencode(".png", image, second));
  });
  early.join();
  late.join();
  EXPECT_FALSE(first.empty());
  EXPECT_EQ(first, second);
}

}  // namespace
}  // namespace zebrageo
