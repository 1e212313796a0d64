// The CUDA interface when stvl is built without nvcc: same API, kCuda throws.
#include <stdexcept>

#include "filter/cuda/context.hpp"

namespace stvl::filter::cuda {

namespace {
constexpr const char* kNoCuda = "filter device 'cuda' requested but stvl was built without CUDA support";
}

bool device_available(std::string* reason) {
  if (reason) *reason = "built without CUDA support";
  return false;
}

struct Context::Impl {};
Context::Context() { throw std::runtime_error(kNoCuda); }
Context::~Context() = default;
Eigen::Matrix3Xf Context::voxel_grid(const Eigen::Matrix3Xf&, const VoxelGridConfig&, MemoryMode) {
  throw std::runtime_error(kNoCuda);
}
Eigen::Matrix3Xf Context::csnb(const Eigen::Matrix3Xf&, const CsnbConfig&, MemoryMode) {
  throw std::runtime_error(kNoCuda);
}

}  // namespace stvl::filter::cuda
