// The device API on CUDA (render/device_api.h): plain cudaMalloc'd memory,
// synchronous copies, and per batch of tiles two launches queued on the
// default stream: the trace (cuda_kernel_*.cu: the full surface integrator,
// unguided, table-guided and neural-guided, in files of their own; ptxas reports their registers
// and stack in the build log, -Xptxas=-v), then the accumulation below. The
// kernel bodies are render/device_tiles.h's, which the host emulation runs too.
#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "render/cuda_kernels.h"
#include "render/device_api.h"

namespace tessera {
namespace {

__global__ void __launch_bounds__(kCudaThreadsPerBlock) accumulate_kernel(DeviceLaunch launch) {
  for (uint32_t p = threadIdx.x; p < launch.max_tile_pixels; p += blockDim.x) accumulate_device_pixel(launch, blockIdx.x, p);
  if (threadIdx.x == 0) gather_device_targets(launch, blockIdx.x);  // reads only what the trace wrote
}

// This process's place among the ranks on its machine (Open MPI, MPICH,
// Slurm), 0 outside a farm.
int local_rank() {
  for (const char* var : {"OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID", "SLURM_LOCALID"})
    if (const char* v = std::getenv(var)) return std::max(0, std::atoi(v));
  return 0;
}

class CudaDevice : public DeviceApi {
 public:
  explicit CudaDevice(int device) {
    cuda_check_error(cudaSetDevice(device), "cudaSetDevice");
    cudaDeviceProp p{};
    cuda_check_error(cudaGetDeviceProperties(&p, device), "cudaGetDeviceProperties");
    description_ = "device " + std::to_string(device) + ": " + p.name + ", " + std::to_string(p.totalGlobalMem >> 20) + " MiB";
    // Paths keep their state in local memory: the default 1 KiB stack per
    // thread is too small for the integrator. eval_texture recurses through
    // nested textures, which ptxas cannot bound: a margin for that.
    const size_t stack = std::max({render_tiles_stack_bytes<kServedSurface>(), render_tiles_stack_bytes<kServedSurface | kSpecGuiding>(),
                                   render_tiles_stack_bytes<kServedSurface | kSpecGuiding | kSpecNeural>()});
    cuda_check_error(cudaDeviceSetLimit(cudaLimitStackSize, std::max<size_t>(stack + 4096, 8192)), "cudaDeviceSetLimit");
    cuda_check_error(cudaEventCreateWithFlags(&done_, cudaEventDisableTiming), "cudaEventCreate");
  }
  ~CudaDevice() override { cudaEventDestroy(done_); }
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
  void start(const DeviceLaunch& launch, uint32_t spec) override {
    if (launch.num_tiles == 0 || launch.max_samples == 0) return;
    if (spec & kSpecMedia)
      throw std::runtime_error("the CUDA backend has no media kernels (device_backend_obstacle keeps such scenes off it)");
    dispatch_served<false>(spec, [&](auto served) { launch_render_tiles<decltype(served)::value>(launch); });
    accumulate_kernel<<<launch.num_tiles, kCudaThreadsPerBlock>>>(launch);
    cuda_check_error(cudaGetLastError(), "launch");
    cuda_check_error(cudaEventRecord(done_), "cudaEventRecord");
  }
  bool finished() override {
    if (cudaEventQuery(done_) != cudaErrorNotReady) return true;
    (void)cudaGetLastError();  // "not ready" is recorded as the thread's last error: not one of ours
    return false;
  }
  void wait() override {
    cuda_check_error(cudaEventSynchronize(done_), "render");
    cuda_check_error(cudaGetLastError(), "render");
  }

 private:
  std::string description_;
  cudaEvent_t done_ = nullptr;
};

}  // namespace

int cuda_device_count(std::string* why) {
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e == cudaSuccess && count > 0) return count;
  if (why) {
    if (e == cudaErrorInsufficientDriver)
      *why = "no CUDA device (no NVIDIA driver, or one older than this build's CUDA runtime)";
    else if (e == cudaSuccess || e == cudaErrorNoDevice)
      *why = "no CUDA device";
    else
      *why = std::string("no CUDA device (") + cudaGetErrorString(e) + ")";
  }
  return 0;
}

std::unique_ptr<DeviceApi> open_cuda_device(std::string* why) {
  const int count = cuda_device_count(why);
  if (count == 0) return nullptr;
  try {
    return std::make_unique<CudaDevice>(local_rank() % count);
  } catch (const std::exception& ex) {
    if (why) *why = ex.what();
    return nullptr;
  }
}

}  // namespace tessera
