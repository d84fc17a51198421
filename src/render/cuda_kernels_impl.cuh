// Definitions behind cuda_kernels.h; each cuda_kernel_*.cu instantiates one.
#pragma once

#include <algorithm>

#include "render/cuda_kernels.h"

namespace tessera {

// Block (tile, first_sample + sample); its threads stride over the tile's pixels.
template <uint32_t Spec>
__global__ void __launch_bounds__(kCudaThreadsPerBlock) trace_samples_kernel(DeviceLaunch launch, uint32_t first_sample) {
  for (uint32_t p = threadIdx.x; p < launch.max_tile_pixels; p += blockDim.x)
    trace_device_sample<Spec>(launch, blockIdx.x, p, first_sample + blockIdx.y);
}

template <uint32_t Spec>
void launch_render_tiles(const DeviceLaunch& launch) {
  constexpr uint32_t kMaxGridY = 65535;  // CUDA's limit on gridDim.y: longer passes launch in parts
  for (uint32_t first = 0; first < launch.max_samples; first += kMaxGridY) {
    const uint32_t n = std::min(kMaxGridY, launch.max_samples - first);
    trace_samples_kernel<Spec><<<dim3(launch.num_tiles, n), kCudaThreadsPerBlock>>>(launch, first);
    cuda_check_error(cudaGetLastError(), "launch");
  }
}

template <uint32_t Spec>
size_t render_tiles_stack_bytes() {
  cudaFuncAttributes a{};
  cuda_check_error(cudaFuncGetAttributes(&a, trace_samples_kernel<Spec>), "cudaFuncGetAttributes");
  return a.localSizeBytes;
}

#define TESSERA_INSTANTIATE_RENDER_TILES(SPEC)                          \
  template void launch_render_tiles<SPEC>(const DeviceLaunch& launch); \
  template size_t render_tiles_stack_bytes<SPEC>();

}  // namespace tessera
