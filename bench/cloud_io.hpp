#pragma once
// Cloud files (.stvlcld) for the filter benchmarks and scripts/ab-filter.sh. Eigen only.
#include <Eigen/Core>

#include <string>

namespace stvl::bench {

// Cloud file: 8 bytes "STVLCLD1", uint64 point count, then count x (x, y, z) float32; little-endian.
void save_cloud(const std::string& path, const Eigen::Matrix3Xf& points);
// Throws std::runtime_error when the file cannot be read, std::invalid_argument when it is not a valid
// cloud file (wrong magic, size not matching the count).
Eigen::Matrix3Xf load_cloud(const std::string& path);

}  // namespace stvl::bench
