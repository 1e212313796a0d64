#pragma once
#include <Eigen/Core>

#include <cstdint>
#include <string>

namespace stvl::filter {

// Cloud file: 8 bytes "STVLCLD1", uint64 point count, then count x (x, y, z) float32; little-endian.
void save_cloud(const std::string& path, const Eigen::Matrix3Xf& points);
// Throws std::runtime_error when the file cannot be read, std::invalid_argument when it is not a valid
// cloud file (wrong magic, size not matching the count).
Eigen::Matrix3Xf load_cloud(const std::string& path);

// Synthetic depth-camera cloud (world frame, z up): a 848x480 pinhole camera (D435-like, 87 deg HFOV) at
// 1 m height looking down a 2 m wide, 2.5 m high corridor with boxes; range 0.2..10 m; depth noise
// sigma = 0.001 z^2 from a counter-based generator. About 400k points; the same for the same seed.
Eigen::Matrix3Xf make_corridor_cloud(std::uint64_t seed = 1, int width_px = 848, int height_px = 480);

}  // namespace stvl::filter
