// The device API on CUDA (worker/device_api.h): plain cudaMalloc'd memory,
// synchronous copies, and one kernel launch per batch of tiles: a block per
// tile, its threads striding over the tile's pixels, each running
// render_device_pixel (worker/device_tiles.h), the body the host emulation
// runs too. Two kernels, the full surface integrator unguided and guided, in
// files of their own (cuda_kernel_*.cu); ptxas reports their registers and stack in the
// build log (-Xptxas=-v).
#include <algorithm>
#include <stdexcept>
#include <string>

#include "worker/cuda_kernels.h"
#include "worker/device_api.h"

namespace tessera {
namespace {

class CudaDevice : public DeviceApi {
 public:
  explicit CudaDevice(int device) {
    cuda_check_error(cudaSetDevice(device), "cudaSetDevice");
    cudaDeviceProp p{};
    cuda_check_error(cudaGetDeviceProperties(&p, device), "cudaGetDeviceProperties");
    description_ = std::string(p.name) + ", " + std::to_string(p.totalGlobalMem >> 20) + " MiB";
    // Paths keep their state in local memory: the default 1 KiB stack per
    // thread is too small for the integrator.
    const size_t stack =
        std::max(render_tiles_stack_bytes<kServedSurface>(), render_tiles_stack_bytes<kServedSurface | kSpecGuiding>());
    cuda_check_error(cudaDeviceSetLimit(cudaLimitStackSize, std::max<size_t>(stack + 1024, 4096)), "cudaDeviceSetLimit");
  }
  std::string backend_name() const override { return "cuda"; }
  std::string description() const override { return description_; }
  bool has_media_kernels() const override { return false; }
  void* alloc(size_t bytes) override {
    void* p = nullptr;
    cuda_check_error(cudaMalloc(&p, bytes), "cudaMalloc");
    return p;
  }
  void release(void* p) noexcept override { cudaFree(p); }
  void upload(void* dst, const void* src, size_t bytes) override {
    cuda_check_error(cudaMemcpy(dst, src, bytes, cudaMemcpyHostToDevice), "upload");
  }
  void download(void* dst, const void* src, size_t bytes) override {
    cuda_check_error(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToHost), "download");
  }
  void zero(void* dst, size_t bytes) override { cuda_check_error(cudaMemset(dst, 0, bytes), "cudaMemset"); }
  void launch(const DeviceLaunch& launch, uint32_t spec) override {
    if (launch.num_tiles == 0) return;
    switch (served_specialisation(spec)) {
      case kServedMedia | kSpecGuiding:
      case kServedMedia:
        throw std::runtime_error("the CUDA backend has no media kernel (device_backend_supports keeps such scenes off it)");
      case kServedSurface | kSpecGuiding: return launch_render_tiles<kServedSurface | kSpecGuiding>(launch);
      default: return launch_render_tiles<kServedSurface>(launch);
    }
  }

 private:
  std::string description_;
};

}  // namespace

std::unique_ptr<DeviceApi> open_cuda_device(std::string* why) {
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e != cudaSuccess || count == 0) {
    if (why) {
      if (e == cudaErrorInsufficientDriver)
        *why = "no CUDA device (no NVIDIA driver, or one older than this build's CUDA runtime)";
      else if (e == cudaSuccess || e == cudaErrorNoDevice)
        *why = "no CUDA device";
      else
        *why = std::string("no CUDA device (") + cudaGetErrorString(e) + ")";
    }
    return nullptr;
  }
  try {
    return std::make_unique<CudaDevice>(0);
  } catch (const std::exception& ex) {
    if (why) *why = ex.what();
    return nullptr;
  }
}

}  // namespace tessera
