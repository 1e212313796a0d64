#pragma once
// Wall-clock milliseconds for the frame loop's stage timings (the only part of a run that is not deterministic).
#include <chrono>

namespace stvl {

using SteadyClock = std::chrono::steady_clock;

// Milliseconds since `start` on the steady clock.
inline double ms_since(SteadyClock::time_point start) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - start).count();
}

}  // namespace stvl
