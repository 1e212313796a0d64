#include "config/timing_lint.hpp"

#include <algorithm>
#include <cmath>

#include "common/format.hpp"

namespace stvl::config {
namespace {

// Rounded up to the next 0.01 s: a value a user writes.
double up_to_centiseconds(double s) { return std::ceil(s * 100.0 - 1e-9) / 100.0; }

}  // namespace

std::vector<LintFinding> lint_timing(const Scenario& s) {
  std::vector<LintFinding> out;
  const pipeline::PipelineConfig& p = s.pipeline;
  const layer::TfTimingConfig& tf = p.tf;
  for (std::size_t c = 0; c < p.cameras.size(); ++c) {
    const pipeline::CameraConfig& camera = p.cameras[c];
    const sensors::CameraTimingConfig& t = camera.timing;
    const std::string name = "camera '" + camera.name + "'";
    const std::string readings = "the readings of " + name;
    const double latency_lo = std::max(0.0, t.latency_mean_s - 3.0 * t.latency_jitter_s);
    const double latency_hi = t.latency_mean_s + 3.0 * t.latency_jitter_s;
    // stamp - arrival, at its smallest and largest.
    double lead_lo = -latency_hi, lead_hi = -latency_lo;
    if (t.stamp == sensors::StampMode::kArrival) lead_lo = lead_hi = 0.0;
    if (t.stamp == sensors::StampMode::kOffset)
      lead_lo = t.stamp_offset_s - latency_hi, lead_hi = t.stamp_offset_s - latency_lo;
    // The pose at the stamp needs the first odometry message at or after it: up to one period later, plus latency.
    const double wait_lo = std::max(0.0, tf.odom_latency_s + lead_lo);
    const double wait_hi = std::max(0.0, 1.0 / tf.odom_rate_hz + tf.odom_latency_s + lead_hi);
    if (p.timing_enabled() && tf.transform_tolerance_s < wait_hi - 1e-9) {
      const bool every = tf.transform_tolerance_s < wait_lo - 1e-9;
      out.push_back({s.file, 0, "tf.transform_tolerance",
                     fixed(tf.transform_tolerance_s, 3) + " s: " + readings + " wait " + fixed(wait_lo, 3) + " to " +
                         fixed(wait_hi, 3) + " s for the robot's pose at their stamp (odometry every " +
                         fixed(1.0 / tf.odom_rate_hz, 3) + " s, " + fixed(tf.odom_latency_s, 3) + " s late; stamp " +
                         sensors::to_string(t.stamp) + ", latency " + fixed(latency_lo, 3) + " to " +
                         fixed(latency_hi, 3) + " s): the message filter drops " +
                         (every ? "every reading" : "the readings that wait longer") + " as tf_timeout",
                     "transform_tolerance: " + fixed(up_to_centiseconds(wait_hi), 2) +
                         " (or odometry sooner: a higher rate or less latency)"});
    }
    // A reading's age at delivery (delivery - stamp): its own lateness, or the wait for the odometry message at or
    // after its stamp, whichever is longer. STVL's RemoveStaleObservations and nav2's purgeStaleObservations age it
    // from its stamp at reception: older than observation_persistence (> 0), it goes at once, the newest included.
    const double age_lo = std::max(-lead_hi, tf.odom_latency_s);
    const double age_hi = std::max(-lead_lo, tf.odom_latency_s + 1.0 / tf.odom_rate_hz);
    for (const auto& source : camera.sources) {
      const double keep = source.params.observation_persistence_s;
      if (!p.timing_enabled() || !(keep > 0.0) || age_hi <= keep + 1e-9) continue;
      const bool every = age_lo > keep + 1e-9;
      out.push_back({s.file, 0, "observation_persistence (source " + source.name + ")",
                     fixed(keep, 3) + " s: " + readings + " are " + fixed(age_lo, 3) + " to " + fixed(age_hi, 3) +
                         " s old when they reach the layer (stamp " + sensors::to_string(t.stamp) +
                         ", odometry every " + fixed(1.0 / tf.odom_rate_hz, 3) + " s, " + fixed(tf.odom_latency_s, 3) +
                         " s late): the buffer ages them from their stamp and drops " +
                         (every ? "every reading" : "the older ones") + " on arrival, the newest included",
                     "observation_persistence: " + fixed(up_to_centiseconds(age_hi + keep), 2) +
                         " (the age on arrival plus the persistence meant), or 0 (the newest reading only)"});
    }
    // Arrivals are one period apart, give or take the jitter (a lost frame aside).
    const double gap_s = 1.0 / camera.intrinsics.rate_hz + (latency_hi - latency_lo);
    for (const auto& source : camera.sources) {
      const double expected = source.params.expected_update_rate_s;
      if (expected > 0.0 && expected < gap_s - 1e-9)
        out.push_back({s.file, 0, "expected_update_rate (source " + source.name + ")",
                       fixed(expected, 3) + " s: " + name + " delivers a reading every " +
                           fixed(1.0 / camera.intrinsics.rate_hz, 3) + " s, up to " + fixed(gap_s, 3) +
                           " s apart with its jitter: STVL marks the source not current between readings",
                       "expected_update_rate: " + fixed(up_to_centiseconds(gap_s * 1.5), 2) +
                           " (1.5 x the longest gap between readings)"});
    }
  }
  return out;
}

}  // namespace stvl::config
