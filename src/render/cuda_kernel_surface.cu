// The device kernel for served specialisation kServedSurface (see cuda_kernels.h).
#include "render/cuda_kernels_impl.cuh"

namespace tessera {
TESSERA_INSTANTIATE_RENDER_TILES(kServedSurface)
}  // namespace tessera
