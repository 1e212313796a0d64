#include "bench/cloud_io.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace stvl::bench {

namespace {
constexpr char kMagic[8] = {'S', 'T', 'V', 'L', 'C', 'L', 'D', '1'};
}

void save_cloud(const std::string& path, const Eigen::Matrix3Xf& points) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("save_cloud: cannot open '" + path + "' for writing");
  const std::uint64_t count = static_cast<std::uint64_t>(points.cols());
  out.write(kMagic, sizeof(kMagic));
  out.write(reinterpret_cast<const char*>(&count), sizeof(count));
  out.write(reinterpret_cast<const char*>(points.data()), static_cast<std::streamsize>(count * 3 * sizeof(float)));
  if (!out) throw std::runtime_error("save_cloud: writing '" + path + "' failed");
}

Eigen::Matrix3Xf load_cloud(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error("load_cloud: cannot open '" + path + "'");
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  char magic[8] = {};
  std::uint64_t count = 0;
  if (size < 16 || !in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) {
    throw std::invalid_argument("load_cloud: '" + path + "' is not a cloud file (no STVLCLD1 header)");
  }
  in.read(reinterpret_cast<char*>(&count), sizeof(count));
  if (count > (size - 16) / 12 || 16 + count * 12 != size) {
    throw std::invalid_argument("load_cloud: '" + path + "' declares " + std::to_string(count) + " points but holds " +
                                std::to_string(size) + " bytes (expected 16 + 12 * count)");
  }
  if (count >= std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("load_cloud: '" + path + "' has too many points: " + std::to_string(count));
  }
  Eigen::Matrix3Xf points(3, static_cast<Eigen::Index>(count));
  in.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(count * 12));
  if (!in) throw std::runtime_error("load_cloud: reading '" + path + "' failed");
  return points;
}

}  // namespace stvl::bench
