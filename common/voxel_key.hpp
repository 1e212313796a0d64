#pragma once
// Integer voxel and cell keys, shared by sim/ (ground truth), mapping/ (the map) and evaluation/. Voxel index = floor(p
// / voxel_size_m) per axis: voxel k covers [k * size, (k + 1) * size) on each axis, so the origin is a voxel corner.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_set>

#include <Eigen/Core>

namespace stvl {

struct VoxelKey {
  std::int32_t x = 0, y = 0, z = 0;
  friend bool operator==(const VoxelKey& a, const VoxelKey& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
  friend bool operator!=(const VoxelKey& a, const VoxelKey& b) { return !(a == b); }
  friend bool operator<(const VoxelKey& a, const VoxelKey& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  }
};

struct CellKey {
  std::int32_t x = 0, y = 0;
  friend bool operator==(const CellKey& a, const CellKey& b) { return a.x == b.x && a.y == b.y; }
  friend bool operator!=(const CellKey& a, const CellKey& b) { return !(a == b); }
  friend bool operator<(const CellKey& a, const CellKey& b) { return a.x != b.x ? a.x < b.x : a.y < b.y; }
};

struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 73856093u) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 19349669u) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 83492791u));
  }
};

struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 73856093u) ^
                                    (static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 19349669u));
  }
};

using VoxelSet = std::unordered_set<VoxelKey, VoxelKeyHash>;
using CellSet = std::unordered_set<CellKey, CellKeyHash>;

inline VoxelKey voxel_key(const Eigen::Vector3d& p, double voxel_size_m) {
  return {static_cast<std::int32_t>(std::floor(p.x() / voxel_size_m)),
          static_cast<std::int32_t>(std::floor(p.y() / voxel_size_m)),
          static_cast<std::int32_t>(std::floor(p.z() / voxel_size_m))};
}

inline Eigen::Vector3d voxel_center(const VoxelKey& k, double voxel_size_m) {
  return Eigen::Vector3d(k.x + 0.5, k.y + 0.5, k.z + 0.5) * voxel_size_m;
}

inline CellKey cell_key(const Eigen::Vector2d& p, double cell_size_m) {
  return {static_cast<std::int32_t>(std::floor(p.x() / cell_size_m)),
          static_cast<std::int32_t>(std::floor(p.y() / cell_size_m))};
}

}  // namespace stvl
