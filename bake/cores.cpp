#include "cores.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>

namespace rtr {
namespace {

double seconds(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

}  // namespace

void CoreUse::add(double dt, double dcpu, unsigned threads) {
  wall += dt;
  cpu += dcpu;
  if (dcpu < (double(threads) - 0.5) * dt) notAll += dt;
  if (dcpu <= 1.5 * dt) oneOrNone += dt;
  idle += std::max(0.0, double(threads) * dt - dcpu);
}

CoreSampler::CoreSampler(unsigned threads, double periodSeconds) : threads_(threads) {
  thread_ = std::thread([this, periodSeconds] { run(periodSeconds); });
}

CoreSampler::~CoreSampler() { stop(); }

void CoreSampler::mark(const std::string& step) {
  std::lock_guard lock(mutex_);
  auto it = std::find_if(steps_.begin(), steps_.end(), [&](const CoreUse& u) { return u.step == step; });
  if (it == steps_.end()) it = steps_.insert(steps_.end(), CoreUse{step});
  current_ = int(it - steps_.begin());
}

std::vector<CoreUse> CoreSampler::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  return steps_;
}

void CoreSampler::run(double period) {
  using Clock = std::chrono::steady_clock;
  auto next = Clock::now();
  double wall = seconds(CLOCK_MONOTONIC), cpu = seconds(CLOCK_PROCESS_CPUTIME_ID);
  while (!stop_) {
    next += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period));
    std::this_thread::sleep_until(next);
    const double w = seconds(CLOCK_MONOTONIC), c = seconds(CLOCK_PROCESS_CPUTIME_ID);
    const int at = current_;
    if (at >= 0) {
      std::lock_guard lock(mutex_);
      steps_[size_t(at)].add(w - wall, c - cpu, threads_);
    }
    wall = w, cpu = c;
    if (Clock::now() > next + std::chrono::milliseconds(100)) next = Clock::now();  // fell behind: no burst
  }
}

}  // namespace rtr
