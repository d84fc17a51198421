// The device backend's CUDA kernels: the full surface integrator, unguided,
// guided by the table and guided by the network, each compiled in a file of its own (cuda_kernel_*.cu) so that
// a parallel build runs their ptxas side by side (each takes minutes: the
// whole integrator is one kernel). Media kernels would double the build;
// scenes with media stay on the CPU until they are worth it. CUDA code only.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <stdexcept>
#include <string>

#include "render/device_tiles.h"

namespace tessera {

inline void cuda_check_error(cudaError_t e, const char* what) {
  if (e != cudaSuccess) throw std::runtime_error(std::string("CUDA: ") + what + ": " + cudaGetErrorString(e));
}

constexpr uint32_t kCudaThreadsPerBlock = 128;

// Queues the trace of every sample of every tile of the batch (a block per
// tile and sample) on the default stream; throws on a launch error.
template <uint32_t Spec>
void launch_render_tiles(const DeviceLaunch& launch);
// The kernel's stack (local memory) per thread, as ptxas compiled it.
template <uint32_t Spec>
size_t render_tiles_stack_bytes();

}  // namespace tessera
