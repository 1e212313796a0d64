#include "sensors/camera_timing.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/splitmix.hpp"

namespace stvl::sensors {
namespace {

// Counter-based draws: stream 1 the latency, stream 2 the drop bursts; each from (seed, stream, frame).
std::uint64_t draw(std::uint64_t seed, std::uint64_t stream, std::uint64_t frame) {
  return splitmix64(splitmix64(seed ^ (stream * 0xD1B54A32D192ED03ull)) ^ frame);
}

void require(bool ok, const char* key, const std::string& what) {
  if (!ok) throw std::invalid_argument(std::string(key) + ": " + what);
}

}  // namespace

StampMode parse_stamp_mode(const std::string& text) {
  if (text == "capture") return StampMode::kCapture;
  if (text == "arrival") return StampMode::kArrival;
  if (text == "offset") return StampMode::kOffset;
  throw std::invalid_argument("unknown stamp '" + text + "'; expected capture, arrival or offset");
}

const char* to_string(StampMode mode) {
  switch (mode) {
    case StampMode::kArrival: return "arrival";
    case StampMode::kOffset: return "offset";
    default: return "capture";
  }
}

bool CameraTimingConfig::enabled() const {
  return latency_mean_s != 0.0 || latency_jitter_s != 0.0 || stamp != StampMode::kCapture || drop_probability != 0.0;
}

void CameraTimingConfig::validate() const {
  require(std::isfinite(latency_mean_s) && latency_mean_s >= 0.0 && latency_mean_s <= 10.0, "latency_mean_s",
          "must lie in [0, 10] s");
  require(std::isfinite(latency_jitter_s) && latency_jitter_s >= 0.0 && latency_jitter_s <= 10.0, "latency_jitter_s",
          "must lie in [0, 10] s");
  require(std::isfinite(stamp_offset_s) && std::abs(stamp_offset_s) <= 10.0, "stamp_offset_s",
          "must lie in [-10, 10] s");
  require(stamp == StampMode::kOffset || stamp_offset_s == 0.0, "stamp_offset_s", "is read with stamp: offset only");
  require(std::isfinite(drop_probability) && drop_probability >= 0.0 && drop_probability <= 1.0, "drop_probability",
          "must lie in [0, 1]");
  require(drop_burst_frames >= 1 && drop_burst_frames <= 10000, "drop_burst_frames", "must lie in [1, 10000]");
}

FrameTiming frame_timing(const CameraTimingConfig& c, std::uint64_t seed, std::uint64_t frame_index, double capture_s) {
  FrameTiming t;
  double latency_s = c.latency_mean_s;
  if (c.latency_jitter_s > 0.0) {  // Box-Muller on two draws of the frame's latency stream
    const std::uint64_t a = draw(seed, 1, 2 * frame_index), b = draw(seed, 1, 2 * frame_index + 1);
    latency_s = std::max(0.0, latency_s + c.latency_jitter_s * box_muller(a, b));
  }
  t.arrival_s = capture_s + latency_s;
  switch (c.stamp) {
    case StampMode::kArrival: t.stamp_s = t.arrival_s; break;
    case StampMode::kOffset: t.stamp_s = capture_s + c.stamp_offset_s; break;
    default: t.stamp_s = capture_s;
  }
  if (c.drop_probability > 0.0) {
    const std::uint64_t first = frame_index + 1 >= static_cast<std::uint64_t>(c.drop_burst_frames)
                                    ? frame_index + 1 - static_cast<std::uint64_t>(c.drop_burst_frames)
                                    : 0;
    for (std::uint64_t k = first; k <= frame_index && !t.dropped; ++k)
      t.dropped = unit_open(draw(seed, 2, k)) < c.drop_probability;
  }
  return t;
}

}  // namespace stvl::sensors
