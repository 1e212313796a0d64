#pragma once
// Wall-clock time on the steady clock: the frame loop's stage timings, the evaluation's phase times and the
// benchmarks (the only parts of the project that read the wall clock; none of it reaches a deterministic output).
#include <chrono>
#include <ctime>

#include "common/units.hpp"

namespace stvl {

using SteadyClock = std::chrono::steady_clock;

// Milliseconds since `start` on the steady clock.
inline double ms_since(SteadyClock::time_point start) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - start).count();
}

// Seconds since `start` on the steady clock.
inline double s_since(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// The process's CPU time (all threads) in milliseconds, CLOCK_PROCESS_CPUTIME_ID: a layer's cpu_ms per update.
inline double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return kMsPerSecond * static_cast<double>(t.tv_sec) + kMsPerNanosecond * static_cast<double>(t.tv_nsec);
}

// Started on construction; reads the time since then (or since the last restart()).
class Stopwatch {
 public:
  Stopwatch() : start_(SteadyClock::now()) {}
  void restart() { start_ = SteadyClock::now(); }
  double elapsed_ms() const { return ms_since(start_); }
  double elapsed_s() const { return s_since(start_); }
  SteadyClock::time_point start() const { return start_; }

 private:
  SteadyClock::time_point start_;
};

// Adds the wall time of its scope, in ms, to `total_ms` when it ends.
class ScopedMsTimer {
 public:
  explicit ScopedMsTimer(double& total_ms) : total_ms_(total_ms) {}
  ~ScopedMsTimer() { total_ms_ += watch_.elapsed_ms(); }
  ScopedMsTimer(const ScopedMsTimer&) = delete;
  ScopedMsTimer& operator=(const ScopedMsTimer&) = delete;

 private:
  double& total_ms_;
  Stopwatch watch_;
};

}  // namespace stvl
