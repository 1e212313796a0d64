#include "layer/tf_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace stvl::layer {

void TfTimingConfig::validate() const {
  if (!(std::isfinite(odom_rate_hz) && odom_rate_hz > 0.0 && odom_rate_hz <= 10000.0))
    throw std::invalid_argument("odom_rate_hz: must lie in (0, 10000] Hz");
  if (!(std::isfinite(odom_latency_s) && odom_latency_s >= 0.0 && odom_latency_s <= 10.0))
    throw std::invalid_argument("odom_latency_s: must lie in [0, 10] s");
  if (!(std::isfinite(transform_tolerance_s) && transform_tolerance_s >= 0.0 && transform_tolerance_s <= 60.0))
    throw std::invalid_argument("transform_tolerance: must lie in [0, 60] s");
  if (queue_size < 1) throw std::invalid_argument("queue_size: must be at least 1");
}

double transform_available_s(const TfTimingConfig& c, double stamp_s) {
  if (stamp_s < 0.0) return std::numeric_limits<double>::infinity();
  // The first message stamped at or after stamp_s (a hair of rounding: a stamp on a message's own time uses it).
  const double k = std::ceil(stamp_s * c.odom_rate_hz - 1e-9);
  return std::max(k, 0.0) / c.odom_rate_hz + c.odom_latency_s;
}

const char* to_string(DropReason reason) {
  switch (reason) {
    case DropReason::kCamera: return "camera";
    case DropReason::kTfTimeout: return "tf_timeout";
    case DropReason::kQueueFull: return "queue_full";
    default: return "delivered";
  }
}

FilterVerdict message_filter(const TfTimingConfig& c, double arrival_s, double stamp_s) {
  const double available_s = transform_available_s(c, stamp_s);
  FilterVerdict v;
  if (available_s > arrival_s + c.transform_tolerance_s + 1e-12) {
    v.reason = DropReason::kTfTimeout;
    return v;
  }
  v.delivered_s = available_s > arrival_s + 1e-9 ? available_s : arrival_s;  // a message at the stamp itself
  return v;
}

}  // namespace stvl::layer
