// Definitions behind cuda_kernels.h; each cuda_kernel_*.cu instantiates one.
#pragma once

#include "worker/cuda_kernels.h"

namespace tessera {

template <uint32_t Spec>
__global__ void __launch_bounds__(kCudaThreadsPerBlock) render_tiles_kernel(DeviceLaunch launch) {
  for (uint32_t p = threadIdx.x; p < launch.max_tile_pixels; p += blockDim.x)
    render_device_pixel<Spec>(launch, blockIdx.x, p);
}

template <uint32_t Spec>
void launch_render_tiles(const DeviceLaunch& launch) {
  render_tiles_kernel<Spec><<<launch.num_tiles, kCudaThreadsPerBlock>>>(launch);
  cuda_check_error(cudaGetLastError(), "launch");
  cuda_check_error(cudaDeviceSynchronize(), "render_tiles_kernel");
}

template <uint32_t Spec>
size_t render_tiles_stack_bytes() {
  cudaFuncAttributes a{};
  cuda_check_error(cudaFuncGetAttributes(&a, render_tiles_kernel<Spec>), "cudaFuncGetAttributes");
  return a.localSizeBytes;
}

#define TESSERA_INSTANTIATE_RENDER_TILES(SPEC)                          \
  template void launch_render_tiles<SPEC>(const DeviceLaunch& launch); \
  template size_t render_tiles_stack_bytes<SPEC>();

}  // namespace tessera
