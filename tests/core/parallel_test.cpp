// parallelFor's promises: every index once, in pieces the caller fixes (so results do not depend on the
// thread count), exactly the threads asked for, and the exception a single thread would have met first.
#include "core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

using namespace rtr;

namespace {

// Float sums over fixed pieces, combined in piece order: the same bits for any thread count.
float pieceSum(const std::vector<float>& v, unsigned threads) {
  constexpr size_t kPiece = 1000;
  std::vector<float> part((v.size() + kPiece - 1) / kPiece, 0.0f);
  parallelFor(part.size(), threads, [&](size_t p) {
    for (size_t i = p * kPiece; i < std::min(v.size(), (p + 1) * kPiece); ++i) part[p] += v[i];
  });
  float sum = 0.0f;
  for (float x : part) sum += x;
  return sum;
}

}  // namespace

TEST(ParallelFor, EveryIndexExactlyOnce) {
  for (unsigned threads : {1u, 2u, 3u, 8u})
    for (size_t count : {size_t(0), size_t(1), size_t(7), size_t(10000)}) {
      std::vector<std::atomic<int>> seen(count);
      parallelFor(count, threads, [&](size_t i) { seen[i].fetch_add(1); });
      for (size_t i = 0; i < count; ++i) ASSERT_EQ(seen[i].load(), 1) << "index " << i << ", " << threads << " threads";
    }
}

TEST(ParallelFor, ResultsDoNotDependOnTheThreadCount) {
  std::vector<float> v(100000);
  for (size_t i = 0; i < v.size(); ++i) v[i] = std::sin(float(i)) * 1e3f + 1e-3f * float(i % 7);
  const float one = pieceSum(v, 1);
  for (unsigned threads : {2u, 3u, 5u, 16u}) EXPECT_EQ(pieceSum(v, threads), one) << threads << " threads";
}

TEST(ParallelFor, RunsOnExactlyTheThreadsAskedFor) {
  for (unsigned threads : {1u, 2u, 4u}) {
    std::mutex m;
    std::set<std::thread::id> ids;
    std::atomic<unsigned> arrived{0};
    bool allMet = true;
    // Each of the first `threads` indices waits until that many have started: only as many threads at
    // once get past it (a second's wait bounds the test when fewer run).
    parallelFor(64, threads, [&](size_t i) {
      {
        std::lock_guard lock(m);
        ids.insert(std::this_thread::get_id());
      }
      if (i < threads) {
        arrived.fetch_add(1);
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        while (arrived.load() < threads && std::chrono::steady_clock::now() < until) std::this_thread::yield();
        if (arrived.load() < threads) {
          std::lock_guard lock(m);
          allMet = false;
        }
      }
    });
    EXPECT_TRUE(allMet) << threads << " threads did not all run at once";
    EXPECT_LE(ids.size(), threads);
    EXPECT_EQ(ids.size(), threads);
    if (threads == 1) { EXPECT_TRUE(ids.count(std::this_thread::get_id())) << "one thread: the caller's"; }
  }
  EXPECT_GE(threadCount(0), 1u);
  EXPECT_EQ(threadCount(3), 3u);
}

TEST(ParallelFor, RethrowsTheSmallestFailingIndexAfterAllStopped) {
  for (unsigned threads : {1u, 2u, 8u}) {
    std::atomic<int> running{0}, maxAfter{0};
    try {
      parallelFor(1000, threads, [&](size_t i) {
        running.fetch_add(1);
        if (i == 100 || i == 101 || i == 500) {
          running.fetch_sub(1);
          throw std::runtime_error("index " + std::to_string(i));
        }
        std::this_thread::sleep_for(std::chrono::microseconds(i % 3 == 0 ? 200 : 0));
        running.fetch_sub(1);
      });
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "index 100") << threads << " threads";
      EXPECT_EQ(running.load(), 0) << "returned while work was running";
    }
  }
}

TEST(ParallelFor, OnAPoolNestsAndCarriesExceptions) {
  ThreadPool pool(3);
  std::vector<std::atomic<int>> seen(64 * 64);
  parallelFor(pool, 64, [&](size_t i) {
    parallelFor(pool, 64, [&](size_t j) { seen[i * 64 + j].fetch_add(1); });  // nested waits run queued work
  });
  for (auto& s : seen) ASSERT_EQ(s.load(), 1);
  EXPECT_THROW(parallelFor(pool, 100,
                           [](size_t i) {
                             if (i == 42) throw std::runtime_error("42");
                           }),
               std::runtime_error);
  ThreadPool::Group g;
  pool.run(g, [] { throw std::runtime_error("task"); });
  EXPECT_THROW(pool.wait(g), std::runtime_error);
}

// parallelSort is std::sort on any thread count: sizes around its piece (2^16) and many buckets, many
// duplicates (equal values are identical), values that are all equal (one bucket holds them), input sorted
// backwards, and a comparator whose ties are broken by an index.
TEST(ParallelSort, IsStdSortOnAnyThreadCount) {
  uint64_t state = 12345;
  auto next = [&] { return state = state * 6364136223846793005ull + 1442695040888963407ull; };
  for (size_t n : {size_t(0), size_t(1000), size_t(1) << 16, (size_t(1) << 16) + 1, size_t(300001), size_t(1234567)})
    for (int pattern = 0; pattern < 3; ++pattern) {
      std::vector<uint64_t> values(n);
      for (size_t k = 0; k < n; ++k)  // 14 random bits (many duplicates), all equal, or falling
        values[k] = pattern == 0 ? next() >> 50 : pattern == 1 ? 7 : n - k;
      std::vector<uint64_t> expected = values;
      std::sort(expected.begin(), expected.end());
      for (unsigned threads : {1u, 3u, 8u}) {
        std::vector<uint64_t> got = values;
        parallelSort(got, threads);
        ASSERT_EQ(got, expected) << n << " values, pattern " << pattern << ", " << threads << " threads";
      }
      std::vector<uint32_t> order(n);
      for (uint32_t k = 0; k < n; ++k) order[k] = k;
      auto byValue = [&](uint32_t a, uint32_t b) { return values[a] != values[b] ? values[a] < values[b] : a < b; };
      std::vector<uint32_t> expectedOrder = order;
      std::sort(expectedOrder.begin(), expectedOrder.end(), byValue);
      parallelSort(order, 5, byValue);
      ASSERT_EQ(order, expectedOrder) << n << " values, pattern " << pattern;
    }
}
