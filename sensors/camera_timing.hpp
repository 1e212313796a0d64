#pragma once
// When a depth frame reaches the map, and what it says about itself (issue 43): a camera's latency from capture to
// arrival (mean and jitter), the stamp its driver writes (the capture time, the arrival time, or the capture time
// plus a fixed offset), and frames lost on the way (a probability per frame, in bursts). Counter-based and seeded:
// frame k of a camera gets the same timing in every run and whatever the other cameras do.
#include <cstdint>
#include <string>

namespace stvl::sensors {

enum class StampMode { kCapture, kArrival, kOffset };
// "capture", "arrival", "offset"; throws std::invalid_argument naming the three.
StampMode parse_stamp_mode(const std::string& text);
const char* to_string(StampMode mode);

// YAML camera.timing (per camera); the defaults are a perfect camera (no latency, stamped at capture, nothing lost).
struct CameraTimingConfig {
  double latency_mean_s = 0.0;            // latency_mean_s: capture to arrival
  double latency_jitter_s = 0.0;          // latency_jitter_s: standard deviation of a normal about the mean, cut at 0
  StampMode stamp = StampMode::kCapture;  // stamp
  double stamp_offset_s = 0.0;            // stamp_offset_s: stamp = capture + offset (stamp: offset)
  double drop_probability = 0.0;          // drop_probability: a frame's chance to start a burst of lost frames
  int drop_burst_frames = 1;              // drop_burst_frames: frames lost per burst (the first included)
  // Whether anything differs from a perfect camera.
  bool enabled() const;
  // Throws std::invalid_argument naming the key (latency_mean_s, ...) for a NaN, a negative latency or jitter, a
  // probability outside [0, 1] or a burst below 1 frame.
  void validate() const;
};

// One frame's fate.
struct FrameTiming {
  bool dropped = false;  // lost before it reached the map
  double arrival_s = 0;  // when it reaches the subscriber (capture + latency)
  double stamp_s = 0;    // what its header says
};

// Frame frame_index of a camera captured at capture_s: its latency drawn from (seed, frame_index), its stamp, and
// whether a burst started at one of the drop_burst_frames frames up to it (each a draw of its own).
FrameTiming frame_timing(const CameraTimingConfig& config, std::uint64_t seed, std::uint64_t frame_index,
                         double capture_s);

}  // namespace stvl::sensors
