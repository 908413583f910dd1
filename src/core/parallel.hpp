#pragma once
// The one way work is spread over threads: parallelFor(count, threads, fn) runs fn(0) … fn(count − 1),
// each thread taking the next index. An index is a fixed piece of work that the caller defines (a tile,
// a mesh, a chunk of count / kPieces elements — never count / threads), so what fn computes, and which
// exception the caller sees, do not depend on the thread count. ThreadPool keeps threads for a job that
// spreads work many times (the BVH build); parallelFor on a pool runs the same loop on its threads.
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace rtr {

// `requested`, or for 0 the cores this process may run on (a cpuset may allow fewer than the machine has).
unsigned threadCount(unsigned requested = 0);

// Threads started once; tasks are queued in groups. A thread waiting for its group runs queued tasks
// meanwhile, so nested waits never starve the pool. A task's exception is rethrown by its group's wait.
class ThreadPool {
 public:
  struct Group {
    std::atomic<int> left{0};
    std::exception_ptr failure;  // the first a task threw
  };
  explicit ThreadPool(unsigned workers);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;
  unsigned workers() const { return unsigned(threads_.size()); }
  void run(Group& g, std::function<void()> task);
  void wait(Group& g);

 private:
  bool runOne();
  void work();
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> queue_;
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

namespace detail {
// The loop every thread of a parallelFor runs. Indices are taken in increasing order; once one fails no
// new one starts, so every index below a failing one has run and the failure kept (the smallest index's)
// is the one a single thread would have met first.
class ForLoop {
 public:
  explicit ForLoop(size_t count) : count_(count) {}
  template <class Fn>
  void run(Fn& fn) {
    for (size_t i; (i = next_.fetch_add(1)) < count_;) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(mutex_);
        if (i < failedAt_) {
          failedAt_ = i;
          failure_ = std::current_exception();
        }
        next_.store(count_);
      }
    }
  }
  void rethrow() const {
    if (failure_) std::rethrow_exception(failure_);
  }

 private:
  size_t count_;
  std::atomic<size_t> next_{0};
  std::mutex mutex_;
  size_t failedAt_ = std::numeric_limits<size_t>::max();
  std::exception_ptr failure_;
};
}  // namespace detail

// fn(i) for i in [0, count) on up to `threads` threads (0: threadCount()), the calling thread one of them.
// Returns once all have stopped; rethrows the exception of the smallest index that threw, if any.
template <class Fn>
void parallelFor(size_t count, unsigned threads, Fn&& fn) {
  const size_t n = std::min<size_t>(threadCount(threads), count);
  detail::ForLoop loop(count);
  std::vector<std::thread> pool;
  for (size_t t = 1; t < n; ++t) {
    try {
      pool.emplace_back([&] { loop.run(fn); });
    } catch (const std::system_error&) {  // no thread to be had (memory or process limits): fewer do it
      break;
    }
  }
  loop.run(fn);
  for (std::thread& t : pool) t.join();
  loop.rethrow();
}

// The same on a pool's threads (and the calling one).
template <class Fn>
void parallelFor(ThreadPool& pool, size_t count, Fn&& fn) {
  const size_t n = std::min<size_t>(pool.workers() + 1, count);
  detail::ForLoop loop(count);
  ThreadPool::Group g;
  for (size_t t = 1; t < n; ++t) pool.run(g, [&] { loop.run(fn); });
  loop.run(fn);
  pool.wait(g);
  loop.rethrow();
}

// std::sort's result on all cores, a sample sort: splitters taken from a fixed sample of the elements
// bound the buckets, fixed pieces of the elements are counted and dealt into them in order, and the
// buckets are sorted at once. The order must be total (ties broken by something that tells elements
// apart, or equal elements identical): then the sorted result is unique, std::sort's whatever the thread
// count. (Merging sorted pieces pairwise ended in one thread merging everything.)
template <class T, class Less = std::less<>>
void parallelSort(std::vector<T>& v, unsigned threads = 0, Less less = {}) {
  constexpr size_t kPiece = size_t(1) << 16, kMaxBuckets = 1024, kSamplesPerBucket = 16;
  const size_t n = v.size();
  if (n <= kPiece) return std::sort(v.begin(), v.end(), less);
  const size_t piece = std::max(kPiece, (n + kMaxBuckets - 1) / kMaxBuckets), pieces = (n + piece - 1) / piece;
  const size_t buckets = pieces, samples = buckets * kSamplesPerBucket;
  std::vector<T> splitters(samples);  // bucket b: splitters[b - 1] <= e < splitters[b]
  for (size_t k = 0; k < samples; ++k) splitters[k] = v[k * (n / samples)];
  std::sort(splitters.begin(), splitters.end(), less);
  for (size_t b = 1; b < buckets; ++b) splitters[b - 1] = splitters[b * kSamplesPerBucket];
  splitters.resize(buckets - 1);
  const auto bucketOf = std::make_unique_for_overwrite<uint16_t[]>(n);
  std::vector<size_t> at(pieces * buckets, 0);  // [piece][bucket]: its count, then where it deals next
  parallelFor(pieces, threads, [&](size_t p) {
    for (size_t i = p * piece; i < std::min(n, (p + 1) * piece); ++i) {
      bucketOf[i] = uint16_t(std::upper_bound(splitters.begin(), splitters.end(), v[i], less) - splitters.begin());
      ++at[p * buckets + bucketOf[i]];
    }
  });
  std::vector<size_t> first(buckets + 1, 0);
  for (size_t b = 0, sum = 0; b < buckets; ++b) {
    first[b] = sum;
    for (size_t p = 0; p < pieces; ++p) sum += std::exchange(at[p * buckets + b], sum);
  }
  first[buckets] = n;
  const auto dealt = std::make_unique_for_overwrite<T[]>(n);
  parallelFor(pieces, threads, [&](size_t p) {
    for (size_t i = p * piece; i < std::min(n, (p + 1) * piece); ++i) dealt[at[p * buckets + bucketOf[i]]++] = std::move(v[i]);
  });
  parallelFor(buckets, threads, [&](size_t b) {
    std::sort(dealt.get() + first[b], dealt.get() + first[b + 1], less);
    std::move(dealt.get() + first[b], dealt.get() + first[b + 1], v.begin() + first[b]);
  });
}

}  // namespace rtr
