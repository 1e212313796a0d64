#pragma once
// Unit conversions and the tolerances that are written the same everywhere, named once. Header-only. Each helper
// computes exactly what the expression it replaced did (the same operations in the same order), so no number changes.
#include <cmath>
#include <cstdint>

namespace stvl {

// --- Unit conversions ---------------------------------------------------------------------------------------

inline constexpr double kSecondsPerNanosecond = 1e-9;
inline constexpr double kNanosecondsPerSecond = 1e9;
inline constexpr std::int64_t kWholeNanosecondsPerSecond = 1000000000;  // for splitting integer stamps
inline constexpr double kMsPerSecond = 1e3;
inline constexpr double kSecondsPerMs = 1e-3;
inline constexpr double kMsPerNanosecond = 1e-6;
inline constexpr double kMmPerMetre = 1000.0;
inline constexpr float kMetresPerMmF = 0.001f;  // 16-bit millimetre depth to float metres
inline constexpr double kRadPerDeg = M_PI / 180.0;

// Degrees from radians as rad * 180 / pi (two roundings, as written before; not rad * (180 / pi)).
inline constexpr double degrees(double rad) { return rad * 180.0 / M_PI; }

// --- Tolerances ---------------------------------------------------------------------------------------------

// Two times this close are the same instant (a frame, an update tick, an evaluation or sample time reached by
// summing periods).
inline constexpr double kTimeEpsilon_s = 1e-9;

// A ratio this close below a whole number counts as that number: ceil(size / cell - kWholeCountEpsilon) cells.
inline constexpr double kWholeCountEpsilon = 1e-9;

// Two angles this close are equal (a FOV given as the camera's).
inline constexpr double kAngleEpsilon_rad = 1e-9;

// Two lengths this close are equal (a resolution, a range, a distance to a ring).
inline constexpr double kLengthEpsilon_m = 1e-9;

// Relative: |a - b| <= kRelativeEpsilon * |b| counts as a == b.
inline constexpr double kRelativeEpsilon = 1e-9;

}  // namespace stvl
