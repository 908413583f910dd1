#include "core/parallel.hpp"

#include <algorithm>

#include <sched.h>

namespace rtr {

unsigned threadCount(unsigned requested) {
  if (requested) return requested;
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return unsigned(std::max(1, CPU_COUNT(&set)));
  return std::max(1u, std::thread::hardware_concurrency());
}

ThreadPool::ThreadPool(unsigned workers) {
  for (unsigned i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void ThreadPool::run(Group& g, std::function<void()> task) {
  g.left.fetch_add(1);
  {
    std::lock_guard lock(mutex_);
    queue_.push_back([this, &g, task = std::move(task)] {
      try {
        task();
      } catch (...) {
        std::lock_guard failLock(mutex_);
        if (!g.failure) g.failure = std::current_exception();
      }
      g.left.fetch_sub(1);
    });
  }
  wake_.notify_one();
}

void ThreadPool::wait(Group& g) {
  while (g.left.load() > 0)
    if (!runOne()) std::this_thread::yield();
  if (g.failure) std::rethrow_exception(g.failure);
}

bool ThreadPool::runOne() {
  std::function<void()> f;
  {
    std::lock_guard lock(mutex_);
    if (queue_.empty()) return false;
    f = std::move(queue_.back());  // the newest: the waiter's own task, most likely
    queue_.pop_back();
  }
  f();
  return true;
}

void ThreadPool::work() {
  for (;;) {
    std::function<void()> f;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;
      f = std::move(queue_.front());
      queue_.pop_front();
    }
    f();
  }
}

}  // namespace rtr
