#pragma once
// How many cores each step of a bake keeps busy (rtr-bake --profile). A thread of its own reads the
// process's CPU time (all threads) every few milliseconds; a sample's CPU time over its wall time is the
// number of cores busy then, counted under the step marked last. Where a step's wall time passes with
// fewer than all threads busy, the cores wait on something: a serial part, the last piece, a barrier.
#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rtr {

struct CoreUse {
  std::string step;
  double wall = 0, cpu = 0;  // seconds
  double notAll = 0;         // wall seconds with fewer than threads − 0.5 cores busy
  double oneOrNone = 0;      // wall seconds with at most 1.5 cores busy: one thread's work, or waiting
  double idle = 0;           // core-seconds left unused: threads × wall − CPU, sample by sample
  // One sample: `dt` seconds of wall time in which the process used `dcpu` seconds of CPU.
  void add(double dt, double dcpu, unsigned threads);
  double cores() const { return wall > 0 ? cpu / wall : 0.0; }
};

class CoreSampler {
 public:
  explicit CoreSampler(unsigned threads, double periodSeconds = 0.002);
  ~CoreSampler();
  CoreSampler(const CoreSampler&) = delete;
  CoreSampler& operator=(const CoreSampler&) = delete;
  void mark(const std::string& step);  // from now on samples count under `step` (any thread)
  std::vector<CoreUse> stop();         // the steps in the order first marked
  unsigned threads() const { return threads_; }

 private:
  void run(double period);
  unsigned threads_;
  std::mutex mutex_;
  std::vector<CoreUse> steps_;
  std::atomic<int> current_{-1};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace rtr
