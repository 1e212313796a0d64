// The CUDA Context: device check, stream; the filters are in voxel_grid.cu and csnb.cu, the buffers in
// buffers.cu.
#include "filter/cuda/buffers.hpp"

namespace stvl::filter::cuda {

bool device_available(std::string* reason) {
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess) {
    cudaGetLastError();
    if (reason) {
      *reason = std::string("cudaGetDeviceCount: ") + cudaGetErrorName(status) + " (error " +
                std::to_string(int(status)) + ")";
    }
    return false;
  }
  if (count == 0) {
    if (reason) *reason = "no CUDA device";
    return false;
  }
  if (reason) reason->clear();
  return true;
}

Context::Context() : impl_(std::make_unique<Impl>()) {
  std::string reason;
  if (!device_available(&reason)) throw std::runtime_error("filter: device 'cuda' unavailable: " + reason);
  STVL_CUDA(cudaStreamCreateWithFlags(&impl_->stream, cudaStreamNonBlocking));
}

Context::~Context() {
  if (impl_ && impl_->stream) cudaStreamDestroy(impl_->stream);
}

}  // namespace stvl::filter::cuda
