#pragma once
// Internal interface to the CUDA filters (filter/cuda/*.cu, or cuda_stub.cpp when built without CUDA).
#include <Eigen/Core>

#include <memory>
#include <string>

#include "filter/filter.hpp"

namespace stvl::filter::cuda {

bool device_available(std::string* reason);

// Owns device buffers (grown, never shrunk) and host staging for the memory modes; reused across calls.
// The constructor throws std::runtime_error when no device can be used.
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  Eigen::Matrix3Xf voxel_grid(const Eigen::Matrix3Xf& points, const VoxelGridConfig& config, MemoryMode mode);
  Eigen::Matrix3Xf csnb(const Eigen::Matrix3Xf& points, const CsnbConfig& config, MemoryMode mode);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stvl::filter::cuda
