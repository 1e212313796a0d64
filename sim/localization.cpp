#include "sim/localization.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/splitmix.hpp"

namespace stvl::sim {
namespace {

// A standard normal from correction k's stream (two counter-based draws).
double normal(std::uint64_t seed, std::uint64_t stream, std::uint64_t k) {
  const std::uint64_t s = splitmix64(seed ^ (stream * 0xD1B54A32D192ED03ull));
  return box_muller(splitmix64(s ^ (2 * k)), splitmix64(s ^ (2 * k + 1)));
}

void require(bool ok, const std::string& key, const std::string& what) {
  if (!ok) throw std::invalid_argument(key + ": " + what);
}

}  // namespace

void LocalizationConfig::validate(double duration_s) const {
  require(std::isfinite(rate_hz) && rate_hz > 0.0 && rate_hz <= 1000.0, "rate_hz", "must lie in (0, 1000] Hz");
  require(std::isfinite(noise_xy_m) && noise_xy_m >= 0.0 && noise_xy_m <= 10.0, "noise_xy_m", "must lie in [0, 10] m");
  require(std::isfinite(noise_yaw_rad) && noise_yaw_rad >= 0.0 && noise_yaw_rad <= M_PI, "noise_yaw_rad",
          "must lie in [0, pi] rad");
  double last_s = -1.0;
  for (std::size_t i = 0; i < jumps.size(); ++i) {
    const LocalizationJump& j = jumps[i];
    const std::string key = "jumps[" + std::to_string(i) + "]";
    require(std::isfinite(j.at_s) && j.at_s >= 0.0, key + ".at_s", "must be finite and >= 0");
    require(
        j.at_s < duration_s, key + ".at_s",
        "at " + std::to_string(j.at_s) + " s is not within the run (duration_s " + std::to_string(duration_s) + ")");
    require(j.at_s > last_s, key + ".at_s", "jumps must be in time order, one per time");
    require(std::isfinite(j.x_m) && std::abs(j.x_m) < 10.0, key + ".x_m", "must lie in (-10, 10) m");
    require(std::isfinite(j.y_m) && std::abs(j.y_m) < 10.0, key + ".y_m", "must lie in (-10, 10) m");
    require(std::isfinite(j.yaw_rad) && std::abs(j.yaw_rad) < M_PI, key + ".yaw_rad", "must lie in (-pi, pi) rad");
    last_s = j.at_s;
  }
}

std::uint64_t correction_index(const LocalizationConfig& config, double time_s) {
  if (!(time_s > 0.0)) return 0;
  return static_cast<std::uint64_t>(std::floor(time_s * config.rate_hz + 1e-9));
}

PoseError2 localization_error(const LocalizationConfig& config, std::uint64_t seed, std::uint64_t k) {
  PoseError2 e;
  const double t_s = static_cast<double>(k) / config.rate_hz;
  for (const LocalizationJump& j : config.jumps)
    if (j.at_s <= t_s + 1e-9) e = {j.x_m, j.y_m, j.yaw_rad};
  if (config.noise_xy_m > 0.0) {
    e.x_m += config.noise_xy_m * normal(seed, 1, k);
    e.y_m += config.noise_xy_m * normal(seed, 2, k);
  }
  if (config.noise_yaw_rad > 0.0) e.yaw_rad += config.noise_yaw_rad * normal(seed, 3, k);
  return e;
}

}  // namespace stvl::sim
